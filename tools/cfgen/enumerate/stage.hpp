#pragma once
/// @file
/// How the enumeration hands out its work (docs/generator.md, "Layers"): a run is a sequence
/// of stages, each a list of tasks for the decide layer, numbered from 0 in the order every
/// run with the same models and options takes. The enumeration says which tasks a stage
/// holds and what to do with their results; a StageRunner (the execute layer's Executor)
/// decides where and when they run: threads, chunks, checkpoints, other processes.

#include "cfgen/decide/task.hpp"

#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace cf::gen {

using Clock = std::chrono::steady_clock;

/// One report from a run: a stage under way (finished = false, sent now and then) or a stage
/// that has just ended (finished = true, sent once).
struct ProgressEvent {
  std::string stage;  // "level 2", "motion round 1", ...
  std::string unit;   // what `done` and `total` count: "candidate sets", "CFs"
  std::size_t done = 0;
  std::size_t total = 0;
  double seconds = 0;  // s since the stage began
  bool finished = false;
  std::string result;  // when finished: what the stage found, e.g. "816 valid"
};

/// A stage: `size` tasks, task i made by make(i) and its result handed to take(i, r) in task
/// order on the calling thread. make(i) must not depend on what take has seen in the same
/// stage (a resumed or distributed run makes the tasks again, in any order of chunks).
struct Stage {
  std::size_t size = 0;
  std::function<Task(std::size_t)> make;
  std::function<void(std::size_t, TaskResult&&)> take;
  ProgressEvent* progress = nullptr;  ///< where this stage's progress goes; null: quiet
  Clock::time_point started;          ///< when the step the stage belongs to began
  /// Set for work that is the enumeration's own, not a search (the neighbour rounds'
  /// screening): item i's result is compute(i), called on any thread (distinct items at
  /// once), and make(i) only names the item, for the checkpoint. Like compute, it must not
  /// depend on what take has seen in the same stage. Shared between shards like tasks; run
  /// here on threads otherwise, never kept in a checkpoint or sent to another process.
  std::function<TaskResult(std::size_t)> compute;
  /// Items a chunk; 0: chunk_size(size).
  std::size_t chunk = 0;
  /// Set: chunk k belongs to the same shard in every stage with the same key (a shard keeps
  /// what it learned of its items between rounds); else chunks are dealt out afresh.
  std::optional<std::size_t> owner_key;
};

/// Runs stages. Implemented by the execute layer (cfgen/execute/executor.hpp).
class StageRunner {
 public:
  virtual ~StageRunner() = default;
  /// Runs every task of `stage`; returns once take() has had every result.
  /// @throws Stopped when the run was asked to stop (cfgen/execute/stop.hpp).
  virtual void run(const Stage& stage) = 0;
  /// fn(i) for i in [0, n) on every thread: work between stages that is not a task (pairing
  /// candidates, records). With `progress`, ticks are reported as for a stage.
  virtual void for_each(std::size_t n, const std::function<void(std::size_t)>& fn,
                        ProgressEvent* progress = nullptr, Clock::time_point started = {}) = 0;
  /// Passes a progress event on (a stage's end, reported by the enumeration).
  virtual void report(const ProgressEvent& event) = 0;
};

/// Runs a stage of the given tasks and returns their results by index.
std::vector<TaskResult> run_tasks(StageRunner& runner, const std::vector<Task>& tasks,
                                  ProgressEvent* progress, Clock::time_point started);

}  // namespace cf::gen
