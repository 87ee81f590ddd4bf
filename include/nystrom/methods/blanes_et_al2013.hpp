// The splitting methods of generalized order for perturbed problems H = A + eps B of S. Blanes, F. Casas,
// A. Farrés, J. Laskar, J. Makazaga and A. Murua, "New families of symplectic splitting methods for numerical
// integration in dynamical astronomy", Appl. Numer. Math. 68 (2013) 58-72, compared on the Solar System by
// A. Farrés, J. Laskar, S. Blanes, F. Casas, J. Makazaga and A. Murua, "High precision symplectic integrators for
// the Solar System", Celest. Mech. Dyn. Astron. 116 (2013) 141-174, and offered by REBOUND (H. Rein, D. Tamayo
// and G. Brown, "High order symplectic integrators for planetary dynamics and their implementation in REBOUND",
// MNRAS 489 (2019) 4632), whose names these are.
//
// A method of generalized order (s1, s2, s3) has the error O(eps h^s1 + eps^2 h^s2 + eps^3 h^s3) (two numbers:
// eps h^s1 + eps^2 h^s2, every higher power of eps at h^s2): the eps^2 h^2 term that limits SABA_n
// (laskar_robutel2001.hpp) on the outer solar system, where eps ~ 1e-3, is gone. All are symmetric ABA schemes
// (drift a_1, kick b_1, drift a_2, ..., kick b_s, drift a_{s+1}, a palindrome) with some negative coefficients.
// The SABAH methods use that [B,[B,[B,A]]] = 0 (B a function of the positions only, A quadratic in the momenta,
// which holds for the Wisdom-Holman splitting in Jacobi coordinates) to reach the same generalized orders with
// fewer stages or smaller error terms.
//
// The coefficients are the published decimals (39 to 40 significant digits; the kick weights of SABA(8,6,4) sum
// to 1 - 5.0e-31 only, so they count as 30 digits); each list below is the first half of a palindrome in time
// order (the middle coefficient, where the count is odd, is the last one listed).
// tests/planetary/test_planetary.cpp checks their sums, and the measured error structure on a two-planet system.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "nystrom/methods/method.hpp"

