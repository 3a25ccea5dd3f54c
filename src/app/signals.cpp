#include "app/signals.hpp"

#include <unistd.h>

#include <csignal>

namespace rktsph {

namespace {

volatile std::sig_atomic_t g_stop = 0;

extern "C" void on_stop_signal(int signal_number) {
  if (g_stop != 0) _exit(128 + signal_number);  // the second signal: stop now (async-signal-safe)
  g_stop = signal_number;
}

}  // namespace

void install_stop_handlers() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A file-size limit (ulimit -f) must fail the write with EFBIG, reported like a full disk,
  // not kill the program without a word.
  std::signal(SIGXFSZ, SIG_IGN);
}

int stop_signal() { return static_cast<int>(g_stop); }

}  // namespace rktsph
