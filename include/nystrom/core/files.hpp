// The files a user names: one writer of result and checkpoint files and one reader of input files for the
// library, the command-line tool and the Python module (POSIX).
//
// write_file_atomic(path, content): a regular file (or a new name) is replaced atomically: the content goes
// to a temporary file of a unique name created in the target's folder (O_CREAT | O_EXCL, so it is never a
// link someone else planted), is flushed to the disk (fsync), and is renamed over the target. A reader sees
// the old file or the new one, never a part; several threads or processes writing the same target all
// succeed (the last rename wins); a failure removes the temporary file. By default a target that is not a
// regular file (a folder, device, FIFO or socket) or is a symbolic link is refused with one line, and
// nothing is written. The tool's result files ask for two relaxations (FileWriteOptions): streams are
// written in place (`--csv /dev/stdout`, a pipe), and a link's final target is replaced (the link kept).
//
// read_input_file(path, what): the whole content of a regular file of at most max_bytes (64 MiB by
// default). A folder, device, FIFO or socket is refused before anything is read (so /dev/zero cannot
// exhaust memory and a FIFO without a writer cannot block: it is opened with O_NONBLOCK and checked with
// fstat), and so is a larger file.
//
// TemporaryPath: a temporary file or folder removed when the object goes; remove_temporary_paths() removes
// every one that exists, and is async-signal-safe: the tool's SIGINT/SIGTERM handler calls it, so no
// interrupted write leaves its temporary file behind.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstring>
#include <string>
#include <string_view>
#include <system_error>

#include "nystrom/core/error.hpp"

