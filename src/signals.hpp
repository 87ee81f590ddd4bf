// SIGINT, SIGTERM and SIGHUP end the tool cleanly: the handler terminates the child process (gnuplot), removes
// the temporary files and folders registered with nystrom::TemporaryPath (core/files.hpp), prints
// "nystrom: error: interrupted" and ends the process with the signal's default status (130, 143).
#pragma once

#include <sys/types.h>

namespace nystrom::cli {

/// Installs the handler for SIGINT, SIGTERM and SIGHUP (an ignored SIGHUP, as under nohup, stays ignored).
void install_signal_handlers();

/// The child process that the signal handler terminates too (gnuplot); 0: none.
void set_signal_child(pid_t pid);

}  // namespace nystrom::cli
