// `nystrom quantum --potential harmonic --dims 1 --grid 256 --box 20 [--method KL8] --dt 0.05 --steps 200
//  [--imaginary-time [--converge TOL]] [--x0 1] [--p0 0] [--initial-file FILE] [--g 0]
//  [--precision double|long-double] [--json] [--plot FILE.png]`
#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "nystrom/quantum/solve.hpp"
#include "nystrom/solve/checkpoint.hpp"  // fnv1a64
#include "plot.hpp"
#include "reported_error.hpp"
#ifdef NYSTROM_HAVE_MPI
#include "nystrom/quantum/fftw_mpi.hpp"
#endif

namespace {

using nystrom::cli::Bound;
using nystrom::cli::UsageError;
using namespace nystrom::quantum;

struct Options {
  std::string potential = "harmonic";
  std::string potential_file;
  int dims = 1;
  int grid = 256;
  std::string box = "20";
  std::string method;  // empty: default_method() (KL8 in real time, M8 in imaginary time)
  std::string dt = "0.05";
  long steps = 200;
  bool imaginary = false;
  bool allow_negative = false;
  std::string converge;
  std::string initial_file;
  std::string x0, p0, width;  // empty: not given (the Gaussian's defaults 1, 0 and 1)
  std::string g = "0";
  std::string precision = "double";
  int threads = 1;
  bool json = false;
  bool autocorrelation = false;
  int states = 1;
  std::string plot;
};

/// MPI for one run when the tool was started by an MPI launcher (OpenMPI's mpirun sets OMPI_COMM_WORLD_SIZE,
/// MPICH's PMI_SIZE, PMIx launchers PMIX_RANK); otherwise none, so a plain run neither needs nor starts MPI.
/// Ranks other than 0 write nothing: every rank computes the same observables of the whole grid. Their
/// standard error is kept aside for the one failure that only they can report (fail()).
class MpiSession {
 public:
  MpiSession() {
#ifdef NYSTROM_HAVE_MPI
    if (!std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMI_SIZE") && !std::getenv("PMIX_RANK")) return;
    MPI_Init(nullptr, nullptr);
    active_ = true;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
    if (rank_ != 0) {
      err_ = ::dup(STDERR_FILENO);
      const int null = ::open("/dev/null", O_WRONLY);
      if (null >= 0) {
        ::dup2(null, STDOUT_FILENO);
        ::dup2(null, STDERR_FILENO);
        ::close(null);
      }
    }
#endif
  }
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  ~MpiSession() {
#ifdef NYSTROM_HAVE_MPI
    if (active_) MPI_Finalize();
    if (err_ >= 0) ::close(err_);
#endif
  }
  bool active() const { return active_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

  /// Before any rank starts the run: every rank must have read its input (`failure`: empty, or why not) and
  /// hold the same arguments and input files (`fingerprint`, a hash of them). Otherwise every rank throws the
  /// same UsageError (the first failing rank's reason, or the mismatch), so the run ends everywhere with one
  /// line and exit status 2, before a rank waits for another or plans a transform of another grid.
  void agree([[maybe_unused]] std::uint64_t fingerprint, const std::string& failure) const {
#ifdef NYSTROM_HAVE_MPI
    if (active_) {
      int first = failure.empty() ? size_ : rank_;
      MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
      if (first < size_) {
        std::string why = failure;
        int n = static_cast<int>(why.size());
        MPI_Bcast(&n, 1, MPI_INT, first, MPI_COMM_WORLD);
        why.resize(static_cast<std::size_t>(n));
        MPI_Bcast(why.data(), n, MPI_CHAR, first, MPI_COMM_WORLD);
        refuse(first == 0 ? why : "MPI rank " + std::to_string(first) + ": " + why);
      }
      unsigned long long lo = fingerprint, hi = fingerprint;
      MPI_Allreduce(MPI_IN_PLACE, &lo, 1, MPI_UNSIGNED_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
      MPI_Allreduce(MPI_IN_PLACE, &hi, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
      if (lo != hi)
        refuse(
            "the MPI ranks were given different arguments or input files: every rank must run the same command on "
            "the same files");
      return;
    }
#endif
    if (!failure.empty()) throw UsageError(failure);
  }

  /// Every rank ends with the same refusal: rank 0 prints its one line before any rank may exit (a rank that
  /// exited first would make the launcher stop rank 0 before it printed), then every rank exits with status 2.
  [[noreturn]] void refuse([[maybe_unused]] const std::string& why) const {
#ifdef NYSTROM_HAVE_MPI
    if (rank_ == 0) {
      const std::string line = nystrom::cli::error_line(why);
      if (::write(STDERR_FILENO, line.data(), line.size()) < 0) {
        // nothing more to report with
      }
    }
    MPI_Barrier(MPI_COMM_WORLD);
#endif
    throw nystrom::cli::ReportedUsageError(why);
  }

  /// A failure on this rank alone during the run (out of memory, a system error): the other ranks would wait
  /// for it forever, so it is reported on this rank's standard error and every rank is stopped (exit 2).
  void fail([[maybe_unused]] const std::string& why) const {
#ifdef NYSTROM_HAVE_MPI
    if (active_ && size_ > 1) {
      const std::string line = nystrom::cli::error_line("MPI rank " + std::to_string(rank_) + ": " + why);
      const int fd = rank_ == 0 ? STDERR_FILENO : err_;
      if (fd >= 0 && ::write(fd, line.data(), line.size()) < 0) {
        // nothing more to report with
      }
      MPI_Abort(MPI_COMM_WORLD, 2);
    }
#endif
  }

 private:
  bool active_ = false;
  int rank_ = 0, size_ = 1;
  int err_ = -1;  // rank != 0: its standard error
};

/// The text of a regular file of at most max_bytes bytes (nystrom::read_input_file: a directory, a FIFO or a
/// device is refused, since reading one could block or never end).
std::string read_bounded(const std::string& path, const std::string& flag, std::uintmax_t max_bytes) {
  return nystrom::read_input_file<UsageError>(path, flag, static_cast<std::size_t>(max_bytes));
}

/// The initial wave function from a text file: one grid point per line in row-major order (last axis fastest,
/// the order of --potential-file), "re im" or "re" (imaginary part 0); `#` to the end of a line a comment, blank
/// lines skipped.
std::vector<std::complex<double>> read_initial_file(const std::string& path, std::size_t points) {
  std::istringstream in(read_bounded(path, "--initial-file", nystrom::cli::grid_file_bound(points)));
  std::vector<std::complex<double>> v;
  std::string line;
  for (long number = 1; std::getline(in, line); ++number) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::vector<std::string> w;
    for (std::string x; words >> x;) w.push_back(x);
    if (w.empty()) continue;
    const std::string where = "--initial-file line " + std::to_string(number);
    if (w.size() > 2)
      throw UsageError(where + " has " + std::to_string(w.size()) + " numbers: one grid point per line, 're im'");
    if (v.size() == points)
      throw UsageError("--initial-file '" + path + "' has more values than the " + std::to_string(points) +
                       " grid points");
    v.emplace_back(nystrom::cli::parse_double(w[0], where + ", real part"),
                   w.size() == 2 ? nystrom::cli::parse_double(w[1], where + ", imaginary part") : 0.0);
  }
  if (v.size() != points)
    throw UsageError("--initial-file '" + path + "' has " + std::to_string(v.size()) + " values for " +
                     std::to_string(points) + " grid points");
  return v;
}

/// A hash of everything a run depends on: its options and the bytes of its input files; `failure` is set
/// (instead of throwing) when an input file cannot be read, so that MPI ranks can agree first
/// (MpiSession::agree).
std::uint64_t fingerprint(const Options& o, std::string& failure) {
  std::ostringstream s;
  s << o.potential << '\0' << o.potential_file << '\0' << o.dims << '\0' << o.grid << '\0' << o.box << '\0' << o.method
    << '\0' << o.dt << '\0' << o.steps << '\0' << o.imaginary << '\0' << o.allow_negative << '\0' << o.converge << '\0'
    << o.initial_file << '\0' << o.x0 << '\0' << o.p0 << '\0' << o.width << '\0' << o.g << '\0' << o.precision << '\0'
    << o.threads << '\0' << o.json << '\0' << o.autocorrelation << '\0' << o.states << '\0' << o.plot << '\0';
  std::string text = s.str();
  std::size_t points = 1;
  for (int d = 0; d < o.dims; ++d) points *= static_cast<std::size_t>(o.grid);
  const std::pair<const std::string*, const char*> files[] = {{&o.potential_file, "--potential-file"},
                                                              {&o.initial_file, "--initial-file"}};
  for (const auto& [path, flag] : files) {
    if (path->empty()) continue;
    try {
      text += read_bounded(*path, flag, nystrom::cli::grid_file_bound(points));
      text += '\0';
    } catch (const std::exception& e) {
      failure = e.what();
    }
  }
  return nystrom::checkpoint_detail::fnv1a64(text);
}

/// "1" (first axis) or "1,0,-0.5" (one value per axis).
std::vector<double> parse_vector(const std::string& text, const std::string& what, int dims) {
  const std::vector<double> v = nystrom::cli::parse_double_list(text, what);
  if (static_cast<int>(v.size()) > dims)
    throw UsageError(what + " has " + std::to_string(v.size()) + " components for " + std::to_string(dims) +
                     " dimension(s)");
  return v;
}

/// Draws <x_1>(t) (or the energy) and the norm with gnuplot: the data inline in the script, nothing of the
/// user's in it; the picture is written as every result file of the tool (nystrom::cli::render_png).
void plot_samples(const std::string& target, const QuantumResult& r, bool imaginary) {
  std::ostringstream script;
  script.precision(17);
  script << "set terminal pngcairo size 900,600\nset output 'plot.png'\nset grid\n"
         << "set xlabel '" << (imaginary ? "imaginary time" : "time") << "'\n"
         << "set ylabel '" << (imaginary ? "energy" : "<x_1>") << "'\nset y2label 'norm'\nset y2tics\n"
         << "$data << EOD\n";
  for (const auto& s : r.samples)
    script << s.time << " " << (imaginary ? s.energy : s.mean_x.at(0)) << " " << s.norm << "\n";
  script << "EOD\n"
         << "plot $data using 1:2 with lines lw 2 title '" << (imaginary ? "energy" : "<x_1>")
         << "', $data using 1:3 axes x1y2 with lines title 'norm'\n";
  nystrom::cli::render_png(target, script.str());
}

template <class R>
QuantumResult run(const Options& o, [[maybe_unused]] const MpiSession& mpi) {
  QuantumProblem<R> p;
#ifdef NYSTROM_HAVE_MPI
  if (mpi.active()) p.transforms = distributed_transforms<R>(MPI_COMM_WORLD);
#endif
  p.dims = o.dims;
  p.grid = o.grid;
  p.box = static_cast<R>(nystrom::cli::parse_double(o.box, "--box", Bound::positive));
  p.potential = o.potential;
  if (!o.potential_file.empty()) {
    const Grid<R> grid(o.dims, o.grid, p.box);
    for (double x : nystrom::cli::read_grid_values(o.potential_file, "--potential-file", grid.size()))
      p.values.push_back(static_cast<R>(x));
  }
  p.g = static_cast<R>(nystrom::cli::parse_double(o.g, "--g"));
  p.time = o.imaginary ? TimeKind::imaginary : TimeKind::real;
  if (!o.initial_file.empty()) {
    if (!o.x0.empty() || !o.p0.empty() || !o.width.empty())
      throw UsageError("--initial-file replaces the Gaussian: give no --x0, --p0 or --width with it");
    const Grid<R> grid(o.dims, o.grid, p.box);
    for (const auto& z : read_initial_file(o.initial_file, grid.size()))
      p.initial.emplace_back(static_cast<R>(z.real()), static_cast<R>(z.imag()));
  } else {
    for (double x : parse_vector(o.x0.empty() ? "1" : o.x0, "--x0", o.dims)) p.x0.push_back(static_cast<R>(x));
    for (double x : parse_vector(o.p0.empty() ? "0" : o.p0, "--p0", o.dims)) p.p0.push_back(static_cast<R>(x));
    p.width = static_cast<R>(nystrom::cli::parse_double(o.width.empty() ? "1" : o.width, "--width", Bound::positive));
  }
  if (!o.converge.empty()) p.converge = nystrom::cli::parse_double(o.converge, "--converge", Bound::positive);
  p.allow_negative_coefficients = o.allow_negative;
  p.fft.threads = o.threads;
  const R dt = static_cast<R>(nystrom::cli::parse_double(o.dt, "--dt", Bound::positive));
  p.autocorrelation = o.autocorrelation;
  p.states = o.states;
  const long samples = o.autocorrelation ? o.steps : o.plot.empty() ? 0 : std::min<long>(o.steps, 400);
  return solve(p, o.method, dt, o.steps, samples);
}

nlohmann::json to_json(const Options& o, const QuantumResult& r, int ranks) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["method"] = r.method;
  j["order"] = r.order;
  j["potential"] = o.potential_file.empty() ? o.potential : "file";
  j["dims"] = o.dims;
  j["grid"] = o.grid;
  j["box"] = nystrom::cli::parse_double(o.box, "--box", Bound::positive);
  j["dt"] = r.dt;
  j["steps"] = r.steps;
  j["steps_taken"] = r.steps_taken;
  j["converged"] = o.converge.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.converged);
  j["initial"] = o.initial_file.empty() ? "gaussian" : "file";
  j["time"] = r.time;
  j["imaginary_time"] = o.imaginary;
  j["g"] = nystrom::cli::parse_double(o.g, "--g");
  j["precision"] = o.precision;
  j["norm"] = r.norm;
  j["norm_drift"] = r.norm_drift;
  j["energy"] = r.energy;
  j["chemical_potential"] = r.chemical_potential;
  j["mean_position"] = r.mean_x;
  j["mean_momentum"] = r.mean_p;
  j["exact_solution"] = r.exact_solution.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.exact_solution);
  j["exact_error"] = num(r.exact_error);
  j["fft_count"] = r.fft_count;
  j["seconds"] = r.seconds;
  j["ranks"] = ranks;
  if (o.states > 1) j["energies"] = r.energies;
  if (o.autocorrelation) {
    auto& c = j["autocorrelation"] = nlohmann::json::array();
    for (const auto& s : r.samples)
      c.push_back({{"t", s.time}, {"re", s.autocorrelation.real()}, {"im", s.autocorrelation.imag()}});
  }
  return j;
}

nystrom::cli::Registrar reg(
    "quantum", "Schrodinger / Gross-Pitaevskii split-operator propagation on a periodic grid", [](CLI::App& app) {
      auto o = std::make_shared<Options>();
      app.add_option("--potential", o->potential,
                     "harmonic, anisotropic, morse, double-well, soft-coulomb, free (docs/quantum.md)")
          ->capture_default_str();
      app.add_option("--potential-file", o->potential_file,
                     "The potential's values: one number per grid point, row-major (last axis fastest), at "
                     "x_i = -L/2 + i L/n; # starts a comment (docs/quantum.md)");
      app.add_option("--dims", o->dims, "Dimensions: 1, 2 or 3")->capture_default_str();
      app.add_option("--grid", o->grid, "Grid points per axis")->capture_default_str();
      app.add_option("--box", o->box, "Box length L (the box is [-L/2, L/2) per axis)")->capture_default_str();
      app.add_option("--method", o->method,
                     "Splitting or MPE method (see `nystrom methods`; also mpe4:1,2,3); default KL8 (unitary) in "
                     "real time, M8 in imaginary time");
      app.add_option("--dt", o->dt, "Step (real or imaginary time)")->capture_default_str();
      app.add_option("--steps", o->steps, "Number of steps")->capture_default_str();
      app.add_flag("--imaginary-time", o->imaginary, "Propagate in imaginary time (ground state), renormalising");
      app.add_option("--converge", o->converge,
                     "Imaginary time: stop once |dE| per unit imaginary time over a step is below this (--steps is "
                     "then the most; JSON: converged, steps_taken)");
      app.add_flag("--allow-negative-coefficients", o->allow_negative,
                   "Imaginary time: run a method with backward sub-steps (negative real parts), refused otherwise");
      app.add_option("--initial-file", o->initial_file,
                     "Initial wave function: one grid point per line, 're im' (or 're'), row-major (last axis "
                     "fastest), # comments; normalised on input; replaces the Gaussian (docs/quantum.md)");
      app.add_option("--states", o->states, "Imaginary time: the N lowest states by orthogonalisation (JSON: energies)")
          ->capture_default_str();
      app.add_option("--x0", o->x0,
                     "Initial centre: one number (first axis) or one per axis, comma-separated (default 1)");
      app.add_option("--p0", o->p0, "Initial momentum, like --x0 (default 0)");
      app.add_option("--width", o->width, "Initial Gaussian width (default 1: the harmonic coherent state)");
      app.add_option("--g", o->g, "Gross-Pitaevskii coupling g (|psi|^2 normalised to 1)")->capture_default_str();
      app.add_option("--precision", o->precision, "double or long-double")->capture_default_str();
      app.add_option("--threads", o->threads, "FFTW threads")->capture_default_str();
      app.add_flag("--json", o->json, "Print one JSON object");
      app.add_flag("--autocorrelation", o->autocorrelation,
                   "Record C(t) = <psi(0)|psi(t)> after every step (JSON: autocorrelation, a list of {t, re, im})");
      app.add_option("--plot", o->plot, "Write <x_1>(t) (real time) or E(tau) (imaginary time) to this PNG");
      return [o]() {
        if (o->grid <= 0) throw UsageError("--grid must be positive, got " + std::to_string(o->grid));
        if (o->dims < 1 || o->dims > 3) throw UsageError("--dims must be 1, 2 or 3, got " + std::to_string(o->dims));
        if (o->steps < 0) throw UsageError("--steps must not be negative");
        if (o->threads < 1) throw UsageError("--threads must be positive");
        if (o->states < 1 || o->states > 1000) throw UsageError("--states must be between 1 and 1000");
        if (o->states > 1 && !o->imaginary) throw UsageError("--states needs --imaginary-time");
        if (!o->converge.empty() && !o->imaginary) throw UsageError("--converge needs --imaginary-time");
        if (!o->converge.empty() && o->states > 1) throw UsageError("--converge works with --states 1 only");
        if (!o->converge.empty()) nystrom::cli::parse_double(o->converge, "--converge", Bound::positive);
        nystrom::cli::parse_double(o->box, "--box", Bound::positive);
        nystrom::cli::parse_double(o->dt, "--dt", Bound::positive);
        nystrom::cli::parse_double(o->g, "--g");
        if (o->precision != "double" && o->precision != "long-double")
          throw UsageError("--precision must be double or long-double, got '" + o->precision + "'");
        if (!o->plot.empty()) nystrom::cli::check_plot_target(o->plot);
        const MpiSession mpi;
        std::string failure;
        mpi.agree(fingerprint(*o, failure), failure);
        QuantumResult r;
        try {
          r = o->precision == "double" ? run<double>(*o, mpi) : run<long double>(*o, mpi);
        } catch (const nystrom::error&) {
          throw;  // the same on every rank: the ranks hold the same input and share the observables
        } catch (const std::invalid_argument&) {
          throw;
        } catch (const std::exception& e) {
          mpi.fail(e.what());
          throw;
        }
        if (mpi.rank() != 0) return 0;
        if (!o->plot.empty()) plot_samples(o->plot, r, o->imaginary);
        if (o->json) {
          std::cout << to_json(*o, r, mpi.size()).dump(2) << "\n";
          return 0;
        }
        fmt::print("method         {} (order {})\n", r.method, r.order);
        fmt::print("problem        {} in {}D, {} points per axis, box {}, g = {}{}\n",
                   o->potential_file.empty() ? o->potential : "potential from file", o->dims, o->grid, o->box, o->g,
                   o->imaginary ? ", imaginary time" : "");
        if (o->converge.empty())
          fmt::print("steps          {} of {:.6g} (time {:.6g})\n", r.steps_taken, r.dt, r.time);
        else
          fmt::print("steps          {} of at most {}, of {:.6g} (time {:.6g}): {} (|dE/dtau| {} {})\n", r.steps_taken,
                     r.steps, r.dt, r.time, r.converged ? "converged" : "NOT converged",
                     r.converged ? "<" : ">=", o->converge);
        fmt::print("norm           {:.15f} (drift {:+.3e})\n", r.norm, r.norm_drift);
        fmt::print("energy         {:.15f}\n", r.energy);
        for (std::size_t n = 1; n < r.energies.size(); ++n) fmt::print("energy {:<7} {:.15f}\n", n, r.energies[n]);
        if (std::stod(o->g) != 0) fmt::print("chem. potential {:.15f}\n", r.chemical_potential);
        std::string mx;
        for (double x : r.mean_x) mx += fmt::format(" {:.12f}", x);
        fmt::print("<x>           {}\n", mx);
        if (!r.exact_solution.empty())
          fmt::print("error          {:.6e} (L2, against the {})\n", r.exact_error, r.exact_solution);
        if (o->autocorrelation)
          fmt::print("C(t)           {:.12f} {:+.12f} i\n", r.autocorrelation.real(), r.autocorrelation.imag());
        fmt::print("FFTs           {}\n", r.fft_count);
        fmt::print("time           {:.6f} s{}\n", r.seconds,
                   mpi.size() > 1 ? fmt::format(" ({} MPI ranks)", mpi.size()) : std::string());
        return 0;
      };
    });

}  // namespace
