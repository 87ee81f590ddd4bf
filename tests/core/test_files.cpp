// The files a user names (core/files.hpp) and checkpoints (solve/checkpoint.hpp): the one writer replaces a
// regular file atomically and refuses devices, FIFOs, folders and symbolic links, never writes through a
// temporary name someone planted, leaves nothing behind when a write fails, and lets several threads and
// processes write one file; the one reader refuses what is not a regular file or is too large without
// blocking; a checkpoint with any byte changed, or with values no run can have written, is refused with one
// line, never restarted from (nor a crash).
#include <gtest/gtest.h>

#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "nystrom/core/files.hpp"
#include "nystrom/solve.hpp"
#include "support/checksum.hpp"
#include "support/files.hpp"
#include "support/kepler.hpp"

using namespace nystrom;
using nystrom::test::kepler;
using nystrom::test::slurp;
namespace fs = std::filesystem;

namespace {

fs::path fresh_dir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto d = fs::temp_directory_path() / ("nystrom-files-" + std::to_string(::getpid()) + "-" + info->name());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

using test::body_of;
using test::with_checksum;

// The line of `key` in a checkpoint text replaced by `line` (no line break), the checksum recomputed.
std::string with_line(const std::string& text, const std::string& key, const std::string& line) {
  std::string body = body_of(text);
  const auto a = body.find("\n" + key + " ");
  EXPECT_NE(a, std::string::npos) << key;
  const auto b = body.find('\n', a + 1);
  return with_checksum(body.substr(0, a + 1) + line + body.substr(b));
}

}  // namespace

// ---- the writer ----------------------------------------------------------------------------------------

TEST(FileWriter, ReplacesARegularFileAtomicallyAndKeepsItsMode) {
  const auto dir = fresh_dir();
  const auto path = (dir / "out.txt").string();
  write_file_atomic(path, "first\n");
  EXPECT_EQ(slurp(path), "first\n");
  const mode_t mask = ::umask(0);
  ::umask(mask);
  EXPECT_EQ(fs::status(path).permissions(), static_cast<fs::perms>(0666 & ~mask));
  fs::permissions(path, static_cast<fs::perms>(0640));
  write_file_atomic(path, "second\n");
  EXPECT_EQ(slurp(path), "second\n");
  EXPECT_EQ(fs::status(path).permissions(), static_cast<fs::perms>(0640));
  EXPECT_EQ(listing(dir), std::set<std::string>{"out.txt"}) << "a temporary file was left";
  // a file name of 250 bytes: its temporary name is shortened, not refused
  const std::string long_name(250, 'n');
  write_file_atomic((dir / long_name).string(), "x");
  EXPECT_EQ(slurp(dir / long_name), "x");
  fs::remove_all(dir);
}

