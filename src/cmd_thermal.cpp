// `nystrom thermal --potential harmonic --grid 64 --box 20 --beta 1 --beads 4,8,16 --extrapolate 1,2,3 [--json]`:
// the partition function and energy of e^{-beta H} from N-bead products of the primitive propagator and of its
// multi-product extrapolation, exactly on the grid (quantum/thermal.hpp).
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/quantum/thermal.hpp"

namespace {

using nystrom::cli::Bound;
using nystrom::cli::UsageError;
using namespace nystrom::quantum;

struct Options {
  std::string potential = "harmonic";
  std::string potential_file;
  int grid = 64;
  std::string box = "20";
  std::string beta = "1";
  std::string beads = "4,8,16";
  std::string extrapolate = "1,2,3";
  bool json = false;
};

std::vector<long> parse_longs(const std::string& text, const std::string& what) {
  std::vector<long> v;
  for (const auto& item : nystrom::cli::split_list(text, what))
    v.push_back(static_cast<long>(nystrom::cli::parse_integer(item, what, 1, 1000000)));
  return v;
}

nystrom::cli::Registrar reg(
    "thermal", "Partition function and energy from extrapolated path-integral propagators on a grid",
    [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--potential", o->potential,
                     "harmonic, anisotropic, morse, double-well, soft-coulomb, free (docs/diffusion.md)")
          ->capture_default_str();
      app.add_option("--potential-file", o->potential_file,
                     "V's values: one number per grid point at x_i = -L/2 + i L/n; # starts a comment");
      app.add_option("--grid", o->grid, "Grid points (one dimension; 4 to 512)")->capture_default_str();
      app.add_option("--box", o->box, "Box length L (the box is [-L/2, L/2))")->capture_default_str();
      app.add_option("--beta", o->beta, "Inverse temperature")->capture_default_str();
      app.add_option("--beads", o->beads, "Numbers of beads N, comma-separated (one row each)")->capture_default_str();
      app.add_option("--extrapolate", o->extrapolate,
                     "Multi-product sequence k_1,k_2,... of the extrapolated propagator (1: the primitive alone)")
          ->capture_default_str();
      app.add_flag("--json", o->json, "Print one JSON object");
      return [o]() {
        ThermalProblem<double> p;
        p.grid = o->grid;
        if (o->grid < 4 || o->grid > 512)
          throw UsageError("--grid must be between 4 and 512, got " + std::to_string(o->grid));
        p.box = nystrom::cli::parse_double(o->box, "--box", Bound::positive);
        p.beta = nystrom::cli::parse_double(o->beta, "--beta", Bound::positive);
        p.potential = o->potential;
        p.beads = parse_longs(o->beads, "--beads");
        p.extrapolate = parse_longs(o->extrapolate, "--extrapolate");
        if (!o->potential_file.empty())
          p.values =
              nystrom::cli::read_grid_values(o->potential_file, "--potential-file", static_cast<std::size_t>(o->grid));
        const ThermalResult r = thermal(p);
        if (o->json) {
          nlohmann::json j;
          j["potential"] = o->potential_file.empty() ? o->potential : "file";
          j["grid"] = o->grid;
          j["box"] = static_cast<double>(p.box);
          j["beta"] = r.beta;
          j["extrapolate"] = r.extrapolate;
          j["order"] = r.order;
          j["z_exact"] = r.z_exact;
          j["energy_exact"] = r.energy_exact;
          j["levels"] = r.levels;
          auto& rows = j["rows"] = nlohmann::json::array();
          for (const auto& row : r.rows)
            rows.push_back({{"beads", row.beads},
                            {"z_primitive", row.z_primitive},
                            {"energy_primitive", row.energy_primitive},
                            {"z_extrapolated", row.z_extrapolated},
                            {"energy_extrapolated", row.energy_extrapolated}});
          j["seconds"] = r.seconds;
          std::cout << j.dump(2) << "\n";
          return 0;
        }
        fmt::print("{} on {} points, box {}, beta {}; extrapolation {{{}}} (order {})\n",
                   o->potential_file.empty() ? o->potential : "potential from file", o->grid, o->box, o->beta,
                   o->extrapolate, r.order);
        fmt::print("grid exact     Z {:.15e}  E {:.15f}\n", r.z_exact, r.energy_exact);
        fmt::print("{:>8} {:>23} {:>20} {:>23} {:>20}\n", "beads", "Z primitive", "E primitive", "Z extrapolated",
                   "E extrapolated");
        for (const auto& row : r.rows)
          fmt::print("{:>8} {:>23.15e} {:>20.15f} {:>23.15e} {:>20.15f}\n", row.beads, row.z_primitive,
                     row.energy_primitive, row.z_extrapolated, row.energy_extrapolated);
        return 0;
      };
    });

}  // namespace
