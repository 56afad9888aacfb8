#pragma once
// Independent test oracle: reading a CF graph written by cfgen (docs/graph-format.md) and
// re-verifying every witness with the oracle's own geometry.

#include "classify.hpp"

#include <functional>
#include <string>
#include <vector>

namespace oracle {

struct GraphCf {
  int id = 0;
  CfKey key;
  Pose witness;
};

struct Graph {
  std::string path;
  Poly A, B;  // rebuilt from models.A / models.B (vertices, edges, faces only)
  std::vector<GraphCf> cfs;
  /// stats.thin_sets: sets the generator found realised only below its witnesses' margins.
  std::vector<CfKey> thin;
  double min_clearance_mm = 0;  // parameters.min_clearance_mm (0 when absent)
};

/// A PC list as the generator writes it ("f-f:3:5;e-e:6:16"), in its order; non-degenerate
/// types only. Throws std::runtime_error naming the item that is not `type:a:b`.
std::vector<Pc> parse_pc_list(const std::string& text);

/// Throws std::runtime_error naming the file and the problem.
Graph read_graph(const std::string& path);

struct WitnessResult {
  int id = 0;
  CfKey key;
  int verdict = 0;  // 0 sound, 1 marginal (fails only at the nominal tolerance), 2 unsound
  std::string problem;
  double clearance = kInf;
  Pose pose;
};

struct CheckReport {
  int total = 0, sound = 0, marginal = 0, unsound = 0;
  double min_clearance = kInf;
  std::vector<WitnessResult> bad;  // marginal and unsound ones
};

/// Sound: at the witness, with tolerance tol, interiors are disjoint and the PCs that hold
/// (touching, non-dominated, classified) are exactly the CF's PCs. A witness that fails at tol
/// but passes at tol/100 or tol*100 is marginal; one that fails at all three is unsound.
WitnessResult check_witness(const Classifier& nominal, const Classifier& lo, const Classifier& hi,
                            const GraphCf& cf);
/// Every witness of G, or those of the CFs `which` accepts.
CheckReport check_graph(const Graph& G, const Tolerances& tol,
                        const std::function<bool(const GraphCf&)>& which = {});

}  // namespace oracle