TEST(FileWriter, RefusesFoldersDevicesFifosAndSymlinks) {
  const auto dir = fresh_dir();
  auto refused = [&](const std::string& path, const std::string& why) {
    const std::string msg = error_of([&] { write_checkpoint_text(path, "checkpoint\n"); });
    EXPECT_NE(msg.find("cannot write the checkpoint file '" + path + "': " + why), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  };
  fs::create_directories(dir / "folder");
  refused((dir / "folder").string(), "it is a folder");
  refused("/dev/null", "it is a device");
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
  // a private character device node (as root; /dev/full's numbers): it stays a device
  const auto node = dir / "node";
  if (::mknod(node.c_str(), S_IFCHR | 0600, ::makedev(1, 7)) == 0) {
    refused(node.string(), "it is a device");
    ASSERT_EQ(::lstat(node.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << "the device node was replaced";
  }
  // a FIFO without a reader: refused at once (the writer does not open it), and it stays a FIFO
  const auto fifo = dir / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  refused(fifo.string(), "it is a FIFO");
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  // a symbolic link to a file, and a dangling one: refused, the link and its target untouched
  std::ofstream(dir / "victim") << "precious\n";
  fs::create_symlink(dir / "victim", dir / "link");
  refused((dir / "link").string(), "it is a symbolic link");
  EXPECT_TRUE(fs::is_symlink(dir / "link"));
  EXPECT_EQ(slurp(dir / "victim"), "precious\n");
  fs::create_symlink(dir / "nowhere", dir / "dangling");
  refused((dir / "dangling").string(), "it is a symbolic link");
  EXPECT_FALSE(fs::exists(dir / "nowhere"));
  refused((dir / "missing" / "cp").string(), "folder '" + (dir / "missing").string() + "' does not exist");
  std::set<std::string> expected{"folder", "fifo", "victim", "link", "dangling"};
  if (fs::exists(fs::symlink_status(node))) expected.insert("node");
  EXPECT_EQ(listing(dir), expected) << "the refusals created a file";
  fs::remove_all(dir);
}

// A path whose last component is no file name (empty after a slash, ".", "..") is refused as such, whether or not
// the folder before it exists, and nothing is created.
TEST(FileWriter, APathEndingInNoFileNameIsRefused) {
  const auto dir = fresh_dir();
  for (const std::string tail : {"missing/", "missing/.", "missing/..", "x/./"}) {
    const std::string path = (dir / tail).string();
    const std::string msg = error_of([&] { write_file_atomic(path, "x\n"); });
    EXPECT_NE(msg.find("'" + path + "': not a file name"), std::string::npos) << msg;
  }
  EXPECT_TRUE(listing(dir).empty());
}

TEST(FileWriter, NeverWritesThroughOrConsumesAPlantedTemporaryName) {
  const auto dir = fresh_dir();
  const auto path = dir / "run.checkpoint";
  std::ofstream(dir / "victim") << "precious\n";
  // the names a fixed-name writer would use: a link to a victim, and a user's own file
  fs::create_symlink(dir / "victim", dir / "run.checkpoint.tmp");
  std::ofstream(dir / "user.tmp") << "mine\n";
  write_checkpoint_text(path.string(), "new\n");
  EXPECT_EQ(slurp(path), "new\n");
  EXPECT_EQ(slurp(dir / "victim"), "precious\n");
  EXPECT_TRUE(fs::is_symlink(dir / "run.checkpoint.tmp"));
  write_checkpoint_text((dir / "user").string(), "other\n");
  EXPECT_EQ(slurp(dir / "user.tmp"), "mine\n");
  EXPECT_EQ(listing(dir),
            (std::set<std::string>{"run.checkpoint", "run.checkpoint.tmp", "victim", "user", "user.tmp"}));
  fs::remove_all(dir);
}

TEST(FileWriter, AFailedWriteKeepsTheOldFileAndLeavesNoTemporary) {
  const auto dir = fresh_dir();
  const auto path = dir / "out.txt";
  std::ofstream(path) << "old\n";
  // a full disk, simulated by a file-size limit of 1000 bytes (write fails with EFBIG)
  struct rlimit old {};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct rlimit small = old;
  small.rlim_cur = 1000;
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string msg = error_of([&] { write_file_atomic(path.string(), std::string(100000, 'x')); });
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, old_handler);
  EXPECT_NE(msg.find("cannot write '" + path.string() + "': File too large"), std::string::npos) << msg;
  EXPECT_EQ(slurp(path), "old\n");
  EXPECT_EQ(listing(dir), std::set<std::string>{"out.txt"});
  fs::remove_all(dir);
}

TEST(FileWriter, ThreadsAndProcessesWritingOneFileAllSucceed) {
  const auto dir = fresh_dir();
  const auto path = (dir / "shared.checkpoint").string();
  auto content = [](int who, int i) { return "writer " + std::to_string(who) + " round " + std::to_string(i) + "\n"; };
  std::vector<std::thread> threads;
  std::vector<int> failures(8, 0);
  for (int w = 0; w < 8; ++w)
    threads.emplace_back([&, w] {
      for (int i = 0; i < 10; ++i) {
        try {
          write_checkpoint_text(path, content(w, i));
        } catch (const std::exception&) {
          ++failures[static_cast<std::size_t>(w)];
        }
      }
    });
  for (auto& t : threads) t.join();
  for (int w = 0; w < 8; ++w) EXPECT_EQ(failures[static_cast<std::size_t>(w)], 0) << "thread " << w;
  EXPECT_EQ(slurp(path).rfind("writer ", 0), 0u);
  std::vector<pid_t> children;
  for (int w = 0; w < 4; ++w) {
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      int bad = 0;
      for (int i = 0; i < 10; ++i) {
        try {
          write_checkpoint_text(path, content(100 + w, i));
        } catch (...) {
          ++bad;
        }
      }
      ::_exit(bad == 0 ? 0 : 1);
    }
    children.push_back(pid);
  }
  for (pid_t pid : children) {
    int status = 0;
    ASSERT_EQ(::waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "a process failed to write";
  }
  const std::string last = slurp(path);
  EXPECT_EQ(last.rfind("writer 10", 0), 0u) << last;
  EXPECT_EQ(listing(dir), std::set<std::string>{"shared.checkpoint"});
  fs::remove_all(dir);
}

TEST(FileWriter, RegisteredTemporaryPathsAreRemovedForASignal) {
  const auto dir = fresh_dir();
  const auto file = dir / "partial";
  std::ofstream(file) << "half";
  {
    TemporaryPath t(file.string());
    nystrom::remove_temporary_paths();  // what the tool's SIGINT/SIGTERM handler calls
    EXPECT_FALSE(fs::exists(file));
    std::ofstream(file) << "kept";
    t.release();
  }
  EXPECT_TRUE(fs::exists(file)) << "a released path is not removed";
  fs::remove_all(dir);
}

// ---- the reader ----------------------------------------------------------------------------------------

TEST(FileReader, ReadsARegularFileAndRefusesAnythingElseWithoutBlocking) {
  const auto dir = fresh_dir();
  std::ofstream(dir / "ok") << "content\n";
  EXPECT_EQ(read_input_file((dir / "ok").string(), "the test file"), "content\n");
  auto refused = [&](const std::string& path, const std::string& why, std::size_t max = max_input_file_bytes) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::string msg = error_of([&] { read_input_file(path, "the test file", max); });
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(5)) << path;
    EXPECT_NE(msg.find("cannot read the test file '" + path + "': " + why), std::string::npos) << msg;
  };
  refused("/dev/zero", "it is a device");
  refused(dir.string(), "it is a folder");
  refused((dir / "none").string(), "No such file or directory");
  ASSERT_EQ(::mkfifo((dir / "fifo").c_str(), 0600), 0);
  refused((dir / "fifo").string(), "it is a FIFO");  // no writer: it would block forever if opened
  std::ofstream(dir / "big") << std::string(2000, 'x');
  refused((dir / "big").string(), "it is larger than 1024 bytes", 1024);
  EXPECT_EQ(read_input_file((dir / "big").string(), "the test file", 2000).size(), 2000u);
  EXPECT_THROW(read_input_file<std::invalid_argument>("/dev/zero", "x"), std::invalid_argument);
  fs::remove_all(dir);
}

