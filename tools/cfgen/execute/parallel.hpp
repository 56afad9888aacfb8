#pragma once
/// @file
/// A loop over indices on a fixed number of threads, with progress ticks and a stop flag.

#include "cfgen/execute/stop.hpp"

#include <cstddef>
#include <functional>

namespace cf::gen {

/// `threads` when positive, else the hardware's thread count (at least 1).
int resolve_threads(int threads);

/// Runs fn(i) for i in [0, n) on `threads` threads (at least 1). tick(done), when set, is
/// called about every 250 ms from one thread. With `stop`, no index is started once it is
/// set. fn writes its results by index, so they do not depend on the thread count.
/// @returns true when every index ran (false: stopped first).
bool parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn,
                  const std::function<void(std::size_t)>& tick = {},
                  const StopFlag* stop = nullptr);

}  // namespace cf::gen
