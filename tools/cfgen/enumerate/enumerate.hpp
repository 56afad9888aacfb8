#pragma once
/// @file
/// Which candidate sets to decide (docs/generator.md, "Layers"): the level-by-level
/// enumeration of the valid contact formations of a model pair, the closure by motion, the
/// neighbour rounds and the models' symmetries, and the transitions between the CFs found
/// (docs/spec.md, section 4). The work goes out as stages to a StageRunner (stage.hpp); the
/// sets are decided by the decide layer's WitnessSearch.

#include "cfgen/decide/cell_search.hpp"
#include "cfgen/decide/witness.hpp"
#include "cfgen/enumerate/stage.hpp"

#include <cf/graph.hpp>

#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

namespace cf::gen {

struct EnumerateOptions {
  int max_pcs = 3;  // 1..3
  /// Search one set of each orbit of the models' symmetries (symmetry.hpp) and take the others
  /// as images of its witness; false searches every set.
  bool use_symmetry = true;
  /// With use_symmetry false: once every set has been searched, add every image of each CF
  /// found under the models' symmetries, verified at the image of its witness (cfgen
  /// --thorough), so that the graph is closed under them.
  bool close_orbits = false;
  /// False: stop once the last stage has run, with the levels' statistics only: no proofs of
  /// invalidity, records or transitions (a shard that does not write the graph).
  bool records = true;
  /// Keep each failed set's outcome and evidence (Enumeration::decisions) for the certificate
  /// file (docs/certificates.md).
  bool certificates = false;
  /// Cells of rotation space each orbit of failed sets without an f-f PC may take in the decision
  /// (cfgen --cube-cells); 0: not searched over cells.
  std::size_t cube_cells = 0;
  /// rad, and in units of D in translation: the decision's cells are not split below it
  /// (cfgen --resolution).
  double resolution = kResolution;
};

/// A failed candidate set: how it was decided, and the evidence (docs/certificates.md).
struct SetDecision {
  PcSet pcs;
  bool invalid = false;             // false: undecided
  RuleVerdict rule;                 // invalid by this rule, or (kNone) by `cells`
  std::shared_ptr<CellTree> cells;  // invalid by cells: the complete tree
  /// Invalid by cells: the tolerances the tree was built with, looser than the run's for a set
  /// decided for its images under the pair's symmetries (loosened()).
  CellSearchLimits cell_limits;
  /// Invalid as the image of `image_of` (a set invalid by cells; empty otherwise) under the
  /// pair's symmetry x -> H (x - c_A) + c_A of A and y -> G (y - c_B) + c_B of B.
  PcSet image_of;
  Mat3 H = Mat3::Identity(), G = Mat3::Identity();
  Vec3 c_A = Vec3::Zero(), c_B = Vec3::Zero();  // mm
  /// A THIN set (Enumeration::thin): realised only with a smaller clearance or margin than a
  /// witness has; invalid is false.
  bool thin = false;
  /// A set a rule refuted whose cells found a witness (a rule that failed): kept invalid, as
  /// the graph has it, and reported.
  bool contradicted = false;
};

struct LevelStats {
  std::size_t candidates = 0;  // sets that reached the witness search
  std::size_t valid = 0;
  double seconds = 0;
  std::size_t by_motion = 0;      // of the valid ones, found by the closure by motion
  std::size_t by_symmetry = 0;    // of the valid ones, images of another's witness
  std::size_t by_neighbours = 0;  // of the valid ones, found near their neighbours' witnesses
  std::size_t by_cells = 0;       // of the valid ones, found by the search over cells of poses
};

struct Enumeration {
  std::vector<CfRecord> cfs;  // canonical order: by number of PCs, then PC set
  std::vector<Transition> transitions;
  LevelStats levels[3];
  double min_clearance = 0;                        // mm, smallest witness clearance in the graph
  double min_margin = 0;                           // mm, smallest LP margin of a witness's contacts
  std::size_t symmetries_a = 1, symmetries_b = 1;  // the models' symmetries, identity included
  std::vector<PcSet> undecided;                    // failed candidates with no proof of invalidity
  /// Failed candidates a pose realises exactly, though only with a clearance or margin below
  /// the witnesses' (thin_params), with that pose; canonical order.
  std::vector<std::pair<PcSet, Witness>> thin;
  std::size_t refuted_over_cells = 0;  // failed candidates refuted by search_cells
  /// With EnumerateOptions::certificates: every failed set, in canonical order.
  std::vector<SetDecision> decisions;
};

/// One level of a run as predicted (RunEstimate). Candidates are the sets the level proposes;
/// orbits, of those, the ones searched first (one a orbit); tasks, the searches including
/// an orbit's retries.
struct LevelEstimate {
  double candidates = 0;
  bool exact = false;  ///< candidates (and orbits) counted, not predicted
  double orbits = 0;
  double valid = 0;  ///< CFs the level finds, images included
  double tasks = 0;
  double explored = 0;      ///< witnesses of the level's CFs the closure by motion explores
  double failed_tries = 0;  ///< members of the failed orbits a neighbour round may search
  double cpu_seconds = 0;   ///< s on one thread of this machine
  std::size_t sampled = 0;  ///< sets of the level decided to predict it
};

/// What a run of enumerate() is predicted to find and cost (cfgen --estimate), from its
/// level-1 candidates counted and a few sets of each level decided (docs/generator.md,
/// "Estimates"); the constants that turn samples into a run are measured on the pairs
/// listed in docs/performance.md, where the predictions' errors are.
struct RunEstimate {
  LevelEstimate levels[3];
  double cfs = 0;          ///< CFs in the graph
  double transitions = 0;  ///< transitions in the graph
  double cpu_seconds = 0;  ///< s, the whole run on one thread
  double seconds = 0;      ///< s, the whole run on `threads` threads
  double peak_bytes = 0;   ///< the run's largest resident size
  int threads = 1;
  double sample_seconds = 0;  ///< s the estimate itself took
};

/// Orbits searched per level by `cfgen --estimate`: the fraction valid to about +-9%
/// (binomial at 96); 32 predicted a quarter of the valid pairs of CGAL's cross and U.
constexpr std::size_t kEstimateSamples = 96;
/// Orbits searched per level by a run's own prediction (its default checkpoint and the time
/// left in its progress line), which every run pays for before it starts: a third of
/// --estimate's cost.
constexpr std::size_t kRunPredictionSamples = 32;

/// Predicts a run of enumerate() with `opt` on `threads` threads, without running it: the
/// sets it decides go to `runner`'s threads (for_each), never as stages. samples: orbits
/// searched per level; twice as many CFs are explored by motion.
/// @throws Stopped when the runner was asked to stop.
RunEstimate estimate(const WitnessSearch& search, const EnumerateOptions& opt, StageRunner& runner,
                     int threads, std::size_t samples = kEstimateSamples);

/// The CFs of the pair `search` was made for, and their transitions; every stage of the
/// work goes to `runner`.
/// @throws Stopped when the runner was asked to stop.
Enumeration enumerate(const WitnessSearch& search, const EnumerateOptions& opt,
                      StageRunner& runner);

/// Transitions (gain, lose, change) between the given CFs, computed on the runner's threads.
std::vector<Transition> transitions_between(const std::vector<CfRecord>& cfs, const Polyhedron& A,
                                            const Polyhedron& B, StageRunner& runner);

}  // namespace cf::gen