// ---- checkpoints ---------------------------------------------------------------------------------------

namespace {

// A checkpoint of `method` on Kepler e = 0.7 over [0, 30], taken at t = 12.3, as text.
std::string checkpoint_text(const std::string& method, const SolveOptions& base) {
  SolveOptions opt = base;
  opt.checkpoint_at = 12.3;
  opt.checkpoint_problem = "kepler e=0.7";
  std::string text;
  opt.on_checkpoint = [&](const std::string& s) { text = s; };
  solve(kepler(0.7, 0.0, 30.0), resolve_solve_method(method), opt);
  return text;
}

}  // namespace

TEST(Checkpoint, TheTextHasAVersionTheRealTypeAndAChecksum) {
  const std::string text = checkpoint_text("M8", {.steps = 3000});
  EXPECT_EQ(text.rfind("nystrom-checkpoint 2\nreal double\nmethod M8\n", 0), 0u) << text;
  EXPECT_EQ(with_checksum(body_of(text)), text);
  const auto c = checkpoint_from_text<double>(text);
  EXPECT_EQ(to_text(c), text);
  EXPECT_EQ(c.carry.size(), c.state.size());  // double's default: compensated summation
  // another real type, the previous version and other versions are refused
  EXPECT_NE(error_of([&] { checkpoint_from_text<long double>(text); }).find("holds double numbers, not long-double"),
            std::string::npos);
  std::string v1 = text;
  v1.replace(0, 20, "nystrom-checkpoint 1");
  EXPECT_NE(error_of([&] { checkpoint_from_text<double>(v1); }).find("version 1"), std::string::npos);
  EXPECT_THROW(checkpoint_from_text<double>("nystrom-checkpoint 99\n"), invalid_input);
  EXPECT_THROW(checkpoint_from_text<double>("garbage"), invalid_input);
  EXPECT_THROW(checkpoint_from_text<double>(""), invalid_input);
}

