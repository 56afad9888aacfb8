#pragma once
// Independent test oracle: whether cfgen's graph depends on the solids only, not on the files
// that describe them (issue 40's property test; docs/generator.md, "What the search could
// not decide"). The same pair is written twice, the second time with each model moved by its
// own random rigid motion and renumbered (vertex order, facet order, each facet's first
// vertex); cfgen runs on both, and the two graphs' CF sets are compared through the map
// between their elements, found from the geometry alone.

#include "graph.hpp"
#include "shapes.hpp"

#include <cstdint>
#include <random>
#include <string>
#include <vector>

namespace oracle {

/// `m` moved by X and renumbered by a random permutation of its vertices and of its facets,
/// each facet starting at a random one of its vertices (its orientation kept).
Mesh moved_renumbered(const Mesh& m, const Pose& X, std::mt19937_64& rng);

/// The map from the elements of `moved` (a graph model built from the moved files) to those
/// of `first`: vertex i of `moved` is vertex vertex[i] of `first`, and so on. Vertices match
/// when X.inv of one is within `tol` times the diagonal of the other (the features of both
/// are the same solid's: 1e-7 for 17-digit files, more for float32 ones); edges by their two
/// vertices, faces by their vertex sets. Empty `problem` when every element has its image;
/// otherwise what is missing.
struct ElementMap {
  std::vector<int> vertex, edge, face;
  std::string problem;
};
ElementMap map_elements(const Poly& moved, const Poly& first, const Pose& X, double tol = 1e-7);

/// `key` (in the moved graph's numbering) in the first graph's numbering, sorted.
CfKey map_key(const CfKey& key, const ElementMap& a, const ElementMap& b);

struct InvarianceOptions {
  std::string cfgen;                    // path of the cfgen binary
  int threads = 2;                      // cfgen -j
  std::vector<std::string> cfgen_args;  // more options for both runs
  std::uint64_t motion_seed = 1;        // the motions and the renumbering
  /// The moved copy written as binary STL with float32 coordinates (write_stl_float32), as CAD
  /// and mesh tools write a part, instead of 17-digit OFF.
  bool float32_stl = false;
  std::string keep_dir;  // "" = a temporary directory, removed if all worked
};

struct InvarianceResult {
  bool ok = false;  // both runs worked and every element was mapped
  std::string error;
  std::string desc;
  int first_cfs = 0, moved_cfs = 0;
  std::vector<CfKey> only_first, only_moved;  // the first graph's numbering
  /// How many of those have a witness the oracle finds sound (check_witness) in their own
  /// graph: CFs the other run missed.
  int sound_first = 0, sound_moved = 0;
  double first_s = 0, moved_s = 0;  // cfgen's wall time, seconds
  bool same() const { return ok && only_first.empty() && only_moved.empty(); }
};

/// Writes the pair, and its moved and renumbered copy, to the directory, runs cfgen on both
/// and compares the graphs.
InvarianceResult run_invariance(const ShapePair& pair, const InvarianceOptions& o);

}  // namespace oracle