namespace nystrom {

/// The largest input file read_input_file reads by default (checkpoints, method files, potential files,
/// particle files): 64 MiB.
inline constexpr std::size_t max_input_file_bytes = std::size_t{64} << 20;

namespace file_detail {

inline constexpr int temp_slots = 64;
inline constexpr std::size_t temp_path_max = 4096;

// The registered temporary paths live in fixed buffers, written before a slot is marked in use (kind 1: a
// file, 2: a folder; 3: being written), so that a signal handler reads them without allocating.
struct TempTable {
  char path[temp_slots][temp_path_max];
  std::atomic<int> kind[temp_slots];
};
inline TempTable temp_table{};

inline std::string reason(int e) { return std::generic_category().message(e); }

inline std::string size_text(std::size_t bytes) {
  if (bytes % (std::size_t{1} << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

inline const char* kind_of(mode_t mode) {
  if (S_ISDIR(mode)) return "it is a folder";
  if (S_ISFIFO(mode)) return "it is a FIFO, not a regular file";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "it is a device, not a regular file";
  if (S_ISSOCK(mode)) return "it is a socket, not a regular file";
  return "it is not a regular file";
}

inline bool under_system_folder(const std::string& path) {
  return path.rfind("/dev/", 0) == 0 || path.rfind("/proc/", 0) == 0;
}

}  // namespace file_detail

/// A temporary file or folder of this process: removed (unlink, rmdir) when the object goes unless
/// released, and by remove_temporary_paths() from a signal handler meanwhile.
class TemporaryPath {
 public:
  enum class Kind : unsigned char { file, directory };
  TemporaryPath() = default;
  explicit TemporaryPath(std::string path, Kind kind = Kind::file)
      : path_(std::move(path)), directory_(kind == Kind::directory) {
    auto& table = file_detail::temp_table;
    if (path_.size() >= file_detail::temp_path_max) return;  // removed by the destructor only
    for (int i = 0; i < file_detail::temp_slots; ++i) {
      int expected = 0;
      if (!table.kind[i].compare_exchange_strong(expected, 3)) continue;
      std::memcpy(table.path[i], path_.c_str(), path_.size() + 1);
      table.kind[i].store(directory_ ? 2 : 1);
      slot_ = i;
      break;
    }
  }
  TemporaryPath(const TemporaryPath&) = delete;
  TemporaryPath& operator=(const TemporaryPath&) = delete;
  ~TemporaryPath() {
    if (!path_.empty()) (directory_ ? ::rmdir(path_.c_str()) : ::unlink(path_.c_str()));
    release();
  }
  const std::string& path() const { return path_; }
  /// The path was renamed into place (or is to stay): nothing to remove.
  void release() {
    if (slot_ >= 0) file_detail::temp_table.kind[slot_].store(0);
    slot_ = -1;
    path_.clear();
  }

 private:
  std::string path_;
  int slot_ = -1;
  bool directory_ = false;
};

/// Removes every registered temporary file, then every registered folder. Async-signal-safe.
inline void remove_temporary_paths() noexcept {
  auto& table = file_detail::temp_table;
  for (int i = 0; i < file_detail::temp_slots; ++i)
    if (table.kind[i].load() == 1) ::unlink(table.path[i]);
  for (int i = 0; i < file_detail::temp_slots; ++i)
    if (table.kind[i].load() == 2) ::rmdir(table.path[i]);
}

/// What write_file_atomic may do besides replacing a regular file.
struct FileWriteOptions {
  /// Write FIFOs, character devices, sockets and paths under /dev/ and /proc/ in place (appending to a regular
  /// file there, e.g. /dev/stdout redirected to a file); otherwise they are refused.
  bool streams = false;
  /// Replace the final target of a symbolic link (created if the link dangles; the link is kept); otherwise a
  /// link is refused.
  bool follow_links = false;
  /// The file's role in messages ("the checkpoint file" gives "cannot write the checkpoint file 'x': ...").
  std::string what{};
};

namespace file_detail {

struct Fd {
  int fd = -1;
  Fd() = default;
  explicit Fd(int f) : fd(f) {}
  Fd(const Fd&) = delete;
  Fd& operator=(const Fd&) = delete;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
  int close() {
    const int r = ::close(fd);
    fd = -1;
    return r;
  }
};

inline int write_all(int fd, std::string_view content) {
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return 0;
}

// The final path that a chain of symbolic links names (the last component may not exist yet); "" with
// errno set when it cannot be resolved.
inline std::string follow_links(std::string path) {
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
    std::string buf(temp_path_max, '\0');
    const ssize_t n = ::readlink(path.c_str(), buf.data(), buf.size() - 1);
    if (n < 0) return {};
    buf.resize(static_cast<std::size_t>(n));
    if (!buf.empty() && buf[0] == '/') {
      path = buf;
    } else {
      const auto slash = path.rfind('/');
      path = (slash == std::string::npos ? std::string() : path.substr(0, slash + 1)) + buf;
    }
  }
  errno = ELOOP;
  return {};
}

}  // namespace file_detail

/// Writes `content` to `path` (see the top of the file). Throws nystrom::error with the system's reason.
inline void write_file_atomic(const std::string& path, std::string_view content, const FileWriteOptions& opt = {}) {
  using namespace file_detail;
  const std::string name = "cannot write " + (opt.what.empty() ? std::string() : opt.what + " ") + "'" + path + "'";
  auto fail = [&](const std::string& why) { return error(name + ": " + why); };
  if (path.empty()) throw error(opt.what.empty() ? "empty output file name" : opt.what + ": empty file name");
  struct stat lst {};
  const bool exists_l = ::lstat(path.c_str(), &lst) == 0;
  if (exists_l && S_ISLNK(lst.st_mode) && !opt.follow_links) throw fail("it is a symbolic link");
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw fail("it is a folder");
  if (exists && (!S_ISREG(st.st_mode) || under_system_folder(path))) {
    if (!opt.streams) throw fail(kind_of(st.st_mode));
    Fd f(::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC | (S_ISREG(st.st_mode) ? O_APPEND : 0)));
    if (f.fd < 0) throw fail(reason(errno));
    if (const int e = write_all(f.fd, content)) throw fail(reason(e));
    if (f.close() != 0) throw fail(reason(errno));
    return;
  }
  const std::string target = opt.follow_links ? follow_links(path) : path;
  if (target.empty()) throw fail(reason(errno));
  const auto slash = target.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : target.substr(0, slash));
  const std::string file = slash == std::string::npos ? target : target.substr(slash + 1);
  if (file.empty() || file == "." || file == "..") throw fail("not a file name");
  struct stat dst {};
  if (::stat(dir.c_str(), &dst) != 0 || !S_ISDIR(dst.st_mode)) throw fail("folder '" + dir + "' does not exist");
  // A new file gets the mode 0666 less the umask (the kernel applies it at O_CREAT); a replaced file keeps its
  // mode. The name: the target's (at most 200 bytes of it), the process, a counter and the clock.
  static std::atomic<unsigned long> counter{0};
  const std::string stem = (slash == std::string::npos ? std::string() : dir + "/") + "." + file.substr(0, 200) +
                           ".tmp." + std::to_string(::getpid()) + ".";
  std::string tmp;
  Fd f;
  for (int attempt = 0; f.fd < 0; ++attempt) {
    const auto tick = static_cast<unsigned long>(std::chrono::steady_clock::now().time_since_epoch().count());
    tmp = stem + std::to_string(counter.fetch_add(1)) + "." + std::to_string(tick % 1000000007UL);
    f.fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY, 0666);
    if (f.fd < 0 && (errno != EEXIST || attempt >= 100)) throw fail(reason(errno));
  }
  TemporaryPath guard(tmp);
  if (exists && ::fchmod(f.fd, st.st_mode & 07777) != 0) throw fail(reason(errno));
  if (const int e = write_all(f.fd, content)) throw fail(reason(e));
  if (::fsync(f.fd) != 0 && errno != EINVAL && errno != EROFS) throw fail(reason(errno));
  if (f.close() != 0) throw fail(reason(errno));
  if (::rename(tmp.c_str(), target.c_str()) != 0) throw fail(reason(errno));
  guard.release();
  // The rename itself reaches the disk with the folder (best effort: not every file system allows it).
  Fd d(::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (d.fd >= 0) ::fsync(d.fd);
}

/// The content of the regular file `path`, at most max_bytes long (see the top of the file). `what` names
/// the file in messages ("the checkpoint file" gives "cannot read the checkpoint file 'x': ..."). Throws
/// Error (nystrom::invalid_input by default) constructed from the one-line message.
template <class Error = invalid_input>
std::string read_input_file(const std::string& path, const std::string& what,
                            std::size_t max_bytes = max_input_file_bytes) {
  using namespace file_detail;
  const std::string name = "cannot read " + what + " '" + path + "'";
  auto fail = [&](const std::string& why) { return Error(name + ": " + why); };
  if (path.empty()) throw Error("cannot read " + what + ": empty file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw fail(reason(errno));
  if (!S_ISREG(st.st_mode)) throw fail(kind_of(st.st_mode));
  const std::string too_large = "it is larger than " + size_text(max_bytes);
  if (static_cast<unsigned long long>(st.st_size) > max_bytes) throw fail(too_large);
  // O_NONBLOCK: should the path have become a FIFO since, the open does not wait for a writer.
  Fd f(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY));
  if (f.fd < 0) throw fail(reason(errno));
  if (::fstat(f.fd, &st) != 0) throw fail(reason(errno));
  if (!S_ISREG(st.st_mode)) throw fail(kind_of(st.st_mode));
  std::string out;
  out.resize(std::min<std::size_t>(static_cast<std::size_t>(st.st_size), max_bytes) + 1);
  std::size_t got = 0;
  for (;;) {
    if (got == out.size()) {
      if (out.size() > max_bytes) throw fail(too_large);  // it grew while being read
      out.resize(std::min(max_bytes + 1, out.size() * 2 + 4096));
    }
    const ssize_t n = ::read(f.fd, out.data() + got, out.size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw fail(reason(errno));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  if (got > max_bytes) throw fail(too_large);
  out.resize(got);
  return out;
}

}  // namespace nystrom