namespace nystrom::methods {

namespace detail {

/// n coefficients, a palindrome, from its first ceil(n / 2) entries.
inline std::vector<bigfloat> palindrome(const std::vector<const char*>& half, std::size_t n) {
  std::vector<bigfloat> out;
  for (std::size_t i = 0; i < n; ++i) out.push_back(big(half[i < half.size() ? i : n - 1 - i]));
  return out;
}

/// The ABA scheme of s kicks: drift a_1, kick b_1, ..., kick b_s, drift a_{s+1}.
inline SplittingScheme<bigcomplex> aba_scheme(const std::vector<const char*>& drifts,
                                              const std::vector<const char*>& kicks, std::size_t s) {
  const std::vector<bigfloat> a = palindrome(drifts, s + 1), b = palindrome(kicks, s);
  SplittingScheme<bigcomplex> sc;
  for (std::size_t i = 0; i < s; ++i) {
    sc.steps.push_back(drift(a[i]));
    sc.steps.push_back(kick(b[i]));
  }
  sc.steps.push_back(drift(a[s]));
  return sc;
}

struct GeneralizedOrderMethod {
  const char* name;
  const char* alias;
  const char* orders;  // the error terms
  std::size_t kicks;
  int digits;  // to which the published coefficients are consistent (their sums equal 1)
  std::vector<const char*> drifts, kick_weights;
};

inline const std::vector<GeneralizedOrderMethod>& generalized_order_methods() {
  static const std::vector<GeneralizedOrderMethod> m{
      {"SABA(10,6,4)",
       "SABA1064",
       "eps h^10 + eps^2 h^6 + eps^3 h^4",
       8,
       39,
       {"0.03809449742241219545697532230863756534060", "0.1452987161169137492940200726606637497442",
        "0.2076276957255412507162056113249882065158", "0.4359097036515261592231548624010651844006",
        "-0.6538612258327867093807117373907094120024"},
       {"0.09585888083707521061077150377145884776921", "0.2044461531429987806805077839164344779763",
        "0.2170703479789911017143385924306336714532", "-0.01737538195906509300561788011852699719871"}},
      {"SABA(8,6,4)",
       "SABA864",
       "eps h^8 + eps^2 h^6 + eps^3 h^4",
       7,
       30,
       {"0.0711334264982231177779387300061549964174", "0.241153427956640098736487795326289649618",
        "0.521411761772814789212136078067994229991", "-0.333698616227678005726562603400438876027"},
       {"0.183083687472197221961703757166430291072", "0.310782859898574869507522291054262796375",
        "-0.0265646185119588006972121379164987592663", "0.0653961422823734184559721793911134363710"}},
      {"SABA(10,4)",
       "SABA104",
       "eps h^10 + eps^2 h^4",
       7,
       39,
       {"0.04706710064597250612947887637243678556564", "0.1847569354170881069247376193702560968574",
        "0.2827060056798362053243616565541452479160", "-0.01453004174289681837857815229683813033908"},
       {"0.1188819173681970199453503950853885936957", "0.2410504605515015657441667865901651105675",
        "-0.2732866667053238060543113981664559460630", "0.8267085775712504407295884329818044835997"}},
      {"SABAH(8,4,4)",
       "SABAH844",
       "eps h^8 + eps^2 h^4, with [B,[B,[B,A]]] = 0",
       6,
       39,
       {"0.2741402689434018761640565440378637101205", "-0.1075684384401642306251105297063236526845",
        "-0.0480185025906016926911954171508475065370", "0.7628933441747280943044988056386148982021"},
       {"0.6408857951625127177322491164716010349386", "-0.8585754489567828565881283246356000103664",
        "0.7176896537942701388558792081639989754277"}},
      {"SABAH(8,6,4)",
       "SABAH864",
       "eps h^8 + eps^2 h^6 + eps^3 h^4, with [B,[B,[B,A]]] = 0",
       8,
       39,
       {"0.06810235651658372084723976682061164571212", "0.2511360387221033233072829580455350680082",
        "-0.07507264957216562516006821767601620052338", "-0.009544719701745007811488218957217113269121",
        "0.5307579480704471776340674235341732001443"},
       {"0.1684432593618954534310382697756917558148", "0.4243177173742677224300351657407231801453",
        "-0.5858109694681756812309015355404036521923", "0.4930499927320125053698281000239887162321"}},
      {"SABAH(10,6,4)",
       "SABAH1064",
       "eps h^10 + eps^2 h^6 + eps^3 h^4, with [B,[B,[B,A]]] = 0",
       9,
       39,
       {"0.04731908697653382270404371796320813250988", "0.2651105235748785159539480036185693201078",
        "-0.009976522883811240843267468164812380613143", "-0.05992919973494155126395247987729676004016",
        "0.2574761120673404534492282264603316880356"},
       {"0.1196884624585322035312864297489892143852", "0.3752955855379374250420128537687503199451",
        "-0.4684593418325993783650820409805381740605", "0.3351397342755897010393098942949569049275",
        "0.2766711191210800975049457263356834696055"}},
  };
  return m;
}

}  // namespace detail

/// SABA(10,6,4), SABA(8,6,4), SABA(10,4), SABAH(8,4,4), SABAH(8,6,4), SABAH(10,6,4) (aliases without
/// parentheses and commas: SABA1064, ...). Order: the classical order in the step (4); the description gives
/// the error terms in eps and h.
inline std::vector<MethodDef> blanes_et_al2013() {
  std::vector<MethodDef> out;
  for (const auto& m : detail::generalized_order_methods()) {
    out.push_back(
        {{.name = m.name,
          .family = "splitting",
          .order = 4,
          .stages = static_cast<int>(m.kicks),
          .forces_per_step = static_cast<int>(m.kicks),
          .symmetric = true,
          .symplectic = true,
          .published_digits = m.digits,
          .source = "Blanes, Casas, Farres, Laskar, Makazaga & Murua, Appl. Numer. Math. 68 (2013) 58",
          .description = std::to_string(m.kicks) + " kicks, symmetric; error O(" + m.orders + ") for H = A + eps B",
          .aliases = {m.alias}},
         [&m] { return MethodData{detail::aba_scheme(m.drifts, m.kick_weights, m.kicks)}; }});
  }
  return out;
}

}  // namespace nystrom::methods
