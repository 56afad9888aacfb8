#include "cfgen/execute/stop.hpp"

#include <csignal>

namespace cf::gen {
namespace {

StopFlag g_stop{false};
volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_stop_signal(int sig) {
  // Async-signal-safe: a lock-free atomic store and a sig_atomic_t.
  g_signal = sig;
  g_stop.store(true);
}

}  // namespace

StopFlag& signal_stop_flag() { return g_stop; }

int stop_signal() { return g_signal; }

void stop_on_signals() {
  static_assert(StopFlag::is_always_lock_free,
                "a signal handler may only store to a lock-free atomic");
  struct sigaction sa {};
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  // The handler runs once: a second Ctrl-C ends the process at once.
  sa.sa_flags = SA_RESETHAND;
  for (const int sig : {SIGINT, SIGTERM}) {
    // A signal ignored from the start stays ignored: a job started in the background by a
    // non-interactive shell, or under nohup, is not meant to stop on it.
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(sig, &sa, nullptr);
  }
}

}  // namespace cf::gen