TEST(Checkpoint, TheCorruptionsOfTheAuditAreRefused) {
  const std::string text = checkpoint_text("M8", {.steps = 3000});
  auto refused = [&](const std::string& bad, const std::string& why, const std::string& what) {
    const std::string msg = error_of([&] { checkpoint_from_text<double>(bad); });
    EXPECT_NE(msg.find(why), std::string::npos) << what << ": " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << what << ": " << msg;
  };
  const std::string checksum = "the checksum does not match";
  // one hex digit of q changed
  {
    std::string bad = text;
    const auto p = bad.find("\nstate 4 0x") + 11;
    bad[p] = bad[p] == '1' ? '2' : '1';
    refused(bad, checksum, "a hex digit of q");
  }
  // step_index off by one, t changed
  {
    const auto c = checkpoint_from_text<double>(text);
    std::string bad = text;
    const std::string from = "\nstep_index " + std::to_string(c.step_index) + "\n";
    bad.replace(bad.find(from), from.size(), "\nstep_index " + std::to_string(c.step_index + 1) + "\n");
    refused(bad, checksum, "step_index + 1");
    bad = text;
    const auto p = bad.find("\nt 0x") + 6;
    bad[p] = bad[p] == '8' ? '9' : '8';
    refused(bad, checksum, "t");
  }
  // a NUL byte inside a number (before the checksum is even looked at), and a deleted carry line
  {
    std::string bad = text;
    bad.insert(bad.find("\nt 0x") + 5, 1, '\0');
    refused(bad, "NUL byte", "NUL in t");
    bad = text;
    const auto a = bad.find("\ncarry ");
    bad.erase(a, bad.find('\n', a + 1) - a);
    refused(bad, checksum, "no carry line");
    refused(with_checksum(body_of(bad)), "expected the line 'carry' here", "no carry line, checksum recomputed");
  }
  // truncated anywhere
  for (std::size_t n = 0; n < text.size(); n += 7)
    EXPECT_THROW(checkpoint_from_text<double>(text.substr(0, n)), invalid_input) << "truncated to " << n;
}

TEST(Checkpoint, EveryChangedByteIsRefused) {
  // every byte of a GBS and an adaptive checkpoint replaced by a few others: never read back
  for (const auto& [method, opt] :
       {std::pair<std::string, SolveOptions>{"GBS", {.rtol = 1e-10}}, {"DP12-adaptive", {.rtol = 1e-10}}}) {
    const std::string text = checkpoint_text(method, opt);
    ASSERT_FALSE(text.empty()) << method;
    long accepted = 0;
    for (std::size_t i = 0; i < text.size(); ++i)
      for (char r : {'0', '1', 'f', 'x', '-', ' ', '\n', '\0'}) {
        if (text[i] == r) continue;
        std::string bad = text;
        bad[i] = r;
        try {
          checkpoint_from_text<double>(bad);
          ++accepted;
          ADD_FAILURE() << method << ": byte " << i << " changed to " << static_cast<int>(r) << " was accepted";
        } catch (const invalid_input&) {
        }
      }
    EXPECT_EQ(accepted, 0) << method;
  }
}

