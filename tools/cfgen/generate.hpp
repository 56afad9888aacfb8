#pragma once
/// @file
/// cfgen's graph generation mode (docs/spec.md, section 5b): `cfgen A_MODEL B_MODEL -o GRAPH.json`.
/// main.cpp parses the command line; run_generate does the work: it loads the models, makes
/// the decide layer's WitnessSearch and the execute layer's Executor, runs the enumeration
/// and writes the graph.

#include "cfgen/decide/witness.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/execute/executor.hpp"
#include "cfgen/execute/stop.hpp"
#include "mesh/model_loader.hpp"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace cf::tools {

/// The search's lengths as fractions of D, the smaller model's bounding-box diagonal: the
/// graph of a pair scaled by any factor is the same up to that scale. Defaults give about
/// the SearchParams defaults (in mm) for a 30 mm cube (D = 52 mm).
struct RelativeLengths {
  double touch_tol = 2e-11;  ///< element pairs closer than this touch
  double min_clearance =
      2e-4;  ///< every pair not part of a PC at least this far apart at a witness
  double good_clearance = 2e-2;  ///< a witness this clear ends the search
  double min_margin = 2e-4;      ///< contact points at least this far inside their elements
};

/// Empty when the lengths can hold together, else why not, naming both options (as the
/// command line spells them, or as the Python binding's keywords with `python_names`). A
/// witness is kept only when its clearance reaches min_clearance, and the search reports a
/// clearance of at most good_clearance, so good_clearance below min_clearance refuses every
/// witness: 0 CFs, as a silent consequence of two values each inside its range.
std::string conflicting_lengths(const RelativeLengths& rel, bool python_names = false);

/// The touch tolerance is at least this many times the sum of the models' planarities
/// (model_precision): two faces each planar to p_A and p_B touch along their whole extent at
/// a pose that puts every vertex of each within p_A + p_B of the other's plane, and the pose
/// itself is found only to rounding; twice that sum again is the margin (docs/features.md,
/// "Precision").
constexpr double kTouchPerPrecision = 4;

/// D in mm: the smaller model's bounding-box diagonal, the unit of RelativeLengths.
double length_scale(const Polyhedron& A, const Polyhedron& B);

/// Models read from files rounded coarser than the symmetry tolerance (float32, a few digits)
/// made exactly symmetric where they are symmetric to their rounding (gen::symmetrized), their
/// deviation from the files grown by the corners' moves (docs/features.md, "Precision").
void symmetrize(MeasuredModel& a, MeasuredModel& b);

/// `base` with its lengths set to `rel` times length_scale(A, B), the touch tolerance at
/// least kTouchPerPrecision times the models' planarities summed (model_precision): the
/// search cfgen runs.
gen::SearchParams scaled_search(const Polyhedron& A, const Polyhedron& B,
                                const RelativeLengths& rel, gen::SearchParams base = {});

/// Parsed arguments of `cfgen A_MODEL B_MODEL -o GRAPH.json [options]`.
struct GenerateArgs {
  std::string a_path;    ///< model of A, the moving object
  std::string b_path;    ///< model of B, the fixed object (world frame)
  std::string out_path;  ///< graph file to write, whole or not at all; empty: `graph_out` only
  /// Null, or where the graph is handed over in memory as well (the Python binding):
  /// with an empty out_path nothing is written and no default checkpoint is kept.
  CfGraph* graph_out = nullptr;
  int threads = 0;     ///< worker threads; 0 = hardware concurrency
  bool quiet = false;  ///< no progress on stderr
  int max_pcs = 3;     ///< largest CFs to enumerate (1..3)
  bool thorough =
      false;  ///< search every set, then add every image of each CF found (enumerate.hpp)
  bool symmetry = true;  ///< search one set per orbit of the models' symmetries (symmetry.hpp)
  /// Cells of rotation space each orbit of failed candidates without an f-f PC may take in the
  /// decision (docs/generator.md, "Refuting a set over cells of poses"); 0: such sets are not
  /// searched over cells.
  std::size_t cube_cells = 0;
  /// The decision's resolution: cells are not split below this many rad in rotation nor this
  /// many D in translation; a set left with such a cell open is undecided.
  double resolution = gen::kResolution;
  gen::SearchParams search;    ///< angular tolerances and search limits (lengths: `rel`)
  RelativeLengths rel;         ///< lengths of the search, relative to the models' size
  LoadOptions load_a, load_b;  ///< units and coplanarity tolerance of each model
  /// With shard.count > 0 (checkpoint_dir or share required, a directory on storage every
  /// shard sees): compute this shard's chunks of every stage and take the others' from the
  /// checkpoint or the share; shard 0 writes the graph, the others nothing
  /// (docs/generator.md, "Shards").
  gen::ShardSpec shard;
  /// s: the least a shard waits for another shard's chunk before computing it itself.
  double shard_patience = 10;
  /// Empty, or how the shards share chunks besides a checkpoint (the ranks of an MPI run,
  /// by messages).
  gen::ChunkStore share;
  /// Null, or a flag read between tasks: once set, the run stops, keeps the chunks it
  /// finished when checkpoint_dir is set, writes nothing else and returns 128 + the signal
  /// that set it (cfgen/execute/stop.hpp).
  const gen::StopFlag* stop = nullptr;
  /// Non-empty: keep every stage's finished chunks there and resume from them.
  std::string checkpoint_dir;
  /// Empty checkpoint_dir: false keeps one in GRAPH.json.ckpt/ when the run is predicted to
  /// take over kDefaultCheckpointSeconds (removed once the graph is written); true never.
  bool no_checkpoint = false;
  /// Predict the run (counts per level, time, memory) on stdout instead of running it.
  bool estimate = false;
  /// Non-empty: also write the certificate file there (docs/certificates.md), by the process
  /// that writes the graph, after it.
  std::string certificates_path;
};

/// s: a run predicted to take longer keeps a checkpoint unless told not to.
constexpr double kDefaultCheckpointSeconds = 120;

/// Generates the CF graph of A against B and writes it to args.out_path.
/// @returns the process exit status (0 on success); errors are one line on stderr.
int run_generate(const GenerateArgs& args);

}  // namespace cf::tools
