#pragma once
/// @file
/// The decide layer's unit of work: one question about one candidate set (find a witness,
/// refine a pose met by motion, explore motions from a witness), asked of a WitnessSearch.
/// A task is a pure function of the models, the search parameters and its inputs: the same
/// task gives the same result in any process, on any thread (docs/generator.md, "Layers").

#include "cfgen/decide/explore.hpp"
#include "cfgen/decide/witness.hpp"

#include <cstdint>
#include <functional>
#include <vector>

namespace cf::gen {

struct Task {
  enum class Kind : std::uint8_t {
    kFind,          // WitnessSearch::find(pcs, seeds)
    kFindOrRefine,  // find(pcs, {pose.R_BA}), else refine(pcs, pose): a set met by motion
    kExplore,       // the motions from the witness `pose` of the CF `pcs` (explore.hpp)
    kFindNear,      // find(pcs, seeds, seeds_only): a failed set near its neighbours' witnesses
    kVerify,        // image_witness(pcs, pose): an image of a CF at the image of its witness
  };
  Kind kind = Kind::kFind;
  PcSet pcs;
  std::vector<Mat3> seeds;  // kFind, kFindNear
  Pose pose;                // kFindOrRefine, kExplore, kVerify
};

struct TaskResult {
  Witness witness;  // kFind, kFindOrRefine, kFindNear, kVerify (pose and clearance)
  // kExplore: the contact sets met, in a fixed order; kFind without a witness: the larger
  // sets read where the contacts were placed and something else touched (forced contacts)
  std::vector<Discovery> met;
  std::vector<PcSet> sets;  // the enumeration's own items (Stage::compute), not a search's
};

/// Answers one task with `search`.
TaskResult decide(const WitnessSearch& search, const Task& task);

/// How a run answers its tasks: decide() bound to the run's search, or a stand-in (the
/// execute layer's tests). Called from several threads at once.
using Decide = std::function<TaskResult(const Task&)>;

}  // namespace cf::gen
