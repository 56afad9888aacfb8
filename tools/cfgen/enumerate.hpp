#pragma once
// Level-by-level enumeration of the valid contact formations of a model pair, and the
// transitions between them (SPEC section 4).

#include "explore.hpp"
#include "progress.hpp"
#include "witness.hpp"

#include <cf/graph.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace cf::gen {

/// A slice of the first level-2 search: candidate i belongs to shard i % count. count == 0:
/// no sharding.
struct ShardSpec {
  int index = 0;
  int count = 0;
};

/// One unit of a run's work, a pure function of the models, the search parameters and its
/// inputs: the same task gives the same result in any process, on any thread.
struct Task {
  enum class Kind : std::uint8_t {
    kFind,          // WitnessSearch::find(pcs, seeds)
    kFindOrRefine,  // find(pcs, {pose.R_BA}), else refine(pcs, pose): a set met by motion
    kExplore,       // the motions from the witness `pose` of the CF `pcs` (explore.hpp)
    kFindNear,      // find(pcs, seeds, seeds_only): a failed set near its neighbours' witnesses
  };
  Kind kind = Kind::kFind;
  PcSet pcs;
  std::vector<Mat3> seeds;  // kFind, kFindNear
  Pose pose;                // kFindOrRefine, kExplore
};

struct TaskResult {
  Witness witness;              // kFind, kFindOrRefine
  std::vector<Discovery> met;   // kExplore: the contact sets met, in a fixed order
};

TaskResult run_task(const WitnessSearch& search, const Task& task);

/// Runs tasks on `threads` threads (0: all cores); results by index, whatever the thread
/// count. tick(done), when set, is called now and then from one thread.
std::vector<TaskResult> run_tasks(const WitnessSearch& search, const std::vector<Task>& tasks, int threads,
                                  const std::function<void(std::size_t)>& tick = {});

/// A run is a sequence of stages (a level's candidates, a motion round's explorations, the
/// sets they met), numbered from 0 in the order every run with the same models and options
/// takes; each stage's tasks are cut into chunks that depend only on their number.
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

/// Hands a stage's chunks to other processes (an MPI run). Called with every chunk of the
/// stage and the indices of those still to do; compute(k) returns the results of chunk k
/// computed here (callable from any one thread), done(k, r) takes the results of chunk k
/// (computed here or elsewhere; call it from the calling thread). Returns when every chunk
/// in `todo` is done.
using Distribute = std::function<void(const std::vector<std::vector<Task>>& chunks, const std::vector<std::size_t>& todo,
                                      const std::function<std::vector<TaskResult>(std::size_t)>& compute,
                                      const std::function<void(std::size_t, std::vector<TaskResult>&&)>& done)>;

struct EnumerateOptions {
  SearchParams search;
  int threads = 0;       // 0: all hardware threads
  int max_pcs = 3;       // 1..3
  /// Search one set of each orbit of the models' symmetries (symmetry.hpp) and take the others
  /// as images of its witness; false searches every set.
  bool use_symmetry = true;
  /// With use_symmetry false: once every set has been searched, add every image of each CF
  /// found under the models' symmetries, verified at the image of its witness (cfgen
  /// --thorough), so that the graph is closed under them.
  bool close_orbits = false;
  /// With shard.count > 0, enumerate() searches only this shard's candidates of the first
  /// level-2 round and returns them in Enumeration::shard_results; nothing else is built.
  ShardSpec shard;
  /// The first level-2 round's results gathered from every shard, one per candidate in
  /// candidate order: used instead of searching (cfgen merge). The rest of the run is the
  /// same, so the graph equals an unsharded run's.
  const std::vector<Witness>* first_pairs = nullptr;
  /// Empty, or where every stage's finished chunks are kept and found again.
  ChunkStore checkpoint;
  /// Empty, or how chunks are shared with other processes.
  Distribute distribute;
  /// Called now and then while a stage runs, and once when it ends (ProgressEvent::finished);
  /// from one thread at a time. Empty to stay quiet.
  std::function<void(const ProgressEvent&)> progress;
};

struct LevelStats {
  std::size_t candidates = 0;  // sets that reached the witness search
  std::size_t valid = 0;
  double seconds = 0;
  std::size_t by_motion = 0;   // of the valid ones, found by the closure by motion
  std::size_t by_symmetry = 0;  // of the valid ones, images of another's witness
  std::size_t by_neighbours = 0;  // of the valid ones, found near their neighbours' witnesses
};

struct Enumeration {
  std::vector<CfRecord> cfs;          // canonical order: by number of PCs, then PC set
  std::vector<Transition> transitions;
  LevelStats levels[3];
  double min_clearance = 0;           // mm, smallest witness clearance in the graph
  double min_margin = 0;              // mm, smallest LP margin of a witness's contacts
  std::size_t symmetries_a = 1, symmetries_b = 1;  // the models' symmetries, identity included
  std::vector<PcSet> undecided;       // failed candidates with no proof of invalidity
  // Sharded runs only (EnumerateOptions::shard): the number of candidates of the first
  // level-2 round, and this shard's results by candidate index.
  std::size_t first_pair_candidates = 0;
  std::vector<std::pair<std::size_t, Witness>> shard_results;
};

Enumeration enumerate(const ModelInfo& A, const ModelInfo& B, const EnumerateOptions& options);

/// Transitions (gain, lose, change) between the given CFs.
std::vector<Transition> transitions_between(const std::vector<CfRecord>& cfs, const Polyhedron& A,
                                            const Polyhedron& B, int threads = 1);

}  // namespace cf::gen
