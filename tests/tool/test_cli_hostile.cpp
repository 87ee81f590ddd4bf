// Hostile input to the command-line tool: a table of malformed invocations across every subcommand, each of
// which must exit with status 2 and exactly one stderr line "nystrom: error: ..." (printable ASCII only), create
// no file and leave no temporary file; the plot-name injection; output paths that are symbolic links, FIFOs
// and folders; SIGTERM during a long run; input files that are devices, FIFOs or folders; corrupted checkpoints
// and checkpoint targets that are not regular files. The tool is found through NYSTROM_BIN (set by CTest) and started
// without a shell, so arguments reach it byte for byte.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "support/checksum.hpp"
#include "support/cli_runner.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;

using cli_test::Result;
using cli_test::slurp;
using cli_test::tool;

// A fresh folder per test: the tool runs there, with TMPDIR pointing to a private folder inside it.
fs::path work_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto d = fs::temp_directory_path() /
           ("nystrom-hostile-" + std::to_string(::getpid()) + "-" + info->test_suite_name() + "-" + info->name());
  fs::remove_all(d);
  fs::create_directories(d / "run");
  fs::create_directories(d / "tmp");
  std::ofstream(d / "stdout.txt").flush();
  std::ofstream(d / "stderr.txt").flush();
  return d;
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::recursive_directory_iterator(dir)) names.insert(e.path().lexically_relative(dir).string());
  return names;
}

