#include "cfgen/execute/executor.hpp"

#include "cfgen/execute/parallel.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <utility>

namespace cf::gen {
namespace {

// Tasks a slice holds in a stage without checkpoint or other processes.
constexpr std::size_t kSliceTasks = std::size_t{1} << 15;
// Shards take a window of chunks at a time (their results taken between windows, on this
// thread): every chunk of a window is made at once.
constexpr std::size_t kWindowChunks = 256;

}  // namespace

std::size_t chunk_size(std::size_t tasks) {
  // About 64 chunks a stage: enough to share among processes and to lose little when killed,
  // few enough files; at most 1024 tasks (about a minute of the slowest searches) a chunk.
  constexpr std::size_t kChunks = 64, kMin = 8, kMax = 1024;
  return std::clamp<std::size_t>((tasks + kChunks - 1) / kChunks, kMin, kMax);
}

ChunkStore either(ChunkStore first, ChunkStore second) {
  if (!first.load) return second;
  if (!second.load) return first;
  ChunkStore out;
  out.load = [first, second](std::size_t stage, std::size_t chunk, const std::vector<Task>& tasks,
                             std::vector<TaskResult>& res) {
    return first.load(stage, chunk, tasks, res) || second.load(stage, chunk, tasks, res);
  };
  out.save = [first, second](std::size_t stage, std::size_t chunk, const std::vector<Task>& tasks,
                             const std::vector<TaskResult>& res) {
    first.save(stage, chunk, tasks, res);
    second.save(stage, chunk, tasks, res);
  };
  return out;
}

std::vector<TaskResult> decide_all(const Decide& decide, const std::vector<Task>& tasks,
                                   int threads, const std::function<void(std::size_t)>& tick,
                                   const StopFlag* stop) {
  std::vector<TaskResult> out(tasks.size());
  if (!parallel_for(
          tasks.size(), resolve_threads(threads), [&](std::size_t i) { out[i] = decide(tasks[i]); },
          tick, stop))
    throw Stopped("stopped on request");
  return out;
}

Executor::Executor(Decide decide, ExecuteOptions options)
    : decide_(std::move(decide)),
      opt_(std::move(options)),
      threads_(resolve_threads(opt_.threads)) {
  gone_.assign(static_cast<std::size_t>(std::max(opt_.shard.count, 0)), 0);
  if (opt_.shard.count > 0 && !opt_.checkpoint.load)
    throw Error("a shard (" + std::to_string(opt_.shard.index) + "/" +
                std::to_string(opt_.shard.count) +
                ") needs a checkpoint directory that every shard sees (--checkpoint DIR)");
}

void Executor::throw_if_stopped() const {
  if (opt_.stop && opt_.stop->load()) throw Stopped("stopped on request");
}

void Executor::tick(const Stage& stage, std::size_t done) const {
  if (!stage.progress || !opt_.progress) return;
  stage.progress->done = done;
  stage.progress->seconds = std::chrono::duration<double>(Clock::now() - stage.started).count();
  opt_.progress(*stage.progress);
}

std::vector<Task> Executor::make_range(const Stage& stage, std::size_t begin,
                                       std::size_t end) const {
  std::vector<Task> tasks;
  tasks.reserve(end - begin);
  for (std::size_t i = begin; i < end; ++i) tasks.push_back(stage.make(i));
  return tasks;
}

std::vector<TaskResult> Executor::compute_range(
    const Stage& stage, std::size_t begin, std::size_t end,
    const std::function<void(std::size_t)>& ticks) const {
  std::vector<TaskResult> out(end - begin);
  if (!parallel_for(
          end - begin, threads_, [&](std::size_t i) { out[i] = stage.compute(begin + i); }, ticks,
          opt_.stop))
    throw Stopped("stopped on request");
  return out;
}

void Executor::run(const Stage& stage) {
  const std::size_t number = stages_++;
  throw_if_stopped();
  // The enumeration's own work is shared between shards, not worth keeping in a checkpoint
  // of one process.
  const bool shared =
      stage.compute ? opt_.shard.count > 0 : static_cast<bool>(opt_.checkpoint.load);
  if (shared)
    run_chunks(stage, number);
  else
    run_slices(stage);
}

void Executor::run_slices(const Stage& stage) {
  const bool report = stage.progress && opt_.progress;
  // A stage with chunks of its own size is taken a chunk at a time: its results are many.
  const std::size_t slice = stage.chunk ? stage.chunk : kSliceTasks;
  for (std::size_t b = 0; b < stage.size; b += slice) {
    const std::size_t e = std::min(stage.size, b + slice);
    std::function<void(std::size_t)> ticks;
    if (report) ticks = [&, b](std::size_t d) { tick(stage, b + d); };
    std::vector<TaskResult> r =
        stage.compute ? compute_range(stage, b, e, ticks)
                      : decide_all(decide_, make_range(stage, b, e), threads_, ticks, opt_.stop);
    for (std::size_t i = 0; i < r.size(); ++i) stage.take(b + i, std::move(r[i]));
  }
}

void Executor::run_chunks(const Stage& stage, std::size_t number) {
  const std::size_t n = stage.size, size = stage.chunk ? stage.chunk : chunk_size(n),
                    count = (n + size - 1) / size;
  const std::size_t key = stage.owner_key.value_or(number);
  const bool report = stage.progress && opt_.progress;
  std::size_t done = 0;  // tasks finished, for the progress
  // Chunks shared with other shards go a window at a time.
  const std::size_t window = opt_.shard.count > 0 ? kWindowChunks : 1;
  for (std::size_t w0 = 0; w0 < count; w0 += window) {
    const std::size_t w1 = std::min(count, w0 + window);
    std::vector<std::vector<Task>> chunks;
    for (std::size_t k = w0; k < w1; ++k)
      chunks.push_back(make_range(stage, k * size, std::min(n, (k + 1) * size)));
    // Chunk j of the window computed here: tasks decided, or the enumeration's items.
    auto compute = [&](std::size_t j, const std::function<void(std::size_t)>& ticks) {
      const std::size_t b = (w0 + j) * size;
      return stage.compute ? compute_range(stage, b, b + chunks[j].size(), ticks)
                           : decide_all(decide_, chunks[j], threads_, ticks, opt_.stop);
    };
    std::vector<std::vector<TaskResult>> res(chunks.size());
    std::vector<std::size_t> todo;  // within the window
    for (std::size_t j = 0; j < chunks.size(); ++j) {
      if (opt_.checkpoint.load && opt_.checkpoint.load(number, w0 + j, chunks[j], res[j])) {
        done += chunks[j].size();
        ++(mine(key, w0 + j) ? resumed_ : shared_);
      } else {
        todo.push_back(j);
      }
    }
    // A resumed run's progress counts the chunks found as done.
    if (todo.size() < chunks.size()) tick(stage, done);
    auto finish = [&](std::size_t j, std::vector<TaskResult>&& r) {
      if (r.size() != chunks[j].size())
        throw Error("stage " + std::to_string(number) + ", chunk " + std::to_string(w0 + j) + ": " +
                    std::to_string(r.size()) + " results for " + std::to_string(chunks[j].size()) +
                    " tasks");
      if (opt_.checkpoint.save) opt_.checkpoint.save(number, w0 + j, chunks[j], r);
      res[j] = std::move(r);
      done += chunks[j].size();
      tick(stage, done);
    };
    // Another shard's chunks come from the checkpoint, once this shard's own are done.
    std::vector<std::size_t> theirs;
    if (opt_.shard.count > 0) {
      std::vector<std::size_t> own;
      for (std::size_t j : todo) (mine(key, w0 + j) ? own : theirs).push_back(j);
      todo.swap(own);
    }
    for (std::size_t j : todo) {
      std::function<void(std::size_t)> ticks;
      if (report) ticks = [&](std::size_t d) { tick(stage, done + d); };
      const auto c0 = Clock::now();
      finish(j, compute(j, ticks));
      slowest_chunk_ =
          std::max(slowest_chunk_, std::chrono::duration<double>(Clock::now() - c0).count());
    }
    if (!theirs.empty())
      take_theirs(
          number, key, w0, chunks, theirs, res, [&](std::size_t j) { finish(j, compute(j, {})); },
          [&](std::size_t j) {
            done += chunks[j].size();
            tick(stage, done);
          });
    for (std::size_t j = 0; j < chunks.size(); ++j)
      for (std::size_t i = 0; i < res[j].size(); ++i)
        stage.take((w0 + j) * size + i, std::move(res[j][i]));
  }
}

std::size_t Executor::owner(std::size_t key, std::size_t chunk) const {
  // Shifted by the key (the stage's number unless it pins its chunks), so that the many
  // stages of a chunk or two spread over the shards.
  return (chunk + key) % static_cast<std::size_t>(opt_.shard.count);
}

bool Executor::mine(std::size_t key, std::size_t chunk) const {
  return opt_.shard.count == 0 || owner(key, chunk) == static_cast<std::size_t>(opt_.shard.index);
}

void Executor::take_theirs(std::size_t number, std::size_t key, std::size_t w0,
                           const std::vector<std::vector<Task>>& chunks,
                           std::vector<std::size_t> outstanding,
                           std::vector<std::vector<TaskResult>>& res,
                           const std::function<void(std::size_t)>& compute_here,
                           const std::function<void(std::size_t)>& arrived) {
  // Polled together against one deadline: a chunk takes milliseconds to seconds, and a run
  // has hundreds of stages, each waited for, so the looks come every 0.1 ms at first, then
  // less and less often up to ExecuteOptions::shard_poll (each a stat of one file a chunk,
  // or a probe for messages).
  const auto t0 = Clock::now();
  const double deadline = patience();
  for (int k = 0; !outstanding.empty(); ++k) {
    std::vector<std::size_t> still;
    for (std::size_t j : outstanding) {
      const std::size_t who = owner(key, w0 + j);
      if (opt_.checkpoint.load(number, w0 + j, chunks[j], res[j])) {
        gone_[who] = 0;  // it is back
        ++shared_;
        arrived(j);
      } else if (gone_[who]) {
        ++taken_over_;
        compute_here(j);
      } else {
        still.push_back(j);
      }
    }
    outstanding.swap(still);
    if (outstanding.empty()) break;
    throw_if_stopped();
    if (std::chrono::duration<double>(Clock::now() - t0).count() >= deadline) {
      // Their shards are taken as gone until a chunk of theirs appears: the next pass
      // computes these chunks, and later stages compute their chunks without waiting.
      for (std::size_t j : outstanding) gone_[owner(key, w0 + j)] = 1;
      continue;
    }
    const double wait = std::min(opt_.shard_poll, 1e-4 * (1 << std::min(k, 20)));  // s
    std::this_thread::sleep_for(std::chrono::duration<double>(wait));
  }
  waited_ += std::chrono::duration<double>(Clock::now() - t0).count();
}

double Executor::patience() const {
  // Long enough for a chunk that takes three times this shard's slowest on one thread (the
  // other shards may have fewer threads than this one).
  return std::max(opt_.shard_patience, 3 * slowest_chunk_ * threads_);
}

void Executor::for_each(std::size_t n, const std::function<void(std::size_t)>& fn,
                        ProgressEvent* progress, Clock::time_point started) {
  std::function<void(std::size_t)> ticks;
  if (progress && opt_.progress) {
    Stage s;
    s.progress = progress;
    s.started = started;
    ticks = [this, s](std::size_t d) { tick(s, d); };
  }
  if (!parallel_for(n, threads_, fn, ticks, opt_.stop)) throw Stopped("stopped on request");
}

void Executor::report(const ProgressEvent& event) {
  if (opt_.progress) opt_.progress(event);
}

Enumeration enumerate_pair(const ModelInfo& A, const ModelInfo& B, const SearchParams& search,
                           const EnumerateOptions& opt, const ExecuteOptions& exec) {
  const WitnessSearch ws(A, B, search);
  Executor executor([&ws](const Task& t) { return decide(ws, t); }, exec);
  return enumerate(ws, opt, executor);
}

}  // namespace cf::gen
