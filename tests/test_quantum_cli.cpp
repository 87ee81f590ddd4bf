// The `nystrom quantum` contract: the JSON fields, physics checks of its output against exact values, and
// bad input (exit code 2, one line `nystrom: error: ...`). The tool is found through NYSTROM_BIN.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli_runner.hpp"

namespace {

using namespace cli_test;

}  // namespace

TEST(QuantumCli, ContractCommandGivesTheCoherentState) {
  const auto r =
      run("quantum --potential harmonic --dims 1 --grid 256 --box 20 --method M8 --dt 0.05 --steps 200 "
          "--x0 1 --p0 0 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* k :
       {"method", "dims", "grid", "dt", "steps", "norm", "energy", "mean_position", "time", "fft_count", "seconds"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["method"], "M8");
  EXPECT_EQ(j["dims"], 1);
  EXPECT_EQ(j["grid"], 256);
  EXPECT_EQ(j["steps"], 200);
  EXPECT_NEAR(j["time"].get<double>(), 10.0, 1e-12);
  ASSERT_EQ(j["mean_position"].size(), 1u);
  EXPECT_NEAR(j["mean_position"][0].get<double>(), std::cos(10.0), 1e-8);  // the classical orbit
  EXPECT_NEAR(j["energy"].get<double>(), 1.0, 1e-8);                       // 1/2 + x0^2/2
  EXPECT_NEAR(j["norm"].get<double>(), 1.0, 1e-7);
  EXPECT_LT(j["exact_error"].get<double>(), 1e-7);
  // M8 = mpe:1,2,3,4 over position Verlet: 4 products with 2, 3, 4, 5 kinetic sub-steps, two FFTs each
  EXPECT_EQ(j["fft_count"], 200 * 2 * (2 + 3 + 4 + 5));
}

TEST(QuantumCli, ImaginaryTimeGroundState3DAndLongDouble) {
  const auto r =
      run("quantum --dims 3 --grid 24 --box 12 --method BC1 --dt 0.2 --steps 100 --imaginary-time "
          "--x0 0.5 --precision long-double --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j["energy"].get<double>(), 1.5, 1e-8);
  EXPECT_NEAR(j["norm"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(j["mean_position"].size(), 3u);
  EXPECT_EQ(j["precision"], "long-double");
}

// --autocorrelation: C(t) after every step; for the 1D coherent state from x0 = 1, p0 = 0 the exact value is
// e^{-it/2} exp(-(1 - e^{-it})/2) (|a|^2 = 1/2).
TEST(QuantumCli, AutocorrelationOfTheCoherentState) {
  const auto r = run("quantum --grid 128 --method M6 --dt 0.1 --steps 30 --x0 1 --autocorrelation --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["autocorrelation"].size(), 31u);
  for (const auto& c : j["autocorrelation"]) {
    const double t = c["t"].get<double>();
    const std::complex<double> exact =
        std::exp(std::complex<double>(0, -t / 2) - 0.5 * (1.0 - std::exp(std::complex<double>(0, -t))));
    EXPECT_NEAR(c["re"].get<double>(), exact.real(), 1e-9) << t;
    EXPECT_NEAR(c["im"].get<double>(), exact.imag(), 1e-9) << t;
  }
  EXPECT_NEAR(j["autocorrelation"].back()["t"].get<double>(), 3.0, 1e-12);
}

// --potential-file with the values of the built-in anisotropic potential (x_1^2/2 + 2 x_2^2/2, computed here as
// the library does, written to round trip) gives the built-in result exactly; the file's order is row-major,
// last axis fastest, which the anisotropic potential tells apart.
TEST(QuantumCli, PotentialFileReproducesTheBuiltInPotential) {
  const auto file = temp_dir() / "anisotropic.txt";
  {
    std::ofstream out(file);
    out << "# anisotropic potential, 32 x 32 points, box 12\n";
    out.precision(17);
    for (int i = 0; i < 32; ++i)
      for (int j = 0; j < 32; ++j) {
        const double x = -12.0 / 2 + i * (12.0 / 32), y = -12.0 / 2 + j * (12.0 / 32);
        double v = 0;
        v += 1.0 * x * x / 2;
        v += 2.0 * y * y / 2;
        out << v << (j + 1 < 32 ? " " : "\n");
      }
  }
  const std::string args = "quantum --dims 2 --grid 32 --box 12 --method M6 --dt 0.1 --steps 20 --x0 1,0.5 --json ";
  const auto a = run(args + "--potential anisotropic");
  const auto b = run(args + "--potential-file " + file.string());
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(jb["potential"], "file");
  for (const char* k : {"norm", "energy", "mean_position", "mean_momentum", "fft_count"}) EXPECT_EQ(ja[k], jb[k]) << k;
  // a transposed file (first axis fastest) gives another result
  {
    std::ofstream out(file);
    out.precision(17);
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i) {
        const double x = -12.0 / 2 + i * (12.0 / 32), y = -12.0 / 2 + j * (12.0 / 32);
        out << (x * x / 2 + y * y) << "\n";
      }
  }
  const auto c = run(args + "--potential-file " + file.string());
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_GT(std::abs(nlohmann::json::parse(c.out)["energy"].get<double>() - ja["energy"].get<double>()), 1e-3);
}

TEST(QuantumCli, BadPotentialFileExitsTwoWithOneLine) {
  const auto dir = temp_dir();
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  std::string few, nan = "nan", inf, word;
  for (int i = 0; i < 7; ++i) few += "1 ";
  for (int i = 0; i < 7; ++i) nan += " 1", inf += "1 ", word += "1 ";
  inf += "inf";
  word += "x1";
  const std::string many = few + "1 1";
  for (const std::string& f :
       {write("few.txt", few), write("many.txt", many), write("nan.txt", nan), write("inf.txt", inf),
        write("word.txt", word), (dir / "missing.txt").string(), dir.string()}) {
    const auto r = run("quantum --grid 8 --steps 2 --potential-file " + f);
    EXPECT_EQ(r.code, 2) << f << ": " << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << f << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << f << ": " << r.err;
  }
}

// --states 3: the three lowest levels of the 1D oscillator, n + 1/2.
TEST(QuantumCli, ExcitedStatesOfTheOscillator) {
  const auto r = run("quantum --grid 64 --method M6 --dt 0.1 --steps 300 --imaginary-time --x0 0.7 --states 3 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["energies"].size(), 3u);
  for (int n = 0; n < 3; ++n) EXPECT_NEAR(j["energies"][n].get<double>(), n + 0.5, 1e-9) << n;
}

TEST(QuantumCli, PlotWritesAPng) {
  const auto png = temp_dir() / "orbit.png";
  const auto r = run("quantum --grid 64 --steps 20 --method PV --plot " + png.string());
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string head = slurp(png).substr(0, 4);
  EXPECT_EQ(head, "\x89PNG");
}

// --plot is written as every result file of the tool (sweep --plot, --csv): a link's target is replaced and the
// link kept, a FIFO and a device are written in place (never replaced by a regular file), a failure says why,
// and no temporary file is left beside the target or in TMPDIR.
TEST(QuantumCli, PlotTargetsAreWrittenAsEveryResultFile) {
  const auto dir = temp_dir() / "plots";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir / "data");
  std::filesystem::create_directories(dir / "tmp");
  const std::string quantum = "quantum --grid 64 --steps 20 --method PV --plot ";
  const std::string env = "env TMPDIR=" + (dir / "tmp").string();
  // a link: its target replaced, the link kept
  std::ofstream(dir / "data" / "target.png") << "old";
  std::filesystem::create_symlink(dir / "data" / "target.png", dir / "link.png");
  const auto l = run(quantum + (dir / "link.png").string(), temp_dir(), env);
  ASSERT_EQ(l.code, 0) << l.err;
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "link.png"));
  EXPECT_EQ(slurp(dir / "data" / "target.png").substr(0, 4), "\x89PNG");
  // a FIFO: written in place, still a FIFO
  const auto fifo = dir / "pipe.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = slurp(fifo); });
  const auto f = run(quantum + fifo.string(), temp_dir(), env);
  // should the tool not have opened the FIFO, a writer of no bytes ends the reader
  const int unblock = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  if (unblock >= 0) ::close(unblock);
  reader.join();
  ASSERT_EQ(f.code, 0) << f.err;
  EXPECT_EQ(got.substr(0, 4), "\x89PNG");
  struct stat st {};
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced";
  // a device node (as root: /dev/full's numbers): written in place, which fails with the device's reason
  const auto node = dir / "node.png";
  if (::mknod(node.c_str(), S_IFCHR | 0600, ::makedev(1, 7)) == 0) {
    const auto d = run(quantum + node.string(), temp_dir(), env);
    EXPECT_EQ(d.code, 2);
    EXPECT_NE(d.err.find("No space left on device"), std::string::npos) << d.err;
    ASSERT_EQ(::lstat(node.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device node was replaced";
    std::filesystem::remove(node);
  }
  // a failure gives the system's reason: a name too long for the file system, and (not as root) a read-only folder
  // (relative to the folder, so that the one-line message, at most 400 characters, holds the reason)
  const std::string long_name = std::string(256, 'n') + ".png";
  const auto n = run(quantum + long_name, temp_dir(), "cd " + dir.string() + " && " + env);
  EXPECT_EQ(n.code, 2);
  EXPECT_NE(n.err.find("File name too long"), std::string::npos) << n.err;
  if (::geteuid() != 0) {
    std::filesystem::create_directories(dir / "ro");
    std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    const auto r = run(quantum + (dir / "ro" / "keep.png").string(), temp_dir(), env);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("Permission denied"), std::string::npos) << r.err;
    std::filesystem::permissions(dir / "ro", std::filesystem::perms::owner_all);
  }
  std::set<std::string> names;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir))
    names.insert(e.path().lexically_relative(dir).string());
  std::set<std::string> expected{"data", "data/target.png", "link.png", "pipe.png", "tmp"};
  if (::geteuid() != 0) expected.insert("ro");
  EXPECT_EQ(names, expected);
  std::filesystem::remove_all(dir);
}

TEST(QuantumCli, BadInputExitsTwoWithOneLine) {
  const auto dir = temp_dir();
  for (const std::string args : {"--grid 0",
                                 "--grid -4",
                                 "--box 0",
                                 "--box -3",
                                 "--box nan",
                                 "--dt nan",
                                 "--dt 0",
                                 "--potential nowhere",
                                 "--method A6",
                                 "--method DP12",
                                 "--method nonsense",
                                 "--dims 4",
                                 "--precision float",
                                 "--x0 1,2",
                                 "--g inf",
                                 "--steps -1",
                                 "--grid abc",
                                 "--states 0",
                                 "--states 2",
                                 "--states 2 --imaginary-time --g 1",
                                 "--method 4A --g 1"}) {
    const auto r = run("quantum " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  const auto missing = run("quantum --grid 32 --steps 2 --plot " + (dir / "no" / "such" / "f.png").string());
  EXPECT_EQ(missing.code, 2) << missing.err;
}

#ifdef NYSTROM_MPIEXEC
namespace {

/// Two ranks on this machine, also as root and in a container (no remote launcher, no shared-memory single
/// copy). OpenMPI keeps allocations of MPI_Init until exit, which LeakSanitizer would report as leaks.
std::string two_ranks() {
  return "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm=isolated "
         "OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none "
         "ASAN_OPTIONS=detect_leaks=0 " NYSTROM_MPIEXEC " --oversubscribe -np 2";
}

void expect_same_result(const std::string& args) {
  const auto one = run(args);
  const auto two = run(args, cli_test::temp_dir(), two_ranks());
  ASSERT_EQ(one.code, 0) << one.err;
  ASSERT_EQ(two.code, 0) << two.err;
  const auto a = nlohmann::json::parse(one.out), b = nlohmann::json::parse(two.out);
  EXPECT_EQ(a["ranks"], 1);
  EXPECT_EQ(b["ranks"], 2);
  EXPECT_EQ(a["fft_count"], b["fft_count"]) << args;
  auto close = [&](const nlohmann::json& x, const nlohmann::json& y, const std::string& what) {
    const double u = x.get<double>(), v = y.get<double>();
    EXPECT_NEAR(u, v, 1e-13 * std::max(1.0, std::abs(u))) << what << " of " << args;
  };
  for (const char* k : {"norm", "energy", "chemical_potential"}) close(a[k], b[k], k);
  for (const char* k : {"mean_position", "mean_momentum"}) {
    ASSERT_EQ(a[k].size(), b[k].size()) << k;
    for (std::size_t i = 0; i < a[k].size(); ++i) close(a[k][i], b[k][i], k);
  }
  if (!a["exact_error"].is_null()) close(a["exact_error"], b["exact_error"], "exact_error");
}

}  // namespace

// A grid distributed over two MPI ranks (a slab of the first axis each) gives the one-process result to
// rounding: real time in 3D (even slabs), imaginary-time Gross-Pitaevskii in 2D, long double (uneven slabs of
// 23 and 22 rows), and the 1D contract command (the whole grid on every rank).
TEST(QuantumMpi, TwoRanksGiveTheOneProcessResult) {
  expect_same_result(
      "quantum --dims 3 --grid 16 --box 12 --method M4 --dt 0.1 --steps 10 --x0 1,0.5 --p0 0,0,0.5 "
      "--json");
  expect_same_result(
      "quantum --dims 2 --grid 45 --box 14 --method BC1 --dt 0.1 --steps 20 --imaginary-time --g 2 "
      "--x0 0.5 --precision long-double --json");
  expect_same_result(
      "quantum --potential harmonic --dims 1 --grid 256 --box 20 --method M8 --dt 0.05 --steps 200 "
      "--json");
}

#endif