// Starts the tool with argv in `dir`/run; returns its pid. stdout and stderr go to files in `dir`.
pid_t start(const fs::path& dir, const std::vector<std::string>& args, const std::string& progress = "0") {
  std::vector<std::string> argv_s{tool()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_s{"TMPDIR=" + (dir / "tmp").string(), "PATH=" + std::string(std::getenv("PATH")),
                                 "NYSTROM_PROGRESS=" + progress, "HOME=" + dir.string()};
  std::vector<char*> env;
  for (auto& e : env_s) env.push_back(e.data());
  env.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addchdir_np(&fa, (dir / "run").c_str());
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&fa, 1, (dir / "stdout.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&fa, 2, (dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), env.data());
  posix_spawn_file_actions_destroy(&fa);
  EXPECT_EQ(rc, 0) << "cannot start " << argv[0];
  return pid;
}

Result finish(const fs::path& dir, pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = slurp(dir / "stdout.txt");
  r.err = slurp(dir / "stderr.txt");
  return r;
}

Result run(const fs::path& dir, const std::vector<std::string>& args) { return finish(dir, start(dir, args)); }

std::string joined(const std::vector<std::string>& args) {
  std::string s;
  for (const auto& a : args) s += (s.empty() ? "" : " ") + (a.size() > 60 ? a.substr(0, 60) + "..." : a);
  return s;
}

// The contract for bad input: status 2, one line "nystrom: error: ..." of printable ASCII on stderr.
void expect_refused(const Result& r, const std::string& what) {
  EXPECT_EQ(r.code, 2) << what << "\nstderr: " << r.err;
  EXPECT_EQ(r.err.rfind("nystrom: error: ", 0), 0u) << what << "\nstderr: " << r.err;
  ASSERT_FALSE(r.err.empty()) << what;
  EXPECT_EQ(r.err.back(), '\n') << what;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << "\nstderr: " << r.err;
  for (unsigned char c : r.err.substr(0, r.err.size() - 1))
    EXPECT_TRUE(c >= 0x20 && c < 0x7f) << what << ": byte " << static_cast<int>(c) << " in stderr: " << r.err;
  EXPECT_EQ(r.err.find("stol"), std::string::npos) << what;
  EXPECT_EQ(r.err.find("filesystem error"), std::string::npos) << what;
}

std::string repeat(const std::string& s, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

std::string sequence(int n) {
  std::string s;
  for (int i = 1; i <= n; ++i) {  // appended piece by piece: GCC 12 reports a false -Warray-bounds for "x" + string
    if (i > 1) s += ',';
    s += std::to_string(i);
  }
  return s;
}

// A splitting with `pairs` drift-kick pairs of equal coefficients 1/pairs: a valid first-order method file.
std::string long_method_file(int pairs) {
  std::string s = "name long\norder 1\n";
  const std::string c = std::to_string(pairs);
  for (int i = 0; i < pairs; ++i) {
    s += "drift 1/";
    s += c;
    s += "\nkick 1/";
    s += c;
    s += '\n';
  }
  return s;
}

}  // namespace

TEST(CliHostile, MalformedInvocationsAreRefusedWithOneLine) {
  const auto dir = work_dir();
  const std::string junk = (dir / "junk.bin").string();
  {
    std::ofstream f(junk, std::ios::binary);
    f << "name \x01\x02\xff\xfe\n\x7f\x80 kick 1\n" << std::string("\0\0\x1b[31m", 7);
  }
  const std::string longfile = (dir / "long.method").string();
  std::ofstream(longfile) << long_method_file(5000);
  const std::string a_dir = (dir / "adir").string();
  fs::create_directories(a_dir);
  const std::vector<std::string> fast = {"--methods", "FR", "--force-evals", "1e3:1e3:1"};
  auto sweep = [&](std::vector<std::string> extra) {
    std::vector<std::string> a{"sweep"};
    a.insert(a.end(), fast.begin(), fast.end());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const std::vector<std::vector<std::string>> cases = {
      // numbers: empty, signs, non-finite, trailing characters, fractions for counts, overflow
      {"run", "--method", "FR", "--ecc", ""},
      {"run", "--method", "FR", "--ecc", "nan"},
      {"run", "--method", "FR", "--ecc", "inf"},
      {"run", "--method", "FR", "--ecc", "-inf"},
      {"run", "--method", "FR", "--ecc", "0.5x"},
      {"run", "--method", "FR", "--ecc", " 0.5"},
      {"run", "--method", "FR", "--ecc", "0x1p-1"},
      {"run", "--method", "FR", "--ecc", "1e999"},
      {"run", "--method", "FR", "--ecc", "1"},
      {"run", "--method", "FR", "--ecc", "-0.1"},
      {"run", "--method", "FR", "--steps-per-period", "0"},
      {"run", "--method", "FR", "--steps-per-period", "-5"},
      {"run", "--method", "FR", "--steps-per-period", "1.5"},
      {"run", "--method", "FR", "--steps-per-period", "1e3"},
      {"run", "--method", "FR", "--steps-per-period", "99999999999999999999"},
      {"run", "--method", "FR", "--steps-per-period", ""},
      {"run", "--method", "FR", "--periods", "0"},
      {"run", "--method", "FR", "--steps-per-period", "1000000000", "--periods", "1000000000"},
      {"run", "--problem", "nbody", "--method", "LF", "--eps2", "-5"},
      {"run", "--problem", "nbody", "--method", "LF", "--h", "0"},
      {"run", "--problem", "nbody", "--method", "LF", "--h", "-1"},
      {"run", "--problem", "nbody", "--method", "LF", "--n", "0"},
      {"run", "--problem", "nbody", "--method", "LF", "--n", "2000000"},
      {"run", "--problem", "nbody", "--method", "LF", "--seed", "-1"},
      {"run", "--problem", "nbody", "--method", "RKNb6", "--n", "1000000", "--steps", "1000"},
      {"run", "--method", "DP12-adaptive", "--tol", "0"},
      {"run", "--method", "DP12-adaptive", "--tol", "inf"},
      {"run", "--method", "FR", "--tol", "1e-9"},
      {"run", "--method", "FR", "--precision", "bogus"},
      {"run", "--method", "FR", "--problem", "bogus"},
      {"run", "--method", "M8", "--precision", "mpfr:256", "--steps-per-period", "1000000000", "--periods", "1000"},
      {"sweep", "--methods", "FR", "--force-evals", "1e20:1e20:1"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e4:0"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e4:2.5"},
      {"sweep", "--methods", "FR", "--force-evals", ""},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e4"},
      {"sweep", "--methods", "FR", "--force-evals", "::"},
      {"sweep", "--methods", "FR", "--force-evals", "1e4:1e3:3"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e4:99999999999999999999"},
      {"sweep", "--methods", "", "--force-evals", "1e3:1e4:2"},
      {"sweep", "--methods", "FR,,M4", "--force-evals", "1e3:1e4:2"},
      {"sweep", "--methods", "FR", "--force-evals", "1e13:1e13:1", "--periods", "100000"},
      sweep({"--t-end", "-1"}),
      sweep({"--error", "bogus"}),
      sweep({"--problem", "nbody", "--error", "precession"}),
      {"sweep", "--methods", "DP12-adaptive", "--tols", "1e-6:1e-9"},
      {"localerr", "--duration", "1e308", "--methods", "LF", "--n", "10"},
      {"localerr", "--h", "0:1:2", "--methods", "LF", "--n", "10"},
      {"localerr", "--eps", "-1", "--methods", "LF", "--n", "10"},
      {"localerr", "--threads", "-1", "--methods", "LF", "--n", "10"},
      {"localerr", "--gbs-sequence", "bogus", "--methods", "LF", "--n", "10"},
      {"localerr", "--tol", "inf", "--methods", "LF", "--n", "10"},
      {"cputime", "--steps", "0", "--n", "10"},
      {"cputime", "--repeats", "0", "--n", "10"},
      {"cputime", "--n", "1"},
      {"cputime", "--n", "1000000", "--steps", "1000", "--methods", "RKNa14"},
      {"bch", "--method", "FR", "--tolerance", "inf"},
      {"bch", "--method", "FR", "--tolerance", "-1"},
      {"bch", "--method", "FR", "--tolerance", "nan"},
      {"bch", "--method", "FR", "--degree", "13"},
      {"bch", "--method", "FR", "--bits", "10"},
      {"bch"},
      {"bch", "--method", "file:" + longfile, "--degree", "12"},
      {"bench-peers", "--periods", "1e12"},
      {"bench-peers", "--periods", "1000000000000"},
      {"bench-peers", "--periods", "0"},
      {"bench-peers", "--ecc", "1"},
      {"bench-peers", "--out", ""},
      {"discover", "--starts", "0"},
      {"discover", "--digits", "1"},
      {"discover", "--threads", "-3"},
      // method specifications: nesting, overflow, huge sequences, bytes
      {"coeffs", repeat("adjoint:", 5000) + "bogus"},
      {"coeffs", repeat("adjoint:", 5000) + "M4"},
      {"run", "--method", repeat("adjoint:", 12000) + "bogus"},
      {"bch", "--method", repeat("adjoint:", 5000) + "M8"},
      {"coeffs", "m99999999999999999999"},
      {"coeffs", "m99999999999999999999-adaptive"},
      {"coeffs", "mpe:99999999999999999999"},
      {"coeffs", "mpe"},
      {"coeffs", "mpe", "--seq", sequence(5000)},
      {"coeffs", "mpe", "--seq", "1,1"},
      {"coeffs", "mpe", "--seq", "0,1"},
      {"coeffs", "mpe", "--seq", " 1,2"},
      {"coeffs", "mpe", "--seq", "1,2,"},
      {"coeffs", "mpe", "--seq", "99999999999999999999"},
      {"coeffs", "mpe", "--order", "3"},
      {"coeffs", "mpe", "--n", "5000", "--sum", "100000000"},
      {"coeffs", "FR", "--digits", "0"},
      {"coeffs", "triplejump:99999"},
      {"run", "--method", "mpe:" + sequence(201)},
      {"run", "--method", ""},
      {"run", "--method", "\x01\x02\xff\xfe\x1b[31m"},
      {"run", "--method", "file:" + junk},
      {"run", "--method", "file:/nonexistent/x.method"},
      {"run", "--method", "file:" + a_dir},
      {"run", "--problem", "nbody", "--method", "LF", "--ic", junk},
      {"run", "--problem", "nbody", "--method", "LF", "--ic", "/nonexistent"},
      {"run", "--problem", "nbody", "--method", "LF", "--ic", ""},
      // output files
      {"demo", "--out-dir", ""},
      {"demo", "--out-dir", "/nonexistent/folder"},
      sweep({"--csv", ""}),
      sweep({"--plot", ""}),
      sweep({"--csv", a_dir}),
      sweep({"--plot", a_dir}),
      sweep({"--csv", "/nonexistent/x.csv"}),
      sweep({"--plot", "/nonexistent/x.png"}),
      sweep({"--csv", "/proc/version"}),
      {"reproduce", "bogus"},
      {"reproduce", "all", "--out-dir", ""},
      {"reproduce", "chin-fig1", "--quad", "bogus"},
      // the command line itself
      {},
      {"bogus"},
      {"run", "--bogus-option"},
      {"methods", "extra"},
      {"run", "--method"},
      {"\xff\xfe"},
  };
  for (const auto& args : cases) {
    const auto before = listing(dir);
    const Result r = run(dir, args);
    expect_refused(r, joined(args));
    EXPECT_EQ(listing(dir / "tmp"), std::set<std::string>{}) << joined(args) << ": temporary files left";
    EXPECT_EQ(listing(dir), before) << joined(args) << ": files created";
  }
  EXPECT_GE(cases.size(), 60u);
  fs::remove_all(dir);
}

TEST(CliHostile, OutOfRangeNumbersGetOneShortLine) {
  // every range check of a numeric option: one short line naming the option and the value given (not the
  // bounds of a double written out in hundreds of digits)
  const auto dir = work_dir();
  const std::vector<std::vector<std::string>> cases = {
      {"run", "--problem", "nbody", "--method", "LF", "--eps2", "-5"},
      {"run", "--problem", "nbody", "--method", "LF", "--h", "-1"},
      {"run", "--problem", "nbody", "--method", "LF", "--h", "0"},
      {"run", "--problem", "nbody", "--method", "LF", "--steps", "0"},
      {"run", "--problem", "nbody", "--method", "LF", "--n", "1"},
      {"run", "--method", "FR", "--steps-per-period", "-7"},
      {"run", "--method", "FR", "--periods", "0"},
      {"run", "--method", "FR", "--ecc", "-0.5"},
      {"run", "--method", "DP12-adaptive", "--tol", "-1"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--problem", "nbody", "--eps2", "-1"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--problem", "nbody", "--n", "1"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--t-end", "0"},
      {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--periods", "-1"},
      {"cputime", "--n", "1"},
      {"cputime", "--n", "10", "--eps", "-1"},
      {"cputime", "--n", "10", "--threads", "5000"},
      {"cputime", "--n", "10", "--h", "-0.1"},
      {"cputime", "--n", "10", "--steps", "0"},
      {"cputime", "--n", "10", "--repeats", "1001"},
      {"localerr", "--methods", "LF", "--n", "1"},
      {"localerr", "--methods", "LF", "--n", "10", "--eps", "-1"},
      {"localerr", "--methods", "LF", "--n", "10", "--threads", "5000"},
      {"localerr", "--methods", "LF", "--n", "10", "--duration", "0"},
      {"discover", "--starts", "0"},
      {"discover", "--threads", "300"},
      {"discover", "--box", "1e7"},
      {"discover", "--polish-bits", "8"},
      {"discover", "--tries", "0"},
      {"discover", "--perturbation", "-1"},
      {"discover", "--six-bits", "5000"},
      {"bench-peers", "--periods", "0"},
  };
  for (const auto& args : cases) {
    const Result r = run(dir, args);
    expect_refused(r, joined(args));
    EXPECT_LE(r.err.size(), 121u) << joined(args) << ": " << r.err;
    EXPECT_NE(r.err.find(args.back()), std::string::npos) << joined(args) << ": the value is named: " << r.err;
    EXPECT_NE(r.err.find(args[args.size() - 2]), std::string::npos) << joined(args) << ": the option: " << r.err;
  }
  // a malformed value of a range-checked option is a syntax error, not a range error
  for (const std::string v : {"nan", "inf", "", "-5x", "1e999"}) {
    const Result r = run(dir, {"run", "--problem", "nbody", "--method", "LF", "--eps2", v});
    expect_refused(r, "--eps2 " + v);
    EXPECT_LE(r.err.size(), 121u) << r.err;
  }
  fs::remove_all(dir);
}

TEST(CliHostile, NestedAdjointsResolveByParity) {
  const auto dir = work_dir();
  // an even nesting is the method itself, an odd one its adjoint; both without recursion
  const Result even = run(dir, {"coeffs", repeat("adjoint:", 10000) + "FR", "--json"});
  ASSERT_EQ(even.code, 0) << even.err;
  const Result plain = run(dir, {"coeffs", "FR", "--json"});
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_EQ(even.out, plain.out);
  const Result odd = run(dir, {"coeffs", repeat("adjoint:", 10001) + "BR1", "--json"});
  ASSERT_EQ(odd.code, 0) << odd.err;
  const Result one = run(dir, {"coeffs", "adjoint:BR1", "--json"});
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_EQ(odd.out, one.out);
  fs::remove_all(dir);
}

TEST(CliHostile, PlotFileNameIsNeverInterpreted) {
  const auto dir = work_dir();
  const std::string name = "a\nsystem 'touch PWNED'\nb.png";
  const std::string name2 = "x'; system \"touch PWNED2\"; '`touch PWNED3`$(touch PWNED4).png";
  for (const auto& n : {name, name2}) {
    const Result r = run(dir, {"sweep", "--methods", "FR,adjoint:FR", "--force-evals", "1e3:1e4:2", "--plot", n});
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(fs::is_regular_file(dir / "run" / n)) << "the plot is written under the name given";
    EXPECT_EQ(slurp(dir / "run" / n).substr(1, 3), "PNG");
  }
  for (const char* p : {"PWNED", "PWNED2", "PWNED3", "PWNED4"}) {
    EXPECT_FALSE(fs::exists(dir / "run" / p)) << p;
    EXPECT_FALSE(fs::exists(dir / "tmp" / p)) << p;
  }
  EXPECT_EQ(listing(dir / "tmp"), std::set<std::string>{});
  fs::remove_all(dir);
}

TEST(CliHostile, OutputThroughSymlinkReplacesTheTargetAndKeepsTheLink) {
  const auto dir = work_dir();
  fs::create_directories(dir / "data");
  std::ofstream(dir / "data" / "target.csv") << "old\n";
  fs::create_symlink(dir / "data" / "target.csv", dir / "run" / "link.csv");
  const Result r = run(dir, {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--csv", "link.csv"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir / "run" / "link.csv"));
  EXPECT_EQ(slurp(dir / "data" / "target.csv").rfind("method,family,order", 0), 0u);
  // a dangling link: its target is created
  fs::create_symlink(dir / "data" / "new.csv", dir / "run" / "dangling.csv");
  const Result d = run(dir, {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--csv", "dangling.csv"});
  ASSERT_EQ(d.code, 0) << d.err;
  EXPECT_TRUE(fs::is_symlink(dir / "run" / "dangling.csv"));
  EXPECT_TRUE(fs::is_regular_file(dir / "data" / "new.csv"));
  EXPECT_EQ(listing(dir / "data"), (std::set<std::string>{"new.csv", "target.csv"}));
  fs::remove_all(dir);
}

TEST(CliHostile, FifoAndDeviceAreWrittenInPlace) {
  const auto dir = work_dir();
  const auto fifo = dir / "run" / "pipe.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = slurp(fifo); });
  const Result r = run(dir, {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--csv", fifo.string()});
  reader.join();
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(got.rfind("method,family,order", 0), 0u);
  struct stat st {};
  ASSERT_EQ(::stat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode)) << "the FIFO was replaced";
  // /dev/null stays a device (written in place, not renamed over)
  const Result n = run(dir, {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--csv", "/dev/null"});
  ASSERT_EQ(n.code, 0) << n.err;
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  // a full device: the system's reason, not "Success"
  const Result full = run(dir, {"sweep", "--methods", "FR", "--force-evals", "1e3:1e3:1", "--csv", "/dev/full"});
  expect_refused(full, "--csv /dev/full");
  EXPECT_NE(full.err.find("No space left on device"), std::string::npos) << full.err;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  fs::remove_all(dir);
}

TEST(CliHostile, SigtermStopsALongRunAndRemovesTemporaryFiles) {
  const auto dir = work_dir();
  // tens of seconds of work: stopped after a moment; the signal's status, no file left behind
  const pid_t pid = start(dir, {"sweep", "--methods", "M8", "--force-evals", "1e6:1e8:40", "--periods", "20", "--csv",
                                "out.csv", "--plot", "out.png"});
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  ASSERT_EQ(::kill(pid, SIGTERM), 0);
  const Result r = finish(dir, pid);
  EXPECT_EQ(r.code, 128 + SIGTERM) << r.err;
  EXPECT_EQ(listing(dir / "run"), std::set<std::string>{});
  EXPECT_EQ(listing(dir / "tmp"), std::set<std::string>{});
  fs::remove_all(dir);
}

// Waits up to `limit` for `path` to contain `text`; true when it does.
bool wait_for_text(const fs::path& path, const std::string& text, std::chrono::seconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (slurp(path).find(text) != std::string::npos) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return false;
}

// The status of `pid` once it ends; SIGKILL and -1 if it has not ended within `limit` (it did not stop).
int wait_or_kill(pid_t pid, std::chrono::seconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  int status = 0;
  while (std::chrono::steady_clock::now() < end) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid) return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  return -1;
}

TEST(CliHostile, SigintStopsALongRunWithProgressAndLeavesNoFile) {
  const auto dir = work_dir();
  // a Kepler run of about 1.5e10 force evaluations (minutes): its progress line (forced on with
  // NYSTROM_PROGRESS=1) shows an estimate of the time left; SIGINT ends it with the signal's status, the
  // one-line message and no result on stdout
  const pid_t pid = start(dir, {"run", "--method", "M8", "--steps-per-period", "1000000", "--periods", "1000"}, "1");
  const bool progress = wait_for_text(dir / "stderr.txt", "ETA", std::chrono::seconds(60));
  EXPECT_TRUE(progress) << "no progress line: " << slurp(dir / "stderr.txt");
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  // promptly: the run had minutes left; the limit only keeps a failing test from hanging
  const int code = wait_or_kill(pid, std::chrono::seconds(30));
  EXPECT_EQ(code, 128 + SIGINT) << "the run did not stop on SIGINT";
  const std::string err = slurp(dir / "stderr.txt");
  EXPECT_NE(err.find("run ["), std::string::npos) << err;
  const std::string last = "nystrom: error: interrupted\n";
  ASSERT_GE(err.size(), last.size());
  EXPECT_EQ(err.substr(err.size() - last.size()), last);
  // The last progress line, just before the message, shows where the run stopped: far from its end.
  const std::string lines = err.substr(0, err.size() - last.size());
  const std::string final_line = lines.substr(lines.rfind('\r') + 1);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(final_line, m, std::regex(R"(^run \[#*-+\] (\d+)/(\d+) \(([0-9.]+)%\), )")))
      << final_line;
  const double done = std::stod(m[1]), total = std::stod(m[2]), percent = std::stod(m[3]);
  EXPECT_GT(done, 0);
  EXPECT_LT(done, 0.5 * total);
  EXPECT_LT(percent, 50);
  EXPECT_NEAR(percent, 100 * done / total, 0.1);
  EXPECT_EQ(slurp(dir / "stdout.txt"), "");
  EXPECT_EQ(listing(dir / "run"), std::set<std::string>{});
  EXPECT_EQ(listing(dir / "tmp"), std::set<std::string>{});
  fs::remove_all(dir);
}

TEST(CliHostile, SigintAfterACheckpointKeepsItWhole) {
  const auto dir = work_dir();
  // 1e7 steps of M8 (1e8 force evaluations) with a checkpoint at t = 1 of a span of 2000 pi: interrupted as soon
  // as the checkpoint is there, the run leaves it complete (it reads back), and nothing else
  const pid_t pid = start(dir, {"run", "--method", "M8", "--steps-per-period", "10000", "--periods", "1000",
                                "--checkpoint", "cp.txt", "--checkpoint-at", "1"});
  const bool written = wait_for_text(dir / "run" / "cp.txt", "\n", std::chrono::seconds(60));
  ASSERT_EQ(::kill(pid, SIGINT), 0);
  const int code = wait_or_kill(pid, std::chrono::seconds(30));
  ASSERT_TRUE(written) << slurp(dir / "stderr.txt");
  EXPECT_EQ(code, 128 + SIGINT) << "the run did not stop on SIGINT";
  EXPECT_EQ(slurp(dir / "stdout.txt"), "");
  EXPECT_EQ(listing(dir / "run"), std::set<std::string>{"cp.txt"});
  EXPECT_EQ(listing(dir / "tmp"), std::set<std::string>{});
  // the checkpoint names its method: the run restarts from it (one period, so that it ends at once)
  fs::rename(dir / "run" / "cp.txt", dir / "cp.txt");
  const Result r = run(
      dir, {"run", "--restart", (dir / "cp.txt").string(), "--steps-per-period", "10000", "--periods", "1", "--json"});
  EXPECT_EQ(r.code, 0) << r.err;
  fs::remove_all(dir);
}

// Runs the tool with a limit: a run that has not ended within `limit` is killed and reported as -1 (it hung).
Result run_limited(const fs::path& dir, const std::vector<std::string>& args,
                   std::chrono::seconds limit = std::chrono::seconds(60)) {
  const pid_t pid = start(dir, args);
  Result r;
  r.code = wait_or_kill(pid, limit);
  r.out = slurp(dir / "stdout.txt");
  r.err = slurp(dir / "stderr.txt");
  return r;
}

TEST(CliHostile, InputFilesThatAreNotRegularFilesAreRefusedAtOnce) {
  const auto dir = work_dir();
  const auto fifo = (dir / "pipe").string();  // no writer ever opens it
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"run", "--restart", "/dev/zero"}, "it is a device"},
      {{"run", "--method", "M8", "--restart", "/dev/zero"}, "it is a device"},
      {{"run", "--method", "M8", "--restart", fifo}, "it is a FIFO"},
      {{"run", "--method", "M8", "--restart", dir.string()}, "it is a folder"},
      {{"run", "--method", "file:/dev/zero"}, "it is a device"},
      {{"run", "--method", "file:" + fifo}, "it is a FIFO"},
      {{"coeffs", "file:/dev/zero"}, "it is a device"},
      {{"run", "--problem", "nbody", "--method", "VV", "--ic", "/dev/zero"}, "it is a device"},
      {{"run", "--problem", "nbody", "--method", "VV", "--ic", fifo}, "it is a FIFO"},
      {{"quantum", "--grid", "8", "--steps", "2", "--potential-file", "/dev/zero"}, "it is a device"},
      {{"quantum", "--grid", "8", "--steps", "2", "--potential-file", fifo}, "it is a FIFO"},
  };
  for (const auto& [args, why] : cases) {
    const auto t0 = std::chrono::steady_clock::now();
    const Result r = run_limited(dir, args);
    const std::string what = joined(args);
    EXPECT_NE(r.code, -1) << what << ": it did not end";
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(30)) << what;
    expect_refused(r, what);
    EXPECT_NE(r.err.find(why), std::string::npos) << what << ": " << r.err;
  }
  fs::remove_all(dir);
}

namespace {

// The checkpoint with its checksum line recomputed (tests/support/checksum.hpp, independently of the tool).
std::string rechecksum(const std::string& text) { return nystrom::test::with_checksum(nystrom::test::body_of(text)); }

std::string replace_line(const std::string& text, const std::string& key, const std::string& line) {
  const auto a = text.find("\n" + key + " ");
  const auto b = text.find('\n', a + 1);
  return text.substr(0, a + 1) + line + text.substr(b);
}

}  // namespace

TEST(CliHostile, CorruptedCheckpointsAreRefused) {
  const auto dir = work_dir();
  const std::vector<std::string> m8 = {"run", "--method", "M8", "--steps-per-period", "1000", "--periods", "2"};
  auto with = [](std::vector<std::string> a, const std::vector<std::string>& more) {
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  ASSERT_EQ(run(dir, with(m8, {"--checkpoint", "cp", "--checkpoint-at", "1"})).code, 0);
  const std::string good = slurp(dir / "run" / "cp");
  ASSERT_NE(good.find("\ncarry 4 "), std::string::npos) << good;
  auto restart = [&](const std::string& text, const std::string& what) {
    std::ofstream(dir / "run" / "bad", std::ios::binary) << text;
    const Result r = run_limited(dir, with(m8, {"--restart", "bad", "--json"}));
    expect_refused(r, what);
    EXPECT_NE(r.err.find("checkpoint"), std::string::npos) << what << ": " << r.err;
    EXPECT_EQ(r.out, "") << what;
  };
  std::string bad = good;
  const auto q = bad.find("\nstate 4 0x") + 11;
  bad[q] = bad[q] == '1' ? '2' : '1';
  restart(bad, "a hex digit of q changed");
  bad = good;
  const auto si = bad.find("\nstep_index ") + 12;
  bad[si] = static_cast<char>(bad[si] == '9' ? '8' : bad[si] + 1);
  restart(bad, "step_index changed");
  bad = good;
  const auto t = bad.find("\nt 0x") + 6;
  bad[t] = bad[t] == '8' ? '9' : '8';
  restart(bad, "t changed");
  bad = good;
  bad.insert(bad.find("\nt 0x") + 5, 1, '\0');
  restart(bad, "a NUL byte in t");
  bad = good;
  const auto c = bad.find("\ncarry ");
  bad.erase(c, bad.find('\n', c + 1) - c);
  restart(bad, "the carry line deleted");
  restart(rechecksum(bad), "the carry line deleted, checksum recomputed");
  // the checkpoint as written restarts
  EXPECT_EQ(run(dir, with(m8, {"--restart", "cp"})).code, 0);

  // GBS: an order of 100000000 columns and a NaN state; an order beyond the integrator's columns with a state
  // that reads: refused (the first crashed the restart), not a signal
  const std::vector<std::string> gbs = {"run", "--method", "GBS", "--tol", "1e-10", "--periods", "2"};
  ASSERT_EQ(run(dir, with(gbs, {"--checkpoint", "g", "--checkpoint-at", "1"})).code, 0);
  const std::string g = slurp(dir / "run" / "g");
  for (const auto& [text, why] : std::vector<std::pair<std::string, std::string>>{
           {rechecksum(
                replace_line(replace_line(g, "columns", "columns 100000000"), "state", "state 4 nan nan nan nan")),
            "malformed checkpoint"},
           {rechecksum(replace_line(g, "columns", "columns 25")), "columns) is outside 2..11"}}) {
    std::ofstream(dir / "run" / "bad", std::ios::binary) << text;
    const Result r = run_limited(dir, with(gbs, {"--restart", "bad"}));
    expect_refused(r, why);
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
  }
  fs::remove_all(dir);
}

TEST(CliHostile, CheckpointTargetsThatAreNotRegularFilesAreRefused) {
  const auto dir = work_dir();
  const std::vector<std::string> m8 = {"run", "--method",        "M8", "--steps-per-period", "1000", "--periods",
                                       "2",   "--checkpoint-at", "1",  "--checkpoint"};
  auto with = [](std::vector<std::string> a, const std::string& target) {
    a.push_back(target);
    return a;
  };
  ASSERT_EQ(::mkfifo((dir / "run" / "pipe").c_str(), 0600), 0);
  std::ofstream(dir / "victim") << "precious\n";
  fs::create_symlink(dir / "victim", dir / "run" / "link");
  fs::create_directories(dir / "run" / "folder");
  for (const auto& [target, why] : std::vector<std::pair<std::string, std::string>>{{"pipe", "it is a FIFO"},
                                                                                    {"link", "it is a symbolic link"},
                                                                                    {"folder", "it is a folder"},
                                                                                    {"/dev/null", "it is a device"}}) {
    const Result r = run_limited(dir, with(m8, target));
    expect_refused(r, target);
    EXPECT_NE(r.err.find("cannot write the checkpoint file '" + target + "': " + why), std::string::npos) << r.err;
  }
  struct stat st {};
  ASSERT_EQ(::lstat((dir / "run" / "pipe").c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  EXPECT_TRUE(fs::is_symlink(dir / "run" / "link"));
  EXPECT_EQ(slurp(dir / "victim"), "precious\n");
  EXPECT_EQ(listing(dir / "run"), (std::set<std::string>{"pipe", "link", "folder"}));
  fs::remove_all(dir);
}
