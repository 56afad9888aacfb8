#pragma once
/// @file
/// The execute layer's StageRunner (docs/generator.md, "Layers"): runs each stage's tasks
/// on threads, cut into chunks that are kept in a checkpoint and found again, or handed to
/// other processes (MPI), with progress and a stop flag. Nothing here knows what a task
/// means: tasks go to a Decide function, a WitnessSearch in a run, a stand-in in tests.

#include "cfgen/decide/task.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/enumerate/stage.hpp"
#include "cfgen/execute/stop.hpp"

#include <cstddef>
#include <functional>
#include <vector>

namespace cf::gen {

/// Each stage's tasks are cut into chunks that depend only on the stage's size: about 64 a
/// stage, 8 to 1024 tasks each.
std::size_t chunk_size(std::size_t tasks);

/// Where finished chunks are kept and found again (cfgen --checkpoint). load: true and `out`
/// filled when chunk `chunk` of stage `stage` was kept (it must have been made from these
/// tasks, else it throws); save: keeps a finished chunk.
struct ChunkStore {
  std::function<bool(std::size_t stage, std::size_t chunk, const std::vector<Task>& tasks,
                     std::vector<TaskResult>& out)>
      load;
  std::function<void(std::size_t stage, std::size_t chunk, const std::vector<Task>& tasks,
                     const std::vector<TaskResult>& results)>
      save;
};

/// A store that finds chunks in `first`, else in `second`, and keeps them in both (an MPI
/// run's checkpoint directory and its messages); either may be empty.
ChunkStore either(ChunkStore first, ChunkStore second);

/// One of K processes that share a run through a checkpoint directory they all see
/// (cfgen --shard i/K --checkpoint DIR) or messages (the ranks of an MPI run): chunk k of
/// stage s is this process's when (k + s) mod count == index (s: Stage::owner_key when set);
/// the others' are read from the checkpoint as they appear. A
/// chunk that does not appear within the patience (three times the slowest chunk computed
/// here on one thread, at least ExecuteOptions::shard_patience) is computed here, and its
/// shard is taken as gone (its chunks computed here without waiting) until a chunk of its
/// appears: a chunk's results do not depend on who computes them, so a shard that is slow,
/// gone or never started costs time, not the graph. count == 0: not sharded.
struct ShardSpec {
  int index = 0;
  int count = 0;
};

struct ExecuteOptions {
  int threads = 0;  ///< worker threads; 0: all hardware threads
  /// With count > 0 (and a checkpoint): compute only this shard's chunks of every stage and
  /// wait for the other shards' chunks in the checkpoint.
  ShardSpec shard;
  /// s: the least a shard waits for another's chunk before computing it itself.
  double shard_patience = 10;
  /// s: the longest wait between looks for the other shards' chunks (the first looks come
  /// every 0.1 ms, then less and less often up to this).
  double shard_poll = 0.005;
  /// Empty, or where every stage's finished chunks are kept and found again (with shards:
  /// where they find each other's).
  ChunkStore checkpoint;
  /// Called now and then while a stage runs, and once when it ends (ProgressEvent::finished);
  /// from one thread at a time. Empty to stay quiet.
  std::function<void(const ProgressEvent&)> progress;
  /// Null, or a flag read between tasks: once set, the run throws Stopped after keeping the
  /// chunks it finished.
  const StopFlag* stop = nullptr;
};

/// Answers `tasks` on `threads` threads, results by index whatever the thread count.
/// @throws Stopped when `stop` is set before every task ran.
std::vector<TaskResult> decide_all(const Decide& decide, const std::vector<Task>& tasks,
                                   int threads, const std::function<void(std::size_t)>& tick = {},
                                   const StopFlag* stop = nullptr);

class Executor final : public StageRunner {
 public:
  Executor(Decide decide, ExecuteOptions options);
  void run(const Stage& stage) override;
  void for_each(std::size_t n, const std::function<void(std::size_t)>& fn,
                ProgressEvent* progress = nullptr, Clock::time_point started = {}) override;
  void report(const ProgressEvent& event) override;

  int threads() const { return threads_; }
  /// Stages run so far.
  std::size_t stages() const { return stages_; }
  /// Chunks found in the checkpoint so far (other shards' chunks not counted).
  std::size_t resumed_chunks() const { return resumed_; }
  /// Other shards' chunks taken from the checkpoint, those computed here because their shard
  /// let them wait too long (as if gone), and the seconds spent waiting.
  std::size_t shared_chunks() const { return shared_; }
  std::size_t taken_over_chunks() const { return taken_over_; }
  double waited_seconds() const { return waited_; }

 private:
  // A stage without checkpoint or other processes: slices of tasks made, run and taken in
  // turn, so that a stage of millions of candidates holds only a slice's tasks.
  void run_slices(const Stage& stage);
  // A stage cut into chunks, each found in the checkpoint, computed here or elsewhere, and
  // kept when done.
  void run_chunks(const Stage& stage, std::size_t number);
  std::vector<Task> make_range(const Stage& stage, std::size_t begin, std::size_t end) const;
  // Items [begin, end) of a stage with Stage::compute, on every thread.
  std::vector<TaskResult> compute_range(const Stage& stage, std::size_t begin, std::size_t end,
                                        const std::function<void(std::size_t)>& ticks) const;
  void tick(const Stage& stage, std::size_t done) const;
  // The shard chunk `chunk` of a stage with owner key `key` belongs to, and whether it is this.
  std::size_t owner(std::size_t key, std::size_t chunk) const;
  bool mine(std::size_t key, std::size_t chunk) const;
  // The other shards' chunks `outstanding` of the window at w0 of stage `number`: read into
  // res as they appear in the checkpoint (then arrived(j)), or, when their shard is gone or
  // lets them wait past the patience, computed here (compute_here(j)).
  void take_theirs(std::size_t number, std::size_t key, std::size_t w0,
                   const std::vector<std::vector<Task>>& chunks,
                   std::vector<std::size_t> outstanding, std::vector<std::vector<TaskResult>>& res,
                   const std::function<void(std::size_t)>& compute_here,
                   const std::function<void(std::size_t)>& arrived);
  // s: how long to wait for another shard's chunk before computing it here.
  double patience() const;
  void throw_if_stopped() const;

  Decide decide_;
  ExecuteOptions opt_;
  int threads_;
  std::size_t stages_ = 0;
  std::size_t resumed_ = 0;
  std::size_t shared_ = 0;
  std::size_t taken_over_ = 0;
  double waited_ = 0;         // s
  double slowest_chunk_ = 0;  // s, of the chunks computed here
  std::vector<char> gone_;    // per shard: taken as gone until a chunk of its appears
};

/// The CFs of A against B and their transitions: a WitnessSearch with `search`, its tasks
/// answered by an Executor with `exec`, the sets chosen by enumerate() with `opt`.
/// @throws as enumerate() does.
Enumeration enumerate_pair(const ModelInfo& A, const ModelInfo& B, const SearchParams& search,
                           const EnumerateOptions& opt, const ExecuteOptions& exec = {});

}  // namespace cf::gen
