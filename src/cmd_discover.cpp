// `nystrom discover [--scheme A|B|both] [--starts N] [--seed S] [--threads T] [--solver newton|lm] [--json]
//                   [--coefficients] [--write DIR]`: solves the fifth-order RKN conditions (2.4) of the Gürkan paper
// from random complex starts, merges duplicates, adjoints and conjugates, polishes in MPFR and classifies the
// methods (REAL / IMAGINARY leading error / OTHER, positive real parts), reporting which published methods
// (AR1, AR2, BR1-BR3, AC1, AC2, BC1, BC2) were found.
// `nystrom discover --six-stage [--from AC1] [--tries N] [--perturbation P] [--seed S] [--write FILE]`: eq (6.1),
// minimise the norm of the (imaginary) sixth-order error terms of a skew-symmetric six-stage method near AC1.
// The --help footer gives the command that rediscovers all of Tables 4.1 and 4.2 and its cost.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "experiments/discover.hpp"
#include "nystrom/analysis/method_file.hpp"
#include "nystrom/methods/catalog.hpp"
#include "output_file.hpp"
#include "progress.hpp"

namespace {

namespace an = nystrom::analysis;
using nystrom::bigcomplex;

struct Options {
  std::string scheme = "both";
  long starts = 2000;
  std::uint64_t seed = 1;
  int threads = 0;
  std::string solver = "newton";
  double box = 2;
  unsigned polish_bits = 256;
  int digits = 20;
  std::string show = "classified";
  bool coefficients = false;
  bool json = false;
  std::string write;
  // six-stage
  bool six = false;
  std::string from = "AC1";
  int tries = 20;
  double perturbation = 0.1;
  unsigned six_bits = 160;
};

int default_threads(int t) {
  if (t > 0) return t;
  const unsigned h = std::thread::hardware_concurrency();
  return h == 0 ? 1 : static_cast<int>(std::min(h, 8u));
}

std::string coef_text(const bigcomplex& c, int digits) {
  const std::string re = an::big_str(c.re, digits);
  if (c.im == 0) return re;
  return re + (c.im < 0 ? " - " : " + ") + an::big_str(boost::multiprecision::abs(c.im), digits) + "i";
}

struct Known {
  std::string name;
  std::vector<an::cd> coefs;
};
std::vector<Known> known_methods() {
  std::vector<Known> k;
  for (const char* n : {"AR1", "AR2", "BR1", "BR2", "BR3", "AC1", "AC2", "BC1", "BC2"}) {
    nystrom::BigPrecision guard(128);
    const auto d = nystrom::resolve_method(n);
    k.push_back({n, an::scheme_coefficients(std::get<nystrom::SplittingScheme<bigcomplex>>(d.build()))});
  }
  return k;
}
std::string match_of(const an::DiscoveredMethod& m, const std::vector<Known>& known) {
  for (const auto& k : known)
    if (an::same_up_to_symmetry(m.coefficients_d, k.coefs, 1e-12)) return k.name;
  return "";
}

bool listed(const an::DiscoveredMethod& m, const std::string& show) {
  if (show == "all") return true;
  if (show == "classified") return m.cls != an::MethodClass::other || m.positive;
  if (show == "real") return m.cls == an::MethodClass::real;
  if (show == "imaginary") return m.cls == an::MethodClass::imaginary;
  if (show == "positive") return m.positive;
  throw nystrom::cli::UsageError("--show must be one of all, classified, real, imaginary, positive");
}

std::string short_class(an::MethodClass c) {
  return c == an::MethodClass::real ? "REAL" : c == an::MethodClass::imaginary ? "IMAG" : "OTHER";
}

int run_search(const Options& o) {
  if (o.digits < 5 || o.digits > 200) throw nystrom::cli::UsageError("--digits must be between 5 and 200");
  std::vector<an::RknForm> forms;
  if (o.scheme == "both") {
    forms = {an::RknForm::A, an::RknForm::B};
  } else {
    forms = {an::parse_rkn_form(o.scheme)};
  }
  listed(an::DiscoveredMethod{}, o.show);  // validate --show early
  if (!o.write.empty()) std::filesystem::create_directories(o.write);
  const auto known = known_methods();
  nlohmann::json out = nlohmann::json::array();
  for (const auto form : forms) {
    an::DiscoverOptions opt;
    opt.form = form;
    opt.starts = o.starts;
    opt.seed = o.seed;
    opt.threads = default_threads(o.threads);
    opt.solver = an::parse_solver(o.solver);
    opt.box = o.box;
    opt.polish_bits = o.polish_bits;
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<nystrom::cli::Progress> progress;
    if (!o.json) progress = std::make_unique<nystrom::cli::Progress>("discover " + an::to_string(form), o.starts);
    const auto rep = an::discover(opt, [&](long done) {
      if (progress) progress->tick(done);
    });
    progress.reset();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<std::string> found;
    for (const auto& m : rep.methods)
      if (auto n = match_of(m, known); !n.empty()) found.push_back(n);
    std::vector<std::string> expected;
    for (const auto& k : known)
      if ((k.name[0] == 'A') == (form == an::RknForm::A)) expected.push_back(k.name);
    if (o.json) {
      nlohmann::json methods = nlohmann::json::array();
      for (const auto& m : rep.methods) {
        if (!listed(m, o.show)) continue;
        nlohmann::json coefs = nlohmann::json::array();
        nystrom::Flow f = an::rkn_first_flow(form);
        for (const auto& c : m.coefficients) {
          coefs.push_back({{"flow", f == nystrom::Flow::drift ? "drift" : "kick"},
                           {"re", an::big_str(c.re, o.digits)},
                           {"im", an::big_str(c.im, o.digits)}});
          f = f == nystrom::Flow::drift ? nystrom::Flow::kick : nystrom::Flow::drift;
        }
        nlohmann::json lead = nlohmann::json::array();
        for (const auto& t : m.leading)
          lead.push_back({{"name", t.name}, {"re", t.value.real()}, {"im", t.value.imag()}});
        methods.push_back({{"class", an::to_string(m.cls)},
                           {"positive", m.positive},
                           {"skew_symmetric", m.skew_symmetric},
                           {"symmetric", m.symmetric},
                           {"error_norm", m.error_norm},
                           {"max_abs_coefficient", m.max_abs_coefficient},
                           {"hits", m.hits},
                           {"first_start", m.first_start},
                           {"digits", m.digits},
                           {"residual", m.residual},
                           {"matches", match_of(m, known)},
                           {"leading", lead},
                           {"coefficients", coefs}});
      }
      out.push_back({{"scheme", an::to_string(form)},
                     {"starts", o.starts},
                     {"seed", o.seed},
                     {"solver", o.solver},
                     {"box", o.box},
                     {"converged", rep.converged},
                     {"distinct", rep.methods.size()},
                     {"singular", rep.not_polished},
                     {"real", rep.count(an::MethodClass::real)},
                     {"imaginary", rep.count(an::MethodClass::imaginary)},
                     {"imaginary_positive", rep.count_positive(an::MethodClass::imaginary)},
                     {"other", rep.count(an::MethodClass::other)},
                     {"other_positive", rep.count_positive(an::MethodClass::other)},
                     {"rediscovered", found},
                     {"seconds", seconds},
                     {"methods", methods}});
    } else {
      fmt::print(
          "{} (Gurkan eq {}), {} random starts in [-{:g},{:g}]^2 per unknown, seed {}, {} ({} threads): {:.1f} s\n",
          an::to_string(form), form == an::RknForm::A ? "3.6" : "3.8", o.starts, o.box, o.box, o.seed, o.solver,
          opt.threads, seconds);
      fmt::print(
          "  {} starts converged; {} distinct methods up to adjoint and conjugation; {} converged points were "
          "singular (not polished)\n",
          rep.converged, rep.methods.size(), rep.not_polished);
      fmt::print("  REAL {}   IMAGINARY {} ({} with positive real parts)   OTHER {} ({} with positive real parts)\n",
                 rep.count(an::MethodClass::real), rep.count(an::MethodClass::imaginary),
                 rep.count_positive(an::MethodClass::imaginary), rep.count(an::MethodClass::other),
                 rep.count_positive(an::MethodClass::other));
      fmt::print("  {:>3} {:<5} {:>3} {:>4} {:>11} {:>8} {:>6} {:>6}  {}\n", "#", "class", "pos", "skew", "|err6|",
                 "max|c|", "hits", "digits", "published");
      int idx = 0;
      for (const auto& m : rep.methods) {
        ++idx;
        if (!listed(m, o.show)) continue;
        fmt::print("  {:>3} {:<5} {:>3} {:>4} {:>11.4e} {:>8.4f} {:>6} {:>6}  {}\n", idx, short_class(m.cls),
                   m.positive ? "+" : "", m.skew_symmetric ? "skew" : "", m.error_norm, m.max_abs_coefficient, m.hits,
                   m.digits, match_of(m, known));
        if (o.coefficients) {
          nystrom::Flow f = an::rkn_first_flow(form);
          for (const auto& c : m.coefficients) {
            fmt::print("        {:<5} {}\n", f == nystrom::Flow::drift ? "drift" : "kick", coef_text(c, o.digits));
            f = f == nystrom::Flow::drift ? nystrom::Flow::kick : nystrom::Flow::drift;
          }
        }
      }
      std::string fs, es;
      for (const auto& n : found) fs += " " + n;
      for (const auto& n : expected) es += " " + n;
      fmt::print("  published methods found:{} (of{})\n", fs.empty() ? " none" : fs, es);
    }
    if (!o.write.empty()) {
      int idx = 0, written = 0;
      for (const auto& m : rep.methods) {
        ++idx;
        if (!listed(m, o.show)) continue;
        const std::string name = fmt::format("{}-{}-{:02}", an::to_string(form), short_class(m.cls), idx);
        const std::string match = match_of(m, known);
        const std::string desc = fmt::format(
            "{} method from the order conditions (2.4); {} leading error, norm {:.4e}{}{}", an::to_string(form),
            an::to_string(m.cls), m.error_norm, m.positive ? ", positive real parts" : "",
            match.empty() ? "" : "; equals " + match + " (Gurkan Tables 4.1/4.2) up to adjoint/conjugation");
        const std::string src =
            fmt::format("nystrom discover --scheme {} --starts {} --seed {} --solver {} (polished, {} digits)",
                        form == an::RknForm::A ? "A" : "B", o.starts, o.seed, o.solver, m.digits);
        const std::string path = (std::filesystem::path(o.write) / (name + ".txt")).string();
        nystrom::BigPrecision guard(o.polish_bits);
        nystrom::cli::write_file_atomic(
            path, an::format_method_file(name, 5, src, desc, m.scheme(), std::min(o.digits * 2, 60)));
        ++written;
      }
      if (!o.json) fmt::print("  wrote {} method files to {}\n", written, o.write);
    }
  }
  if (o.json) std::cout << out.dump(2) << "\n";
  return 0;
}

int run_six(const Options& o) {
  const auto def = nystrom::resolve_method(o.from);
  std::vector<bigcomplex> start;
  {
    nystrom::BigPrecision guard(256);
    const auto data = def.build();
    const auto* sp = std::get_if<nystrom::SplittingScheme<bigcomplex>>(&data);
    if (!sp) throw nystrom::cli::UsageError("--from must name a splitting method");
    start = an::embed_rkna_in_kick_first(*sp);
  }
  an::SkewSearchOptions so;
  so.order = 5;
  so.tries = o.tries;
  so.perturbation = o.perturbation;
  so.seed = o.seed;
  so.polish_bits = o.six_bits;
  so.threads = default_threads(o.threads);
  const auto t0 = std::chrono::steady_clock::now();
  const auto res = an::optimize_skew(start, nystrom::Flow::kick, so);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // the published eq (6.1) method, for comparison
  nystrom::BigPrecision guard(256);
  const auto paper = nystrom::resolve_method("AC1-6");
  an::AnalysisOptions ao;
  ao.degree = 6;
  const auto pa = an::analyze_method(paper, ao);
  const auto paper_coefs = an::scheme_coefficients(std::get<nystrom::SplittingScheme<bigcomplex>>(paper.build()));
  if (res.minima.empty()) throw std::runtime_error("no try converged (raise --tries or change --perturbation)");
  if (o.json) {
    nlohmann::json minima = nlohmann::json::array();
    for (const auto& m : res.minima) {
      nlohmann::json coefs = nlohmann::json::array();
      for (const auto& c : m.coefficients)
        coefs.push_back({{"re", an::big_str(c.re, o.digits)}, {"im", an::big_str(c.im, o.digits)}});
      minima.push_back({{"error_norm", m.error_norm},
                        {"constraint_residual", m.constraint_residual},
                        {"iterations", m.iterations},
                        {"distance_to_published", an::max_distance(an::scheme_coefficients(m.scheme()), paper_coefs)},
                        {"coefficients", coefs}});
    }
    std::cout << nlohmann::json{{"from", o.from},
                                {"start_error_norm", res.minima.front().start_error_norm},
                                {"tries", o.tries},
                                {"failed", res.failed},
                                {"seed", o.seed},
                                {"perturbation", o.perturbation},
                                {"published_error_norm", pa.degrees[5].norm},
                                {"seconds", seconds},
                                {"minima", minima}}
                     .dump(2)
              << "\n";
  } else {
    fmt::print(
        "eq (6.1): skew-symmetric six-stage methods (kick first, 7 kicks, 6 drifts) of order 5 from {} "
        "(norm {:.4e}), {} tries (seed {}, tangent moves up to {:g}): {:.1f} s, {} did not converge\n",
        o.from, res.minima.front().start_error_norm, o.tries, o.seed, o.perturbation, seconds, res.failed);
    fmt::print("  local minima of (sum |X_i|^2)^(1/2) over the degree-6 terms:\n");
    for (const auto& m : res.minima)
      fmt::print("    {:.6e}   (order conditions to {:.1e}; distance to the published eq 6.1 method {:.2e})\n",
                 m.error_norm, m.constraint_residual,
                 an::max_distance(an::scheme_coefficients(m.scheme()), paper_coefs));
    fmt::print("  published eq (6.1) method: norm {:.6e}\n", pa.degrees[5].norm);
    fmt::print("  best method (time order; first half, middle; the rest are complex conjugates in reverse order):\n");
    const auto& b = res.minima.front();
    for (std::size_t k = 0; k <= b.coefficients.size() / 2; ++k)
      fmt::print("    {:<5} {}\n", k % 2 == 0 ? "kick" : "drift", coef_text(b.coefficients[k], o.digits));
  }
  if (!o.write.empty()) {
    const auto& b = res.minima.front();
    const std::string name = std::filesystem::path(o.write).stem().string();
    nystrom::cli::write_file_atomic(
        o.write,
        an::format_method_file(
            an::detail::valid_name(name) ? name : "six-stage", 5,
            fmt::format("nystrom discover --six-stage --from {} --tries {} --seed {}", o.from, o.tries, o.seed),
            fmt::format("skew-symmetric six-stage fifth-order RKN splitting (Gurkan eq 6.1), "
                        "sixth-order error norm {:.4e}",
                        b.error_norm),
            b.scheme(), std::min(2 * o.digits, 45)));
    if (!o.json) fmt::print("  wrote {}\n", o.write);
  }
  return 0;
}

nystrom::cli::Registrar reg(
    "discover", "Find fifth-order RKN splittings from the order conditions (Gurkan sec. 4, eq 6.1)", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--scheme", o->scheme, "A (RKNA, eq 3.6), B (RKNB, eq 3.8) or both")->capture_default_str();
      app.add_option("--starts", o->starts, "Random starts per scheme")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(1, 1000000));
      app.add_option("--seed", o->seed, "Seed of the random starts")->capture_default_str();
      app.add_option("--threads", o->threads, "Threads (0: all cores, at most 8)")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(0, 256));
      app.add_option("--solver", o->solver, "newton (damped) or lm (Levenberg-Marquardt)")->capture_default_str();
      app.add_option("--box", o->box, "Starts uniform in [-box, box] for real and imaginary parts")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(1e-6, 1e6));
      app.add_option("--polish-bits", o->polish_bits, "MPFR precision of the final Newton polish")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(64, 4096));
      app.add_option("--digits", o->digits, "Digits printed")->capture_default_str();
      app.add_option("--show", o->show,
                     "Methods listed: classified (REAL, IMAGINARY, positive), all, real, imaginary, positive")
          ->capture_default_str();
      app.add_flag("--coefficients", o->coefficients, "Print the coefficients of the listed methods");
      app.add_flag("--json", o->json, "JSON output");
      app.add_option(
          "--write", o->write,
          "Write the listed methods as method files into this folder (search) or to this file (--six-stage)");
      app.add_flag("--six-stage", o->six, "Eq (6.1): minimise the sixth-order error of a six-stage method near --from");
      app.add_option("--from", o->from, "Start of --six-stage (an RKNA method)")->capture_default_str();
      app.add_option("--tries", o->tries, "--six-stage: the start plus tries-1 random moves along the constraints")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(1, 100000));
      app.add_option("--perturbation", o->perturbation, "--six-stage: size of the random moves")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(0.0, 1e3));
      app.add_option("--six-bits", o->six_bits, "--six-stage: MPFR precision of the final polish (0: none)")
          ->capture_default_str()
          ->check(nystrom::cli::range_check(0, 4096));
      app.footer(
          "Rediscovering Gurkan's Tables 4.1 and 4.2: `nystrom discover --seed 1` (2000 starts per scheme, the "
          "default)\n"
          "finds all nine published methods (AR1 AR2 AC1 AC2 among the RKNA solutions, BR1 BR2 BR3 BC1 BC2 among the\n"
          "RKNB ones; the last of them first reached at start 219 of RKNA and 436 of RKNB) in about 40 s of processor\n"
          "time for both schemes; each run prints its wall time.\n"
          "Eq (6.1): `nystrom discover --six-stage --from AC1 --tries 6 --seed 5` reaches the basin of the published\n"
          "six-stage method (norm 2.6e-7) and its minimum there, 3.6e-8.");
      return [o] { return o->six ? run_six(*o) : run_search(*o); };
    });

}  // namespace
