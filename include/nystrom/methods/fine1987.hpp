// Fine's general Runge-Kutta-Nystrom (RKNG) pairs for y'' = f(t, y, y'): J. M. Fine, "Low order
// practical Runge-Kutta-Nystrom methods", Computing 38 (1987) 281-297. RKNG4(3) (5 stages) and RKNG5(4)
// (7 stages, first same as last: 6 forces per step). Exact rational coefficients; the orders are proved
// by the order test of the general pairs on a velocity-dependent force (tests/engines/test_adaptive_rkn.cpp,
// Rkng.*).
#pragma once

#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

namespace fine1987 {

/// A general RKN pair from strings: c, position coefficients a, velocity coefficients av, weights b, B,
/// embedded weights bhat, Bhat, and the orders of both.
inline RknTableau<bigcomplex> rkng(const std::vector<std::string>& c, const std::vector<std::vector<std::string>>& a,
                                   const std::vector<std::vector<std::string>>& av, const std::vector<std::string>& b,
                                   const std::vector<std::string>& B, const std::vector<std::string>& bhat,
                                   const std::vector<std::string>& Bhat, int order, int embedded_order) {
  RknTableau<bigcomplex> t = tableau(c, a, b, B);
  const RknTableau<bigcomplex> v = tableau(c, av, bhat, Bhat);
  t.av = v.a;
  t.bhat = v.b;
  t.Bhat = v.B;
  t.general_order = order;
  t.general_embedded_order = embedded_order;
  return t;
}

inline RknTableau<bigcomplex> rkng43() {
  return rkng({"0", "2/9", "1/3", "3/4", "1"},
              {{}, {"2/81"}, {"1/36", "1/36"}, {"9/128", "0", "27/128"}, {"11/60", "-3/20", "9/25", "8/75"}},
              {{}, {"2/9"}, {"1/12", "1/4"}, {"69/128", "-243/128", "135/64"}, {"-17/12", "27/4", "-27/5", "16/15"}},
              {"19/180", "0", "63/200", "16/225", "1/120"}, {"1/9", "0", "9/20", "16/45", "1/12"},
              {"116/1395", "0", "567/1550", "176/6975", "4/155"},
              {"107/1125", "0", "1233/2500", "1712/5625", "161/1500"}, 4, 3);
}

inline RknTableau<bigcomplex> rkng54() {
  return rkng({"0", "8/39", "4/13", "5/6", "43/47", "1", "1"},
              {{},
               {"32/1521"},
               {"4/169", "4/169"},
               {"175/5184", "0", "1625/5184"},
               {"-342497279/5618900760", "6827067/46824173", "35048741/102161832", "-2201514/234120865"},
               {"-7079/52152", "767/2173", "14027/52152", "30/2173"},
               {"4817/51600", "0", "388869/1216880", "3276/23575", "-1142053/22015140"}},
              {{},
               {"8/39"},
               {"1/13", "3/13"},
               {"7385/6912", "-9425/2304", "13325/3456"},
               {"223324757/91364240", "-174255393/18272848", "382840094/46824173", "-39627252/234120865"},
               {"108475/36464", "-9633/848", "7624604/806183", "8100/49979", "-4568212/19446707"},
               {"4817/51600", "0", "1685099/3650640", "19656/23575", "-53676491/88060560", "53/240"}},
              {"4817/51600", "0", "388869/1216880", "3276/23575", "-1142053/22015140", "0", "0"},
              {"4817/51600", "0", "1685099/3650640", "19656/23575", "-53676491/88060560", "53/240", "0"},
              {"5705201/63210000", "0", "487384677/1490678000", "3426228/28879375", "-966881509/26968546500", "0", "0"},
              {"5705201/63210000", "0", "704000089/1490678000", "20557368/28879375", "-45443430923/107874186000",
               "31429/294000", "1/25"},
              5, 4);
}

}  // namespace fine1987

inline std::vector<MethodDef> fine1987_methods() {
  const std::string src = "Fine, Computing 38 (1987) 281";
  std::vector<MethodDef> m;
  m.push_back({{.name = "Fine4-adaptive",
                .family = "rkn",
                .order = 4,
                .adaptive = true,
                .velocity = true,
                .source = src,
                .description = "Fine's RKNG4(3) pair for y'' = f(t, y, y'): order 4, step-size control from its "
                               "embedded weights of order 3",
                .aliases = {"RKNG4(3)"}},
               [] { return MethodData{fine1987::rkng43()}; }});
  m.push_back({{.name = "Fine5-adaptive",
                .family = "rkn",
                .order = 5,
                .adaptive = true,
                .velocity = true,
                .source = src,
                .description = "Fine's RKNG5(4) pair for y'' = f(t, y, y'): order 5 (first same as last), step-size "
                               "control from its embedded weights of order 4",
                .aliases = {"RKNG5(4)"}},
               [] { return MethodData{fine1987::rkng54()}; }});
  return m;
}

}  // namespace nystrom::methods
