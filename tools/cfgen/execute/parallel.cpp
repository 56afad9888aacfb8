#include "cfgen/execute/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

namespace cf::gen {

int resolve_threads(int threads) {
  return threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

bool parallel_for(std::size_t n, int threads, const std::function<void(std::size_t)>& fn,
                  const std::function<void(std::size_t)>& tick, const StopFlag* stop) {
  std::atomic<std::size_t> next{0}, done{0};
  auto work = [&] {
    for (std::size_t i; !(stop && stop->load(std::memory_order_relaxed)) && (i = next++) < n;) {
      fn(i);
      ++done;
    }
  };
  std::vector<std::thread> pool;
  for (int k = 1; k < threads; ++k) pool.emplace_back(work);
  // The reporter ticks every 250 ms and is woken at the end, so a short loop costs no wait.
  std::thread reporter;
  std::mutex m;
  std::condition_variable cv;
  bool finished = false;
  if (tick)
    reporter = std::thread([&] {
      std::unique_lock<std::mutex> lock(m);
      while (!cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return finished; })) {
        lock.unlock();
        tick(done.load());
        lock.lock();
      }
    });
  work();
  for (auto& t : pool) t.join();
  {
    std::lock_guard<std::mutex> lock(m);
    finished = true;
  }
  cv.notify_one();
  if (reporter.joinable()) reporter.join();
  return done.load() == n;
}

}  // namespace cf::gen
