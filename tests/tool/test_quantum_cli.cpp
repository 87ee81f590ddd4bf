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
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "support/cli_runner.hpp"

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
                                 "--method 4A --g 1",
                                 "--method BC1 --g 2",
                                 "--method AC1 --g 1 --imaginary-time"}) {
    const auto r = run("quantum " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
  const auto missing = run("quantum --grid 32 --steps 2 --plot " + (dir / "no" / "such" / "f.png").string());
  EXPECT_EQ(missing.code, 2) << missing.err;
}

// Imaginary time refuses a method with a backward sub-step (Forest-Ruth on the double well printed a wrong energy,
// 210 for 0.8696 on 128 points in a box of 8, and exited 0) with one line naming the forward methods and the override;
// the override runs it; the forward methods run.
TEST(QuantumCli, ImaginaryTimeRefusesBackwardMethods) {
  const std::string args =
      "quantum --potential double-well --grid 128 --box 8 --imaginary-time --dt 0.05 --steps 400 --json ";
  for (const std::string m : {"FR", "KL8"}) {
    const auto r = run(args + "--method " + m);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: '" + m + "' has a coefficient with a real part that is not positive", 0), 0u)
        << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    for (const char* alt : {"M4..M16", "Chin's 4A", "BC1", "--allow-negative-coefficients"})
      EXPECT_NE(r.err.find(alt), std::string::npos) << alt << " not in " << r.err;
  }
  const auto forced = run(args + "--method FR --allow-negative-coefficients");
  ASSERT_EQ(forced.code, 0) << forced.err;
  double e0 = 0;
  for (const std::string m : {"M8", "BC1"}) {
    const auto r = run(args + "--method " + m);
    ASSERT_EQ(r.code, 0) << r.err;
    const double e = nlohmann::json::parse(r.out)["energy"].get<double>();
    if (m == "M8") e0 = e;
    EXPECT_NEAR(e, e0, 1e-6) << m;
  }
  EXPECT_GT(std::abs(nlohmann::json::parse(forced.out)["energy"].get<double>() - e0), 1.0);
}

// The default method: KL8 (unitary) in real time, M8 in imaginary time, as in the library and Python.
TEST(QuantumCli, DefaultMethodIsKL8InRealTimeAndM8InImaginaryTime) {
  const auto real = run("quantum --potential double-well --dt 0.01 --steps 200 --json");
  ASSERT_EQ(real.code, 0) << real.err;
  const auto jr = nlohmann::json::parse(real.out);
  EXPECT_EQ(jr["method"], "KL8");
  EXPECT_NEAR(jr["norm"].get<double>(), 1, 1e-12);
  const auto imag = run("quantum --imaginary-time --steps 10 --json");
  ASSERT_EQ(imag.code, 0) << imag.err;
  EXPECT_EQ(nlohmann::json::parse(imag.out)["method"], "M8");
}

// --initial-file: three times the coherent state from x0 = 1, p0 = 0.5 as "re im" lines gives the --x0 1 --p0 0.5
// run (normalised on input); a real part alone is a real value; bad files exit 2 with one line.
TEST(QuantumCli, InitialFileGivesTheGaussianResult) {
  const auto dir = temp_dir();
  const auto file = dir / "psi0.txt";
  {
    std::ofstream out(file);
    out << "# three times the coherent state, 64 points, box 20\n";
    out.precision(17);
    for (int i = 0; i < 64; ++i) {
      const double x = -10 + i * (20.0 / 64);
      const std::complex<double> z =
          3 * std::pow(std::numbers::pi, -0.25) * std::exp(std::complex<double>(-(x - 1) * (x - 1) / 2, 0.5 * x));
      out << z.real() << " " << z.imag() << "\n";
    }
  }
  const std::string args = "quantum --grid 64 --method KL8 --dt 0.05 --steps 40 --json ";
  const auto a = run(args + "--x0 1 --p0 0.5");
  const auto b = run(args + "--initial-file " + file.string());
  ASSERT_EQ(a.code, 0) << a.err;
  ASSERT_EQ(b.code, 0) << b.err;
  const auto ja = nlohmann::json::parse(a.out), jb = nlohmann::json::parse(b.out);
  EXPECT_EQ(jb["initial"], "file");
  EXPECT_NEAR(jb["norm"].get<double>(), 1, 1e-13);
  EXPECT_NEAR(jb["energy"].get<double>(), ja["energy"].get<double>(), 1e-12);
  EXPECT_NEAR(jb["mean_position"][0].get<double>(), ja["mean_position"][0].get<double>(), 1e-12);
  EXPECT_TRUE(jb["exact_error"].is_null());

  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  std::string ok, few, nan, three, zero;
  for (int i = 0; i < 8; ++i) {
    ok += "1 0\n";
    zero += "0 0\n";
  }
  for (int i = 0; i < 7; ++i) few += "1 0\n";
  nan = few + "nan 0\n";
  three = few + "1 0 0\n";
  const std::string fifo = (dir / "fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto big = dir / "big.txt";
  { std::ofstream(big) << "1 0\n"; }
  std::filesystem::resize_file(big, std::uintmax_t(1) << 24);  // 16 MiB (sparse), beyond the bound for 8 points
  const auto fine = run("quantum --grid 8 --steps 2 --initial-file " + write("ok.txt", ok));
  EXPECT_EQ(fine.code, 0) << fine.err;
  for (const std::string& f :
       {write("few.txt", few), write("many.txt", ok + "1\n"), write("nan.txt", nan), write("three.txt", three),
        write("word.txt", few + "x 1\n"), write("zero.txt", zero), (dir / "missing.txt").string(), dir.string(), fifo,
        std::string("/dev/zero"), big.string()}) {
    const auto r = run("quantum --grid 8 --steps 2 --initial-file " + f);
    EXPECT_EQ(r.code, 2) << f << ": " << r.err;
    EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << f << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << f << ": " << r.err;
  }
  const auto with_x0 = run("quantum --grid 8 --steps 2 --x0 1 --initial-file " + write("ok2.txt", ok));
  EXPECT_EQ(with_x0.code, 2) << with_x0.err;
  EXPECT_NE(with_x0.err.find("replaces the Gaussian"), std::string::npos) << with_x0.err;
}

// --converge: the oscillator's ground state from x0 = 0.5 (E - 1/2 = e^{-2 tau}/8, |dE/dtau| = 2 (E - 1/2)) stops
// near tau = ln(2.5e7)/2 = 8.5, 170 steps of 0.05, with E - 1/2 below the tolerance; too few steps say so.
TEST(QuantumCli, ConvergeStopsImaginaryTimeEarly) {
  const std::string args = "quantum --grid 64 --imaginary-time --x0 0.5 --dt 0.05 --converge 1e-8 --json ";
  const auto r = run(args + "--steps 10000");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["converged"], true);
  EXPECT_EQ(j["steps"], 10000);
  EXPECT_NEAR(j["steps_taken"].get<double>(), 170, 9);
  EXPECT_NEAR(j["time"].get<double>(), 0.05 * j["steps_taken"].get<double>(), 1e-12);
  EXPECT_LT(std::abs(j["energy"].get<double>() - 0.5), 1e-8);
  const auto s = run(args + "--steps 20");
  ASSERT_EQ(s.code, 0) << s.err;
  const auto js = nlohmann::json::parse(s.out);
  EXPECT_EQ(js["converged"], false);
  EXPECT_EQ(js["steps_taken"], 20);
  const auto text = run("quantum --grid 64 --imaginary-time --x0 0.5 --dt 0.05 --converge 1e-8 --steps 20");
  EXPECT_NE(text.out.find("NOT converged"), std::string::npos) << text.out;
  EXPECT_TRUE(nlohmann::json::parse(run("quantum --steps 2 --json").out)["converged"].is_null());
  for (const std::string bad : {"--converge 1e-8", "--imaginary-time --converge 0", "--imaginary-time --converge -1",
                                "--imaginary-time --converge nan", "--imaginary-time --converge 1e-8 --states 2"}) {
    const auto e = run("quantum --steps 2 " + bad);
    EXPECT_EQ(e.code, 2) << bad << ": " << e.err;
    EXPECT_EQ(std::count(e.err.begin(), e.err.end(), '\n'), 1) << bad << ": " << e.err;
  }
}

#ifdef NYSTROM_MPIEXEC
namespace {

/// Two ranks on this machine, also as root and in a container (no remote launcher, no shared-memory single
/// copy). OpenMPI keeps allocations of MPI_Init until exit, which LeakSanitizer would report as leaks. Each launch
/// keeps its own session directory: two launches starting at once (ctest -j) otherwise race to
/// create the same /tmp/ompi.HOST.UID and one fails in orte_init.
std::string two_ranks() {
  // (short: OpenMPI's sockets live below it, and a socket's path is limited to 107 characters)
  struct Sessions {  // removed when the test program ends
    std::vector<std::filesystem::path> dirs;
    ~Sessions() {
      for (const auto& d : dirs) {
        std::error_code ec;
        std::filesystem::remove_all(d, ec);
      }
    }
  };
  static Sessions sessions;
  const auto session = std::filesystem::temp_directory_path() /
                       ("nyompi-" + std::to_string(::getpid()) + "-" + std::to_string(sessions.dirs.size() + 1));
  std::filesystem::create_directories(session);
  sessions.dirs.push_back(session);
  return "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm=isolated "
         "OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none "
         "OMPI_MCA_orte_tmpdir_base=" +
         session.string() + " ASAN_OPTIONS=detect_leaks=0 " NYSTROM_MPIEXEC " --oversubscribe -np 2";
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
      "quantum --dims 2 --grid 45 --box 14 --method M6 --dt 0.1 --steps 20 --imaginary-time --g 2 "
      "--x0 0.5 --precision long-double --json");
  expect_same_result(
      "quantum --potential harmonic --dims 1 --grid 256 --box 20 --method M8 --dt 0.05 --steps 200 "
      "--json");
}

// An initial wave function from a file on a distributed grid: each rank takes its own slab of the file's values
// (a packet displaced along the distributed axis, so that a rank reading another slab changes every result).
TEST(QuantumMpi, TwoRanksReadTheirOwnSlabOfTheInitialFile) {
  const auto dir = cli_test::temp_dir();
  const auto file = dir / "psi0_2d.txt";
  {
    std::ofstream out(file);
    out.precision(17);
    for (int i = 0; i < 24; ++i)
      for (int j = 0; j < 24; ++j) {
        const double x = -6 + i * 0.5, y = -6 + j * 0.5;
        const std::complex<double> z = std::exp(std::complex<double>(-((x - 1.5) * (x - 1.5) + y * y) / 2, 0.7 * x));
        out << z.real() << " " << z.imag() << "\n";
      }
  }
  expect_same_result("quantum --dims 2 --grid 24 --box 12 --method M6 --dt 0.05 --steps 20 --initial-file " +
                     file.string() + " --json");
  const auto r = nlohmann::json::parse(run("quantum --dims 2 --grid 24 --box 12 --method M6 --dt 0.05 --steps 20 "
                                           "--initial-file " +
                                           file.string() + " --json")
                                           .out);
  EXPECT_GT(r["mean_position"][0].get<double>(), 1.0);  // the packet where the file put it
}

// Ranks that were given different arguments or input files, or that cannot read their input, all stop before
// the run with one line and exit status 2 (a different grid on one rank would otherwise plan transforms of
// another shape and corrupt memory, and a rank that failed alone would leave the others waiting forever).
TEST(QuantumMpi, RanksThatDisagreeStopTogetherWithOneLine) {
  const auto dir = cli_test::temp_dir();
  const std::string common = "quantum --dims 2 --box 12 --method M4 --dt 0.1 --steps 5 --json";
  std::string launcher = two_ranks();
  launcher.replace(launcher.find("-np 2"), 5, "-np 1");
  auto mpmd = [&](const std::string& a, const std::string& b) {
    // `timeout` turns a hang into a failure of this test rather than of the whole suite.
    return run(a + " : -np 1 " + cli_test::tool() + " " + b, dir, "timeout 60 " + launcher);
  };
  const auto grid = mpmd(common + " --grid 16", common + " --grid 20");
  EXPECT_EQ(grid.code, 2) << grid.err;
  EXPECT_NE(grid.err.find("nystrom: error: the MPI ranks were given different arguments"), std::string::npos)
      << grid.err;
  const auto precision = mpmd(common + " --grid 16", common + " --grid 16 --precision long-double");
  EXPECT_EQ(precision.code, 2) << precision.err;
  EXPECT_NE(precision.err.find("different arguments"), std::string::npos) << precision.err;
  // The potential file of rank 1 is missing: rank 0 reports rank 1's reason.
  {
    std::ofstream f(dir / "v.txt");
    for (int i = 0; i < 256; ++i) f << 0.5 * (i - 128) * (i - 128) / 256.0 << "\n";
  }
  const std::string one = "quantum --dims 2 --grid 16 --box 12 --method M4 --dt 0.1 --steps 5 --json --potential-file ";
  const auto missing = mpmd(one + (dir / "v.txt").string(), one + (dir / "absent.txt").string());
  EXPECT_EQ(missing.code, 2) << missing.err;
  EXPECT_NE(missing.err.find("nystrom: error: MPI rank 1: "), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("absent.txt"), std::string::npos) << missing.err;
  // The same command on every rank still runs.
  const auto same = mpmd(one + (dir / "v.txt").string(), one + (dir / "v.txt").string());
  EXPECT_EQ(same.code, 0) << same.err;
}

#endif
