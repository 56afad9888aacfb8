#include "cfgen/execute/stop.hpp"

#include <csignal>

namespace cf::gen {
namespace {

StopFlag g_stop{false};
volatile std::sig_atomic_t g_signal = 0;
// The signals stop_on_signals() handles (set before the handlers are installed).
volatile std::sig_atomic_t g_handled[2] = {0, 0};
constexpr int kSignals[2] = {SIGINT, SIGTERM};

extern "C" void on_stop_signal(int sig) {
  // Async-signal-safe: a lock-free atomic store, sig_atomic_t, and signal().
  if (g_signal == 0) g_signal = sig;
  g_stop.store(true);
  // The handlers run once: a second Ctrl-C, or a SIGTERM after it, ends the process at once.
  for (int k = 0; k < 2; ++k)
    if (g_handled[k]) std::signal(kSignals[k], SIG_DFL);
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
  // Interrupted system calls (a checkpoint's write in progress) resume: the stop is taken
  // between tasks, not as a failed write.
  sa.sa_flags = SA_RESTART;
  for (int k = 0; k < 2; ++k) {
    // A signal ignored from the start stays ignored: a job started in the background by a
    // non-interactive shell is not meant to stop on Ctrl-C.
    struct sigaction old {};
    if (sigaction(kSignals[k], nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    g_handled[k] = 1;
    sigaction(kSignals[k], &sa, nullptr);
  }
}

}  // namespace cf::gen
