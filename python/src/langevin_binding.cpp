// nystrom._core.langevin: Langevin path ensembles of the built-in one-dimensional problems
// (nystrom/stochastic/potentials.hpp), the solver of `nystrom langevin`. The paths run in blocks with the GIL
// released; between blocks Python checks for Ctrl-C and reports progress. A block is a whole number of chunks
// of paths, so the result is bitwise that of one run (nystrom/stochastic/langevin.hpp). langevin_partial and
// langevin_finish split the paths over executors (other processes, Dask, MPI) with the same result. Every check
// of the input is the library's (nystrom::invalid_input reaches Python as ValueError with its one-line message).
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "langevin_binding.hpp"
#include "nystrom/stochastic/potentials.hpp"
#include "nystrom/stochastic/splitting_law.hpp"

namespace nystrom::python {

namespace py = pybind11;
namespace st = nystrom::stochastic;

namespace {

/// The arguments every entry point shares.
struct Request {
  std::string potential;
  double omega, gamma, kT, q0, v0;
  std::string method;
  double h, t_end;
  long paths;
  std::uint64_t seed;
  std::vector<long> extrapolate;
  int threads;

  st::Problem1D problem() const { return st::builtin_problem_1d(potential, gamma, kT, t_end, q0, v0, omega); }
  st::LangevinOptions options() const {
    st::LangevinOptions o;
    o.method = method;
    o.h = h;
    o.paths = paths;
    o.seed = seed;
    o.extrapolate = extrapolate;
    o.threads = threads;
    return o;
  }
};

py::dict estimate(const st::Estimate& e) {
  py::dict d;
  d["value"] = e.value;
  d["stderr"] = e.stderr_;
  return d;
}

py::dict result_dict(const st::LangevinResult& r, std::uint64_t seed) {
  py::dict d, averages, finals;
  py::list members_list;
  for (const auto& ob : r.observables) {
    averages[py::str(ob.name)] = estimate(ob.average);
    finals[py::str(ob.name)] = estimate(ob.final);
  }
  for (std::size_t i = 0; i < r.extrapolate.size(); ++i) {
    py::dict m, ma, mf;
    m["k"] = r.extrapolate[i];
    m["h"] = r.h / static_cast<double>(r.extrapolate[i]);
    for (const auto& ob : r.observables) {
      ma[py::str(ob.name)] = estimate(ob.member_average[i]);
      mf[py::str(ob.name)] = estimate(ob.member_final[i]);
    }
    m["averages"] = ma;
    m["final"] = mf;
    members_list.append(m);
  }
  d["method"] = r.method;
  d["h"] = r.h;
  d["t_end"] = r.t_end;
  d["steps"] = r.steps;
  d["window"] = py::make_tuple(r.window_start, r.t_end);
  d["paths"] = r.paths;
  d["seed"] = seed;
  d["extrapolate"] = r.extrapolate;
  d["coefficients"] = r.coefficients;
  d["order"] = r.order;
  d["force_evaluations"] = r.force_evaluations;
  d["averages"] = averages;
  d["final"] = finals;
  d["members"] = members_list;
  return d;
}

py::dict langevin(const Request& q, const py::object& progress) {
  const auto problem = q.problem();
  const auto o = q.options();
  st::check_langevin(problem, o);
  st::LangevinPartial all;
  // blocks of about 2e7 force evaluations (a tenth of a second or so), at least one chunk per thread
  double members = 0;
  for (long k : q.extrapolate) members += static_cast<double>(k);
  const double per_path = std::max(1.0, q.t_end / q.h * members);
  const long per_block = std::max<long>(st::chunk_paths * std::max(1, q.threads),
                                        static_cast<long>(2e7 / per_path) / st::chunk_paths * st::chunk_paths);
  for (long done = 0; done < q.paths;) {
    const long n = std::min(per_block, q.paths - done);
    st::LangevinPartial part;
    {
      py::gil_scoped_release free;
      part = st::run_langevin_paths(problem, o, done, n);
    }
    all.merge(part);
    done += n;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (!progress.is_none()) progress(done, q.paths);
  }
  return result_dict(st::finish_langevin(problem, o, all), q.seed);
}

// A partial result as plain Python data (picklable, for executors): (first_path, paths, force_evaluations,
// observables, members, [chunk, ...]), each chunk a list of (n, mean, m2) triples of the final values, then of
// the time averages.
py::tuple partial_to_python(const st::LangevinPartial& p) {
  py::list chunks;
  for (const auto& c : p.chunks) {
    std::vector<double> flat;
    for (const auto* v : {&c.final_stats, &c.average_stats})
      for (const auto& s : *v) flat.insert(flat.end(), {s.n, s.mean, s.m2});
    chunks.append(py::cast(flat));
  }
  return py::make_tuple(p.first_path, p.paths, p.force_evaluations, p.observables, p.members, chunks);
}

st::LangevinPartial partial_from_python(const py::tuple& t) {
  if (t.size() != 6) throw invalid_input("a Langevin partial result is a tuple of 6 items");
  st::LangevinPartial p;
  p.first_path = t[0].cast<long>();
  p.paths = t[1].cast<long>();
  p.force_evaluations = t[2].cast<long long>();
  p.observables = t[3].cast<std::size_t>();
  p.members = t[4].cast<std::size_t>();
  const std::size_t n = p.observables * p.members;
  for (const auto& item : t[5].cast<py::list>()) {
    const auto flat = item.cast<std::vector<double>>();
    if (flat.size() != 6 * n) throw invalid_input("a Langevin partial result has a chunk of the wrong size");
    st::LangevinPartial::Chunk c;
    for (std::size_t m = 0; m < n; ++m) {
      c.final_stats.push_back({flat[3 * m], flat[3 * m + 1], flat[3 * m + 2]});
      c.average_stats.push_back({flat[3 * (n + m)], flat[3 * (n + m) + 1], flat[3 * (n + m) + 2]});
    }
    p.chunks.push_back(std::move(c));
  }
  return p;
}

py::tuple langevin_partial(const Request& q, long first_path, long count) {
  const auto problem = q.problem();
  st::LangevinPartial p;
  {
    py::gil_scoped_release free;
    p = st::run_langevin_paths(problem, q.options(), first_path, count);
  }
  return partial_to_python(p);
}

py::dict langevin_finish(const Request& q, const py::list& parts) {
  const auto problem = q.problem();
  st::LangevinPartial all;
  for (const auto& part : parts) all.merge(partial_from_python(part.cast<py::tuple>()));
  if (all.first_path != 0 || all.paths != q.paths)
    throw invalid_input("the partial results cover paths " + std::to_string(all.first_path) + ".." +
                        std::to_string(all.first_path + all.paths) + ", not 0.." + std::to_string(q.paths));
  return result_dict(st::finish_langevin(problem, q.options(), all), q.seed);
}

// The stationary law of a built-in problem's splitting on a phase-space grid (the keys of `nystrom langevin
// --stationary-law --json`).
py::dict stationary_law(const std::string& potential, double omega, double gamma, double kT, double q0,
                        const std::string& method, double h, const std::vector<long>& extrapolate, int grid_points) {
  st::check_front_end_grid_points(grid_points, "grid_points");
  const auto problem = st::builtin_problem_1d(potential, gamma, kT, 1.0, q0, 0.0, omega);
  st::StationaryLawOptions o;
  o.method = method;
  o.h = h;
  o.extrapolate = extrapolate;
  o.grid.nq = o.grid.nv = grid_points;
  st::StationaryLawResult r;
  {
    py::gil_scoped_release free;
    r = st::stationary_law(problem, o);
  }
  py::dict d, avg, boltzmann, grid;
  for (std::size_t b = 0; b < r.observable_names.size(); ++b) {
    avg[py::str(r.observable_names[b])] = r.averages[b];
    boltzmann[py::str(r.observable_names[b])] = r.boltzmann[b];
  }
  py::list members;
  for (std::size_t i = 0; i < r.extrapolate.size(); ++i) {
    py::dict m, ma;
    m["k"] = r.extrapolate[i];
    m["h"] = r.h / static_cast<double>(r.extrapolate[i]);
    m["steps"] = r.steps[i];
    for (std::size_t b = 0; b < r.observable_names.size(); ++b) ma[py::str(r.observable_names[b])] = r.members[i][b];
    m["stationary"] = ma;
    members.append(m);
  }
  grid["points"] = py::make_tuple(r.grid.nq, r.grid.nv);
  grid["q"] = py::make_tuple(r.grid.q_min, r.grid.q_max);
  grid["v_max"] = r.grid.v_max;
  d["method"] = r.method;
  d["h"] = r.h;
  d["extrapolate"] = r.extrapolate;
  d["coefficients"] = r.coefficients;
  d["order"] = r.order;
  d["stationary"] = avg;
  d["boltzmann"] = boltzmann;
  d["members"] = members;
  d["grid"] = grid;
  d["resolution"] = r.resolution;
  d["edge"] = r.edge;
  return d;
}

}  // namespace

void register_langevin(py::module_& m) {
  py::class_<Request>(m, "LangevinRequest")
      .def(py::init<std::string, double, double, double, double, double, std::string, double, double, long,
                    std::uint64_t, std::vector<long>, int>(),
           py::arg("potential"), py::arg("omega"), py::arg("gamma"), py::arg("kT"), py::arg("q0"), py::arg("v0"),
           py::arg("method"), py::arg("h"), py::arg("t_end"), py::arg("paths"), py::arg("seed"), py::arg("extrapolate"),
           py::arg("threads"));
  m.def(
      "langevin_check", [](const Request& q) { st::check_langevin(q.problem(), q.options()); }, py::arg("request"),
      "The library's checks of a request (ValueError with one line)");
  m.def("langevin", &langevin, py::arg("request"), py::arg("progress"),
        "Langevin paths of a built-in problem (nystrom.langevin checks the arguments and wraps the result)");
  m.def("langevin_partial", &langevin_partial, py::arg("request"), py::arg("first_path"), py::arg("count"),
        "The statistics of the paths first_path .. first_path + count - 1 (first_path a multiple of 64) as plain, "
        "picklable data for langevin_finish");
  m.def("stationary_law", &stationary_law, py::arg("potential"), py::arg("omega"), py::arg("gamma"), py::arg("kT"),
        py::arg("q0"), py::arg("method"), py::arg("h"), py::arg("extrapolate"), py::arg("grid_points"),
        "The exact stationary averages of a splitting and its extrapolation from its law on a phase-space grid "
        "(nystrom.stationary_law checks the arguments and wraps the result)");
  m.def("langevin_finish", &langevin_finish, py::arg("request"), py::arg("parts"),
        "Merges partial results (in path order) into the result of nystrom.langevin");
}

}  // namespace nystrom::python
