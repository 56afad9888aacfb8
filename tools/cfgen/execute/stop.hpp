#pragma once
/// @file
/// Stopping a run on request (docs/generator.md, "Stopping a run"): a flag read between
/// tasks, set by SIGINT or SIGTERM (cfgen), or by any other thread (the Python binding).

#include <cf/types.hpp>

#include <atomic>

namespace cf::gen {

/// A request to stop, set from a signal handler or another thread.
using StopFlag = std::atomic<bool>;

/// Thrown where a run stops because its StopFlag was set: the chunks finished before it are
/// kept when the run keeps a checkpoint; nothing else is written.
struct Stopped : Error {
  using Error::Error;
};

/// The flag that stop_on_signals() sets.
StopFlag& signal_stop_flag();

/// From now on, the first SIGINT or SIGTERM sets signal_stop_flag() and records the signal;
/// a second signal of either ends the process as if no handler were installed. A signal the process
/// ignores already (a background job of a non-interactive shell ignores SIGINT) stays ignored.
void stop_on_signals();

/// The signal that set signal_stop_flag(), or 0.
int stop_signal();

}  // namespace cf::gen
