// The tool's result files (CSV, JSON, PNG, ...), written with the library's atomic writer (core/files.hpp).
#pragma once

#include <string>

#include "nystrom/core/files.hpp"

namespace nystrom::cli {

/// Writes a result file `content` to `path` with the library's writer (nystrom::write_file_atomic,
/// core/files.hpp). A regular file (or a new path) is replaced atomically: a unique temporary file in the
/// same folder, fsync, then rename; a symbolic link is followed and its target replaced in the target's
/// folder; anything else (FIFO, device, /dev/stdout, a path under /dev or /proc) is written in place.
/// Refuses an empty path and a folder; errors carry the system's reason. (Checkpoints are stricter:
/// write_checkpoint_text refuses links and anything but a regular file.)
inline void write_file_atomic(const std::string& path, const std::string& content) {
  nystrom::write_file_atomic(path, content, {.streams = true, .follow_links = true});
}

}  // namespace nystrom::cli
