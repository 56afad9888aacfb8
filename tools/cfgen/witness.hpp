#pragma once
// Witness search for one candidate set of principal contacts: rotations that satisfy the
// rotational conditions of its f-f / e-f / f-e contacts, a linear program for the translation
// with the largest margin inside the touching elements, and a verification of the whole pose.

#include "analysis.hpp"

#include <cf/graph.hpp>

#include <string>
#include <vector>

namespace cf::gen {

struct SearchParams {
  double touch_tol = 1e-9;       // mm: element pairs closer than this touch
  double min_clearance = 1e-2;   // mm: every pair not part of a PC at least this far apart
  double good_clearance = 1.0;   // mm: stop searching once a witness is this clear
  double min_margin = 1e-2;      // mm: contact point at least this far inside its elements
  double angle_margin = 1e-3;    // rad: local non-penetration with this much slack
  int theta_samples = 24;        // samples of a one-parameter rotation family
  int max_rotations = 64;        // rotations tried per candidate
  int max_piece_combinations = 4;
};

/// The outcome of a search: whether a witness was found, and its quality.
struct Witness {
  bool found = false;
  Pose pose;
  double clearance = 0;  // mm, smallest distance between elements not part of a PC
  double margin = 0;     // mm, the LP margin of the contacts inside their elements
};

class WitnessSearch {
 public:
  WitnessSearch(const ModelInfo& a, const ModelInfo& b, const SearchParams& p);

  /// Searches a witness for `pcs`, trying the seed rotations (witnesses of sub-sets) first.
  Witness find(const PcSet& pcs, const std::vector<Mat3>& seeds) const;

  /// Verifies a pose: exactly the PCs of `pcs` hold (every other touching element pair is
  /// dominated by one of them), locally without penetration, pairwise distinct contact
  /// planes, every other pair at least min_clearance apart, neither solid inside the other.
  /// Returns the clearance, or a negative number when the pose is not a witness.
  double verify(const PcSet& pcs, const Pose& pose, std::string* why = nullptr) const;

  /// Cheap necessary conditions on a candidate set (no geometry search).
  bool plausible(const PcSet& pcs) const;

  /// Instantaneous freedoms of the CF at a pose: (dof, translation_dof, pure_rotation).
  void freedoms(const PcSet& pcs, const Pose& pose, CfRecord& out) const;

  /// Contact plane of a PC at a pose (unit normal pointing into A, offset along it).
  std::pair<Vec3, double> contact_plane(const Pc& pc, const Pose& pose) const;

 private:
  // generic_seeds: add each PC's preferred family and a spread of rotations to `seeds`.
  std::vector<Mat3> rotation_candidates(const PcSet& pcs, const std::vector<Mat3>& seeds,
                                        bool generic_seeds = true) const;
  double local_margin(const PcSet& pcs, const Mat3& R) const;
  LinearProgram build_lp(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces) const;
  // Candidate translations for rotation R, best first; empty when the contacts cannot hold
  // with min_margin. `margin` receives the largest margin.
  // near_boundary: instead, extremes that keep only 5% of the margin (a contact that must sit
  // close to its element's boundary, e.g. A in a slot barely wider than itself).
  std::vector<Vec3> translations(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces,
                                 double& margin, bool near_boundary) const;

  const ModelInfo& A_;
  const ModelInfo& B_;
  SearchParams p_;
  double scale_;
  bool debug_;  // CFGEN_DEBUG set: explain every attempt on stderr
};

}  // namespace cf::gen
