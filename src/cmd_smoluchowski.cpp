// `nystrom smoluchowski --potential double-well --dims 1 --grid 64 --box 6 --beta 1 --diffusion 1 [--method M8]
//  --dt 0.01 --steps 100 [--x0 0] [--width 0.25] [--initial-file FILE] [--potential-file FILE] [--rates N]
//  [--density-file FILE] [--json]`: the Smoluchowski equation on the periodic grid (quantum/smoluchowski.hpp).
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/quantum/smoluchowski.hpp"
#include "output_file.hpp"

namespace {

using nystrom::cli::Bound;
using nystrom::cli::UsageError;
using namespace nystrom::quantum;

struct Options {
  std::string potential = "double-well";
  std::string potential_file, initial_file, density_file;
  int dims = 1;
  int grid = 64;
  std::string box = "6";
  std::string beta = "1", diffusion = "1";
  std::string method;  // empty: M8
  std::string dt = "0.01";
  long steps = 100;
  std::string x0, width;  // empty: the Gaussian's defaults (0 and 0.25)
  int rates = 0;
  int threads = 1;
  bool json = false;
};

SmoluchowskiResult run(const Options& o) {
  SmoluchowskiProblem<double> p;
  p.dims = o.dims;
  p.grid = o.grid;
  p.box = nystrom::cli::parse_double(o.box, "--box", Bound::positive);
  p.potential = o.potential;
  p.beta = nystrom::cli::parse_double(o.beta, "--beta", Bound::positive);
  p.diffusion = nystrom::cli::parse_double(o.diffusion, "--diffusion", Bound::positive);
  const Grid<double> grid(o.dims, o.grid, p.box);
  if (!o.potential_file.empty())
    p.values = nystrom::cli::read_grid_values(o.potential_file, "--potential-file", grid.size());
  if (!o.initial_file.empty()) {
    if (!o.x0.empty() || !o.width.empty())
      throw UsageError("--initial-file replaces the Gaussian: give no --x0 or --width with it");
    p.initial = nystrom::cli::read_grid_values(o.initial_file, "--initial-file", grid.size());
  } else {
    if (!o.x0.empty()) p.x0 = nystrom::cli::parse_double_list(o.x0, "--x0");
    if (!o.width.empty()) p.width = nystrom::cli::parse_double(o.width, "--width", Bound::positive);
  }
  p.rates = o.rates;
  p.fft.threads = o.threads;
  p.keep_density = !o.density_file.empty();
  return smoluchowski(p, o.method, nystrom::cli::parse_double(o.dt, "--dt", Bound::positive), o.steps);
}

/// One line per grid point: the coordinates, the density and the Boltzmann density.
std::string density_text(const Options& o, const SmoluchowskiResult& r) {
  const Grid<double> g(o.dims, o.grid, nystrom::cli::parse_double(o.box, "--box", Bound::positive));
  std::string s =
      "# x_1 .. x_d, rho(t), rho_boltzmann (nystrom smoluchowski, t = " + fmt::format("{:.17g}", r.time) + ")\n";
  int idx[3] = {0, 0, 0};
  for (std::size_t i = 0; i < r.density.size(); ++i) {
    g.indices(i, idx);
    for (int a = 0; a < o.dims; ++a) s += fmt::format("{:.17g} ", g.coordinate(idx[a]));
    s += fmt::format("{:.17g} {:.17g}\n", r.density[i], r.boltzmann[i]);
  }
  return s;
}

nlohmann::json to_json(const Options& o, const SmoluchowskiResult& r) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["method"] = r.method;
  j["order"] = r.order;
  j["potential"] = o.potential_file.empty() ? o.potential : "file";
  j["initial"] = o.initial_file.empty() ? "gaussian" : "file";
  j["dims"] = o.dims;
  j["grid"] = o.grid;
  j["box"] = nystrom::cli::parse_double(o.box, "--box");
  j["beta"] = nystrom::cli::parse_double(o.beta, "--beta");
  j["diffusion"] = nystrom::cli::parse_double(o.diffusion, "--diffusion");
  j["dt"] = r.dt;
  j["steps"] = r.steps;
  j["time"] = r.time;
  j["mass"] = r.mass;
  j["mass_drift"] = r.mass_drift;
  j["min_density"] = r.min_density;
  j["negative_mass"] = r.negative_mass;
  j["imaginary_part"] = r.imaginary_part;
  j["mean"] = r.mean;
  j["variance"] = r.variance;
  j["boltzmann_distance"] = r.boltzmann_distance;
  j["exact_solution"] = r.exact_solution.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.exact_solution);
  j["exact_error"] = num(r.exact_error);
  j["rates"] = r.rates;
  j["rate_residuals"] = r.rate_residuals;
  j["kramers_rate"] = num(r.kramers_rate);
  j["fft_count"] = r.fft_count;
  j["seconds"] = r.seconds;
  return j;
}

