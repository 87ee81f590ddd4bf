#include "signals.hpp"

#include <signal.h>
#include <unistd.h>

#include <csignal>

#include "nystrom/core/files.hpp"

namespace nystrom::cli {

// The handler may only call async-signal-safe functions: the temporary paths are those registered with
// nystrom::TemporaryPath (fixed buffers, core/files.hpp).

namespace {

volatile pid_t g_child = 0;

void on_signal(int sig) {
  if (g_child > 0) ::kill(g_child, SIGTERM);
  nystrom::remove_temporary_paths();
  static const char msg[] = "\nnystrom: error: interrupted\n";
  [[maybe_unused]] const auto n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

}  // namespace

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    ::sigaction(sig, nullptr, &old);
    if (old.sa_handler != SIG_IGN) ::sigaction(sig, &sa, nullptr);  // keep an ignored SIGHUP (nohup) ignored
  }
}

void set_signal_child(pid_t pid) { g_child = pid; }

}  // namespace nystrom::cli