TEST(Checkpoint, ValuesNoRunCanHaveWrittenAreRefusedWithAValidChecksum) {
  const std::string gbs = checkpoint_text("GBS", {.rtol = 1e-10});
  const std::string fixed = checkpoint_text("M8", {.steps = 3000});
  const std::string adaptive = checkpoint_text("DP12-adaptive", {.rtol = 1e-10});
  struct Case {
    std::string text, why;
  };
  const std::vector<Case> cases = {
      {with_line(gbs, "columns", "columns 100000000"), "columns"},
      {with_line(gbs, "columns", "columns 30"), "2 to 29 columns"},
      {with_line(gbs, "columns", "columns 1"), "2 to 29 columns"},
      {with_line(gbs, "state", "state 4 nan nan nan nan"), "not a number in hexadecimal"},
      {with_line(gbs, "state", "state 4 0x1p+0 0x1p+0 0x1p+0 0x1p+5000"), "not a finite number"},
      {with_line(gbs, "state", "state 4 0x1p+0 0x1p+0 0x1p+0 0x1p+0junk"), "not a number in hexadecimal"},
      {with_line(gbs, "state", "state 5 0x1p+0 0x1p+0 0x1p+0 0x1p+0"), "declares 5 values but holds 4"},
      {with_line(gbs, "state", "state 99999999999 0x1p+0"), "declares 99999999999 values"},
      {with_line(gbs, "state", "state 2 0x1p+0 0x1p+0"), ""},  // read; the run refuses its size (below)
      {with_line(gbs, "h_want", "h_want -0x1p+0"), "must be positive"},
      {with_line(gbs, "span", "span 0x0p+0"), "must be positive"},
      {with_line(gbs, "step_index", "step_index 3"), "no step index"},
      {with_line(gbs, "counters", "counters 1 2 3"), "counters needs 4 values"},
      {with_line(gbs, "counters", "counters -1 0 0 0"), "not an integer"},
      {with_line(gbs, "counters", "counters +1 0 0 0"), "not an integer"},
      {with_line(gbs, "last_rejected", "last_rejected 2"), "not an integer in [0, 1]"},
      {with_line(gbs, "engine", "engine warp"), "unknown engine"},
      {with_line(gbs, "t", "t  0x1p+0"), "not a number in hexadecimal"},
      {with_line(fixed, "step_index", "step_index 0"), "step_index >= 1"},
      {with_line(fixed, "carry", "carry 2 0x0p+0 0x0p+0"), "as many as the state's values"},
      {with_line(fixed, "columns", "columns 3"), "no step controller"},
      {with_line(adaptive, "hmax", "hmax 0x1p-40"), "within its bound"},
      {with_line(adaptive, "q_prev", "q_prev -0x1p+0"), "history is negative"},
      {with_checksum(body_of(gbs) + "extra 1\n"), "unexpected lines"},
      {gbs + "trailing\n", "no checksum line"},
      // a number cut short at every place of its grammar
      {with_line(gbs, "t", "t 0x1.8p"), "not a number in hexadecimal"},
      {with_line(gbs, "t", "t 0x1.8p+"), "not a number in hexadecimal"},
      {with_line(gbs, "t", "t 0x1.8"), "not a number in hexadecimal"},
      {with_line(gbs, "t", "t 0x1."), "not a number in hexadecimal"},
      {with_line(gbs, "t", "t 0x"), "not a number in hexadecimal"},
      {with_line(gbs, "t", "t -"), "not a number in hexadecimal"},
  };
  for (const auto& c : cases) {
    if (c.why.empty()) continue;
    const std::string msg = error_of([&] { checkpoint_from_text<double>(c.text); });
    EXPECT_NE(msg.find(c.why), std::string::npos) << msg << "\n" << c.text;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
  // a state of another size is read, and refused by the run
  const auto small = checkpoint_from_text<double>(cases[8].text);
  const auto prob = kepler(0.7, 0.0, 30.0);
  SolveOptions opt{.rtol = 1e-10};
  opt.checkpoint_problem = "kepler e=0.7";
  EXPECT_THROW(resume(prob, gbs_method_def(), small, opt), invalid_input);
}

TEST(Checkpoint, AGbsRestartWithAnOrderBeyondItsColumnsIsRefusedNotACrash) {
  // The checkpoint of the audit: columns 100000000 and a NaN state, handed to resume() directly (a program
  // may build a Checkpoint itself): the engine's order would index its step-number sequence far out of bounds.
  const auto prob = kepler(0.7, 0.0, 30.0);
  SolveOptions opt{.rtol = 1e-10};
  opt.checkpoint_problem = "kepler e=0.7";
  auto cp = checkpoint_from_text<double>(checkpoint_text("GBS", opt));
  for (int columns : {100000000, 12, 1, -5}) {
    auto bad = cp;
    bad.columns = columns;
    if (columns == 100000000)
      for (auto& x : bad.state) x = std::numeric_limits<double>::quiet_NaN();
    const std::string msg = error_of([&] { resume(prob, gbs_method_def(), bad, opt); });
    EXPECT_NE(msg.find("columns) is outside 2..11"), std::string::npos) << columns << ": " << msg;
  }
  auto late = cp;
  late.span = 31.0;  // beyond the span
  EXPECT_THROW(resume(prob, gbs_method_def(), late, opt), invalid_input);
  // the checkpoint as taken restarts
  const auto sol = resume(prob, gbs_method_def(), cp, opt);
  EXPECT_EQ(sol.status, SolveStatus::success);
}

TEST(Checkpoint, ARestartRefusesATimeOrStepThatDoNotMatchTheRun) {
  const auto prob = kepler(0.7, 0.0, 30.0);
  SolveOptions fixed{.steps = 3000};
  fixed.checkpoint_problem = "kepler e=0.7";
  const auto cp = checkpoint_from_text<double>(checkpoint_text("M8", fixed));
  const auto def = resolve_method("M8");
  auto bad = cp;
  bad.t = std::nextafter(cp.t, 100.0);
  EXPECT_NE(error_of([&] { resume(prob, def, bad, fixed); }).find("time is not that of its step index"),
            std::string::npos);
  bad = cp;
  bad.step_index = 3001;
  EXPECT_THROW(resume(prob, def, bad, fixed), invalid_input);
  // adaptive: a next step that is not positive
  SolveOptions tol{.rtol = 1e-10};
  tol.checkpoint_problem = "kepler e=0.7";
  auto ad = checkpoint_from_text<double>(checkpoint_text("DP12-adaptive", tol));
  ad.h_want = -1;
  EXPECT_NE(error_of([&] { resume(prob, resolve_solve_method("DP12-adaptive"), ad, tol); }).find("resume point"),
            std::string::npos);
}

TEST(Checkpoint, ReadCheckpointRefusesDevicesFoldersAndLargeFiles) {
  const auto dir = fresh_dir();
  EXPECT_NE(error_of([] { read_checkpoint<double>("/dev/zero"); }).find("it is a device"), std::string::npos);
  EXPECT_NE(error_of([&] { read_checkpoint<double>(dir.string()); }).find("it is a folder"), std::string::npos);
  const std::string text = checkpoint_text("M8", {.steps = 3000});
  std::ofstream(dir / "cp") << text;
  EXPECT_EQ(to_text(read_checkpoint<double>((dir / "cp").string())), text);
  EXPECT_NE(error_of([&] { read_checkpoint<double>((dir / "cp").string(), 100); }).find("larger than 100 bytes"),
            std::string::npos);
  // write_checkpoint and read_checkpoint round trip
  write_checkpoint((dir / "cp2").string(), read_checkpoint<double>((dir / "cp").string()));
  EXPECT_EQ(slurp(dir / "cp2"), text);
  fs::remove_all(dir);
}
