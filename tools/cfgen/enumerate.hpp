#pragma once
// Level-by-level enumeration of the valid contact formations of a model pair, and the
// transitions between them (SPEC section 4).

#include "progress.hpp"
#include "witness.hpp"

#include <cf/graph.hpp>

#include <functional>
#include <string>
#include <vector>

namespace cf::gen {

/// A slice of the first level-2 search, the bulk of a run: candidate i belongs to shard
/// i % count. count == 0: no sharding.
struct ShardSpec {
  int index = 0;
  int count = 0;
  /// When set, the shards to search are handed out one at a time (-1: no more) instead of
  /// `index` alone: the processes of an MPI run share them dynamically.
  std::function<int()> next;
};

/// Keeps the first level-2 round's results in chunks as they are finished, so that a killed
/// run resumes (cfgen --checkpoint). load: true and `out` filled when chunk [begin, end) was
/// kept; save: keeps a finished chunk. Chunks do not depend on the thread count.
struct ChunkStore {
  std::size_t chunk_size = 2048;
  std::function<bool(std::size_t chunk, std::size_t begin, std::size_t end, std::vector<Witness>& out)> load;
  std::function<void(std::size_t chunk, std::size_t begin, std::size_t end, const std::vector<Witness>& results)> save;
};

struct EnumerateOptions {
  SearchParams search;
  int threads = 0;       // 0: all hardware threads
  int max_pcs = 3;       // 1..3
  /// With shard.count > 0, enumerate() searches only this shard's candidates of the first
  /// level-2 round and returns them in Enumeration::shard_results; nothing else is built.
  ShardSpec shard;
  /// The first level-2 round's results gathered from every shard, one per candidate in
  /// candidate order: used instead of searching (cfgen merge). The rest of the run is the
  /// same, so the graph equals an unsharded run's.
  const std::vector<Witness>* first_pairs = nullptr;
  /// Empty, or where the first level-2 round's finished chunks are kept and found again.
  ChunkStore checkpoint;
  /// Called now and then while a stage runs, and once when it ends (ProgressEvent::finished);
  /// from one thread at a time. Empty to stay quiet.
  std::function<void(const ProgressEvent&)> progress;
};

struct LevelStats {
  std::size_t candidates = 0;  // sets that reached the witness search
  std::size_t valid = 0;
  double seconds = 0;
  std::size_t by_motion = 0;   // of the valid ones, found by the closure by motion
};

struct Enumeration {
  std::vector<CfRecord> cfs;          // canonical order: by number of PCs, then PC set
  std::vector<Transition> transitions;
  LevelStats levels[3];
  double min_clearance = 0;           // mm, smallest witness clearance in the graph
  double min_margin = 0;              // mm, smallest LP margin of a witness's contacts
  std::vector<PcSet> undecided;       // failed candidates with no proof of invalidity
  // Sharded runs only (EnumerateOptions::shard): the number of candidates of the first
  // level-2 round, and this shard's results by candidate index.
  std::size_t first_pair_candidates = 0;
  std::vector<std::pair<std::size_t, Witness>> shard_results;
};

Enumeration enumerate(const ModelInfo& A, const ModelInfo& B, const EnumerateOptions& options);

/// Transitions (gain, lose, change) between the given CFs.
std::vector<Transition> transitions_between(const std::vector<CfRecord>& cfs, const Polyhedron& A,
                                            const Polyhedron& B);

}  // namespace cf::gen
