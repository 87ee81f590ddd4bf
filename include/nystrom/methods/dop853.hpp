// Dormand and Prince's explicit Runge-Kutta pair DOP853 (order 8, embedded order 5; Hairer, Norsett &
// Wanner, Solving Ordinary Differential Equations I, 2nd ed., Springer 1993, sec. II.10, after Prince &
// Dormand, J. Comput. Appl. Math. 7 (1981) 67) in its Nystrom form for y'' = f(t, y, y') (the same book,
// sec. II.14: a Runge-Kutta method (A, b) applied to the first-order system (y, y') is the general RKN
// method with velocity coefficients A, position coefficients A^2 and weights b A, b). Its coefficients
// are published as 30-digit decimals (those of the error weights to 28 digits); the Nystrom
// coefficients are their products, formed at the reference precision.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

namespace dop853 {

inline const std::vector<std::string>& c() {
  static const std::vector<std::string> v = {"0.0",
                                             "0.526001519587677318785587544488e-01",
                                             "0.789002279381515978178381316732e-01",
                                             "0.118350341907227396726757197510",
                                             "0.281649658092772603273242802490",
                                             "0.333333333333333333333333333333",
                                             "0.25",
                                             "0.307692307692307692307692307692",
                                             "0.651282051282051282051282051282",
                                             "0.6",
                                             "0.857142857142857142857142857142",
                                             "1.0",
                                             "1.0"};
  return v;
}
inline const std::vector<std::vector<std::string>>& a() {
  static const std::vector<std::vector<std::string>> v = {
      {},
      {"5.26001519587677318785587544488e-2"},
      {"1.97250569845378994544595329183e-2", "5.91751709536136983633785987549e-2"},
      {"2.95875854768068491816892993775e-2", "0", "8.87627564304205475450678981324e-2"},
      {"2.41365134159266685502369798665e-1", "0", "-8.84549479328286085344864962717e-1",
       "9.24834003261792003115737966543e-1"},
      {"3.7037037037037037037037037037e-2", "0", "0", "1.70828608729473871279604482173e-1",
       "1.25467687566822425016691814123e-1"},
      {"3.7109375e-2", "0", "0", "1.70252211019544039314978060272e-1", "6.02165389804559606850219397283e-2",
       "-1.7578125e-2"},
      {"3.70920001185047927108779319836e-2", "0", "0", "1.70383925712239993810214054705e-1",
       "1.07262030446373284651809199168e-1", "-1.53194377486244017527936158236e-2",
       "8.27378916381402288758473766002e-3"},
      {"6.24110958716075717114429577812e-1", "0", "0", "-3.36089262944694129406857109825",
       "-8.68219346841726006818189891453e-1", "2.75920996994467083049415600797e1", "2.01540675504778934086186788979e1",
       "-4.34898841810699588477366255144e1"},
      {"4.77662536438264365890433908527e-1", "0", "0", "-2.48811461997166764192642586468",
       "-5.90290826836842996371446475743e-1", "2.12300514481811942347288949897e1", "1.52792336328824235832596922938e1",
       "-3.32882109689848629194453265587e1", "-2.03312017085086261358222928593e-2"},
      {"-9.3714243008598732571704021658e-1", "0", "0", "5.18637242884406370830023853209",
       "1.09143734899672957818500254654", "-8.14978701074692612513997267357", "-1.85200656599969598641566180701e1",
       "2.27394870993505042818970056734e1", "2.49360555267965238987089396762", "-3.0467644718982195003823669022"},
      {"2.27331014751653820792359768449", "0", "0", "-1.05344954667372501984066689879e1",
       "-2.00087205822486249909675718444", "-1.79589318631187989172765950534e1", "2.79488845294199600508499808837e1",
       "-2.85899827713502369474065508674", "-8.87285693353062954433549289258", "1.23605671757943030647266201528e1",
       "6.43392746015763530355970484046e-1"},
      {"5.42937341165687622380535766363e-2", "0", "0", "0", "0", "4.45031289275240888144113950566",
       "1.89151789931450038304281599044", "-5.8012039600105847814672114227", "3.1116436695781989440891606237e-1",
       "-1.52160949662516078556178806805e-1", "2.01365400804030348374776537501e-1",
       "4.47106157277725905176885569043e-2"},
  };
  return v;
}
inline const std::vector<std::string>& e5() {
  static const std::vector<std::string> v = {"0.1312004499419488073250102996e-1",
                                             "0",
                                             "0",
                                             "0",
                                             "0",
                                             "-0.1225156446376204440720569753e+1",
                                             "-0.4957589496572501915214079952",
                                             "0.1664377182454986536961530415e+1",
                                             "-0.3503288487499736816886487290",
                                             "0.3341791187130174790297318841",
                                             "0.8192320648511571246570742613e-1",
                                             "-0.2235530786388629525884427845e-1",
                                             "0"};
  return v;
}
/// The Nystrom form of the pair: stages 1-12 of DOP853 and its 13th stage, which is evaluated at the
/// step's solution (first same as last, 12 forces per step); error weights of order 5 and 3, combined into
/// Hairer's stretched estimate (engines/adaptive_rkn.hpp).
inline RknTableau<bigcomplex> tableau() {
  const std::size_t s = 13;
  const bigcomplex zero(big("0"));
  std::vector<std::vector<bigcomplex>> A(s, std::vector<bigcomplex>(s, zero));
  for (std::size_t i = 0; i < s; ++i)
    for (std::size_t j = 0; j < a()[i].size(); ++j) A[i][j] = bigcomplex(big(a()[i][j]));
  RknTableau<bigcomplex> t;
  for (const auto& x : c()) t.c.push_back(bigcomplex(big(x)));
  // w A: the position coefficients of a stage (row i of A^2 is A[i] A) or weights (b A) from its velocity ones.
  auto times_a = [&](const std::vector<bigcomplex>& w) {
    std::vector<bigcomplex> out(s, zero);
    for (std::size_t j = 0; j < s; ++j)
      for (std::size_t i = j + 1; i < s; ++i) out[j] = out[j] + w[i] * A[i][j];
    return out;
  };
  t.av = A;
  for (const auto& row : A) t.a.push_back(times_a(row));
  // The weights b are the 13th row of A (its last entry 0); the embedded weights b - e5.
  std::vector<bigcomplex> b(A[s - 1]), bhat(s, zero);
  for (std::size_t i = 0; i < s; ++i) bhat[i] = b[i] - bigcomplex(big(e5()[i]));
  t.B = b;
  t.b = times_a(b);
  t.Bhat = bhat;
  t.bhat = times_a(bhat);
  t.general_order = 8;
  t.general_embedded_order = 5;
  // The third-order weights of the stretched estimate.
  std::vector<bigcomplex> b3(s, zero);
  b3[0] = bigcomplex(big("0.244094488188976377952755905512"));
  b3[8] = bigcomplex(big("0.733846688281611857341361741547"));
  b3[11] = bigcomplex(big("0.220588235294117647058823529412e-1"));
  t.Blow = b3;
  t.blow = times_a(b3);
  return t;
}

}  // namespace dop853

inline std::vector<MethodDef> dop853_methods() {
  return {{{.name = "DOP853-adaptive",
            .family = "rkn",
            .order = 8,
            .adaptive = true,
            .velocity = true,
            .published_digits = 28,
            .source = "Hairer, Norsett & Wanner, Solving ODEs I (1993), sec. II.10 and II.14; Prince & Dormand, J. "
                      "Comput. Appl. Math. 7 (1981) 67",
            .description = "Dormand-Prince DOP853 in Nystrom form for y'' = f(t, y, y'): order 8, step-size control "
                           "from its embedded weights of orders 5 and 3 (Hairer's estimate)",
            .aliases = {"DOP853"}},
           [] { return MethodData{dop853::tableau()}; }}};
}

}  // namespace nystrom::methods