nystrom::cli::Registrar reg(
    "smoluchowski", "The Smoluchowski (overdamped Fokker-Planck) equation on a periodic grid", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--potential", o->potential, "harmonic, double-well, free (docs/diffusion.md)")
          ->capture_default_str();
      app.add_option("--potential-file", o->potential_file,
                     "U's values: one number per grid point, row-major (last axis fastest), at x_i = -L/2 + i L/n; "
                     "# starts a comment");
      app.add_option("--dims", o->dims, "Dimensions: 1, 2 or 3")->capture_default_str();
      app.add_option("--grid", o->grid, "Grid points per axis (at least 16)")->capture_default_str();
      app.add_option("--box", o->box, "Box length L (the box is [-L/2, L/2) per axis)")->capture_default_str();
      app.add_option("--beta", o->beta, "Inverse temperature 1/kT")->capture_default_str();
      app.add_option("--diffusion", o->diffusion, "Diffusion coefficient D")->capture_default_str();
      app.add_option("--method", o->method,
                     "A forward splitting or MPE method (M4..M16, mpe:K1,K2,..., 4A, AC1, BC1, ...); default M8");
      app.add_option("--dt", o->dt, "Time step")->capture_default_str();
      app.add_option("--steps", o->steps, "Number of steps")->capture_default_str();
      app.add_option("--x0", o->x0, "Centre of the initial Gaussian density: one number or one per axis (default 0)");
      app.add_option("--width", o->width, "Standard deviation of the initial Gaussian per axis (default 0.25)");
      app.add_option("--initial-file", o->initial_file,
                     "Initial density: one value per grid point, row-major like --potential-file; normalised on input");
      app.add_option("--rates", o->rates, "The N lowest nonzero relaxation rates (JSON: rates, rate_residuals)")
          ->capture_default_str();
      app.add_option("--density-file", o->density_file,
                     "Write the final density and the Boltzmann density, one grid point per line");
      app.add_option("--threads", o->threads, "FFTW threads")->capture_default_str();
      app.add_flag("--json", o->json, "Print one JSON object");
      return [o]() {
        if (o->grid <= 0) throw UsageError("--grid must be positive, got " + std::to_string(o->grid));
        if (o->dims < 1 || o->dims > 3) throw UsageError("--dims must be 1, 2 or 3, got " + std::to_string(o->dims));
        if (o->steps < 0) throw UsageError("--steps must not be negative");
        if (o->threads < 1) throw UsageError("--threads must be positive");
        if (o->rates < 0 || o->rates > 100) throw UsageError("--rates must be between 0 and 100");
        for (const auto* s : {&o->box, &o->beta, &o->diffusion, &o->dt})
          nystrom::cli::parse_double(*s,
                                     s == &o->box    ? "--box"
                                     : s == &o->beta ? "--beta"
                                     : s == &o->dt   ? "--dt"
                                                     : "--diffusion",
                                     Bound::positive);
        const SmoluchowskiResult r = run(*o);
        if (!o->density_file.empty()) nystrom::cli::write_file_atomic(o->density_file, density_text(*o, r));
        if (o->json) {
          std::cout << to_json(*o, r).dump(2) << "\n";
          return 0;
        }
        fmt::print("method         {} (order {})\n", r.method, r.order);
        fmt::print("problem        {} in {}D, {} points per axis, box {}, beta {}, D {}\n",
                   o->potential_file.empty() ? o->potential : "potential from file", o->dims, o->grid, o->box, o->beta,
                   o->diffusion);
        fmt::print("steps          {} of {:.6g} (time {:.6g})\n", r.steps, r.dt, r.time);
        fmt::print("mass           {:.15f} (drift {:+.3e})\n", r.mass, r.mass_drift);
        fmt::print("min density    {:.3e} (negative mass {:.3e})\n", r.min_density, r.negative_mass);
        std::string m, v;
        for (double x : r.mean) m += fmt::format(" {:.12f}", x);
        for (double x : r.variance) v += fmt::format(" {:.12f}", x);
        fmt::print("<x>           {}\nvariance      {}\n", m, v);
        fmt::print("to Boltzmann   {:.6e} (L1)\n", r.boltzmann_distance);
        if (!r.exact_solution.empty())
          fmt::print("error          {:.6e} (L1, against the {} density)\n", r.exact_error, r.exact_solution);
        for (std::size_t k = 0; k < r.rates.size(); ++k)
          fmt::print("rate {:<9} {:.12f} (residual {:.1e})\n", k + 1, r.rates[k], r.rate_residuals[k]);
        if (std::isfinite(r.kramers_rate))
          fmt::print("Kramers        {:.12f} (high-barrier estimate of rate 1)\n", r.kramers_rate);
        fmt::print("FFTs           {}\n", r.fft_count);
        fmt::print("time           {:.6f} s\n", r.seconds);
        return 0;
      };
    });

}  // namespace
