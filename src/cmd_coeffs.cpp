// `nystrom coeffs mpe --seq 1,2,3 [--json]`: exact MPE coefficients (Chin eqs 14-15);
// `nystrom coeffs NAME [--digits D] [--json]`: the coefficients of any catalog method.
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <fmt/core.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/methods/catalog.hpp"

namespace {

using nystrom::bigcomplex;

struct Options {
  std::string what;
  std::string seq;
  int order = 0;
  int n = 0;
  long sum = 0;
  int digits = 20;
  bool json = false;
};

std::string show(const nystrom::bigfloat& x, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << x;
  return s.str();
}
std::string show(const bigcomplex& x, int digits) {
  if (x.is_real()) return show(x.re, digits);
  return show(x.re, digits) + (x.im < 0 ? " - " : " + ") + show(boost::multiprecision::abs(x.im), digits) + "i";
}

int mpe(const Options& o) {
  std::vector<long> k;
  const int given = (!o.seq.empty()) + (o.order != 0) + (o.n != 0 || o.sum != 0);
  if (given != 1) throw nystrom::cli::UsageError("coeffs mpe needs exactly one of --seq, --order, or --n with --sum");
  if (!o.seq.empty()) {
    k = nystrom::parse_sequence(o.seq);
  } else if (o.order != 0) {
    if (o.order < 2 || o.order % 2) throw nystrom::cli::UsageError("--order must be a positive even number");
    if (o.order > 400) throw nystrom::cli::UsageError("--order must be at most 400");
    for (long i = 1; i <= o.order / 2; ++i) k.push_back(i);
  } else {
    if (o.n <= 0 || o.sum <= 0) throw nystrom::cli::UsageError("--n and --sum must both be positive");
    k = nystrom::optimal_mpe_sequence(o.n, o.sum);
  }
  const auto m = nystrom::mpe_coefficients(k);
  long tsum = 0;
  for (long x : k) tsum += x;
  if (o.json) {
    nlohmann::json c = nlohmann::json::array();
    for (const auto& x : m.c) c.push_back(x.get_str());
    std::cout << nlohmann::json{{"sequence", k},
                                {"order", m.order()},
                                {"coefficients", c},
                                {"error_coefficient", m.error.get_str()},
                                {"amplification", nystrom::mpe_amplification(m)},
                                {"force_evals_pv", tsum},
                                {"force_evals_vv", tsum + 1}}
                     .dump(2)
              << "\n";
    return 0;
  }
  fmt::print("MPE sequence {{{}}}: order {}, {} force evaluations per step on PV ({} on VV)\n",
             fmt::format("{}", fmt::join(k, ",")), m.order(), tsum, tsum + 1);
  for (std::size_t i = 0; i < k.size(); ++i)
    fmt::print("  c_{:<3} (k = {:>3}) = {:>28}  ~ {:+.17e}\n", i + 1, k[i], m.c[i].get_str(), m.c[i].get_d());
  fmt::print("  e_{} = {}  ~ {:.6e}\n", m.order() + 1, m.error.get_str(), m.error.get_d());
  fmt::print("  sum |c_i| = {:.6g} (rounding amplification)\n", nystrom::mpe_amplification(m));
  return 0;
}

int method(const Options& o) {
  if (o.digits < 1 || o.digits > 1000) throw nystrom::cli::UsageError("--digits must be between 1 and 1000");
  const auto def = nystrom::resolve_method(o.what);
  nystrom::BigPrecision guard(static_cast<unsigned>(o.digits * 3.33 + 64));
  const auto data = def.build();
  nlohmann::json j{{"method", def.info.name}, {"order", def.info.order}, {"source", def.info.source}};
  std::ostringstream text;
  auto str = [&](const bigcomplex& x) { return show(x, o.digits); };
  if (const auto* sp = std::get_if<nystrom::SplittingScheme<bigcomplex>>(&data)) {
    j["family"] = "splitting";
    nlohmann::json steps = nlohmann::json::array();
    text << def.info.name << ": sub-steps in order of application (drift: q += c h v; kick: v += c h a(q))\n";
    for (const auto& s : sp->steps) {
      const char* f = s.flow == nystrom::Flow::drift ? "drift" : "kick";
      steps.push_back({{"flow", f}, {"re", show(s.coef.re, o.digits)}, {"im", show(s.coef.im, o.digits)}});
      text << "  " << f << (s.flow == nystrom::Flow::kick ? " " : "") << "  " << str(s.coef) << "\n";
    }
    j["steps"] = steps;
  } else if (const auto* t = std::get_if<nystrom::RknTableau<bigcomplex>>(&data)) {
    j["family"] = "rkn";
    auto vec = [&](const std::vector<bigcomplex>& v) {
      nlohmann::json a = nlohmann::json::array();
      for (const auto& x : v) a.push_back(str(x));
      return a;
    };
    j["c"] = vec(t->c);
    j["b"] = vec(t->b);
    j["B"] = vec(t->B);
    nlohmann::json a = nlohmann::json::array();
    for (const auto& row : t->a) a.push_back(vec(row));
    j["a"] = a;
    if (!t->bhat.empty()) {  // the embedded weights of a pair
      j["bhat"] = vec(t->bhat);
      j["Bhat"] = vec(t->Bhat);
    }
    if (t->general()) {  // the velocity coefficients of a general (RKNG) tableau
      nlohmann::json av = nlohmann::json::array();
      for (const auto& row : t->av) av.push_back(vec(row));
      j["av"] = av;
    }
    text << def.info.name
         << (t->general() ? ": general RKN tableau for y'' = f(t, y, y') (stage velocities v + h sum av f)\n"
                          : ": RKN tableau (Gurkan eq 2.1)\n");
    for (std::size_t i = 0; i < t->c.size(); ++i) {
      text << "  stage " << i + 1 << ": c = " << str(t->c[i]) << ", b = " << str(t->b[i]) << ", B = " << str(t->B[i]);
      if (!t->bhat.empty()) text << ", bhat = " << str(t->bhat[i]) << ", Bhat = " << str(t->Bhat[i]);
      text << "\n      a =";
      for (std::size_t jx = 0; jx < i; ++jx) text << " " << str(t->a[i][jx]);
      if (t->general()) {
        text << "\n      av =";
        for (std::size_t jx = 0; jx < i; ++jx) text << " " << str(t->av[i][jx]);
      }
      text << "\n";
    }
  } else {
    const auto& m = std::get<nystrom::MpeDef>(data);
    const auto mc = nystrom::mpe_coefficients(m.k);
    j["family"] = "mpe";
    j["sequence"] = m.k;
    j["base"] = m.base_name;
    nlohmann::json c = nlohmann::json::array();
    for (const auto& x : mc.c) c.push_back(x.get_str());
    j["coefficients"] = c;
    j["error_coefficient"] = mc.error.get_str();
    text << def.info.name << ": multi-product expansion over " << m.base_name << "\n";
    for (std::size_t i = 0; i < m.k.size(); ++i) text << "  k = " << m.k[i] << ": c = " << mc.c[i].get_str() << "\n";
    text << "  e_" << mc.order() + 1 << " = " << mc.error.get_str() << "\n";
  }
  std::cout << (o.json ? j.dump(2) + "\n" : text.str());
  return 0;
}

nystrom::cli::Registrar reg("coeffs", "Print coefficients: exact MPE rationals, or any catalog method's table",
                            [](CLI::App& app) {
                              auto o = std::make_shared<Options>();
                              app.add_option("what", o->what, "`mpe`, or a method name/spec")->required();
                              app.add_option("--seq", o->seq, "MPE sequence, e.g. 1,2,3");
                              app.add_option("--order", o->order, "MPE natural sequence of this even order");
                              app.add_option("--n", o->n, "MPE: number of products (with --sum)");
                              app.add_option("--sum", o->sum,
                                             "MPE: optimal sequence of --n members summing to this (eq 16)");
                              app.add_option("--digits", o->digits, "Digits printed for decimal coefficients");
                              app.add_flag("--json", o->json, "Print JSON");
                              return [o]() { return o->what == "mpe" ? mpe(*o) : method(*o); };
                            });

}  // namespace
