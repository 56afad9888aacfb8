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
  double clearance = 0;  // mm, smallest distance between elements not part of a PC, <= good_clearance
  double margin = 0;     // mm, the LP margin of the contacts inside their elements
};

/// Whether a PC of `pcs` covers the pair (element a of A, element b of B): each element lies
/// in the closure of that PC's element on its side (a PC covers its own pair). Touching such
/// a pair does not change the contact set.
bool covered_by(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs, ElementKind ka, int a,
                ElementKind kb, int b);

class WitnessSearch {
 public:
  WitnessSearch(const ModelInfo& a, const ModelInfo& b, const SearchParams& p);

  /// Searches a witness for `pcs`, trying the seed rotations (witnesses of sub-sets) first.
  /// With `seeds_only`, a search near given rotations: tries only the seeds and rotations
  /// 0.01 and 0.025 rad about each axis from them (projected onto the PCs' rotational
  /// conditions), then climbs past the obstacles met there.
  Witness find(const PcSet& pcs, const std::vector<Mat3>& seeds, bool seeds_only = false) const;

  /// Verifies a pose: exactly the PCs of `pcs` hold (every other touching element pair is
  /// dominated by one of them), locally without penetration, pairwise distinct contact
  /// planes, every other pair at least min_clearance apart, neither solid inside the other.
  /// Returns the clearance (the smallest distance of such a pair, at most good_clearance: pairs
  /// farther apart are not measured), or a negative number when the pose is not a witness.
  double verify(const PcSet& pcs, const Pose& pose, std::string* why = nullptr) const;

  /// A pair of elements, not part of the contacts, that came too close at a pose verify
  /// refused (set: whether there was one).
  struct Obstacle {
    bool set = false;
    ElementKind ka = ElementKind::kVertex, kb = ElementKind::kVertex;
    int a = -1, b = -1;
  };

  /// True when the obstacle's pair, neither a PC nor covered by one, is still closer than
  /// min_clearance at `pose` (and touching in open points if within touch_tol): then verify
  /// refuses `pose` too. False proves nothing.
  bool still_blocked(const PcSet& pcs, const Pose& pose, const Obstacle& o) const;

  /// The pair of elements a refused pose failed on: an obstacle (as Obstacle), or a PC or a
  /// pair a PC covers where A and B overlap (touching, tangent cones not disjoint).
  struct FailedPair {
    enum class Kind { kNone, kObstacle, kOverlap } kind = Kind::kNone;
    ElementKind ka = ElementKind::kVertex, kb = ElementKind::kVertex;
    int a = -1, b = -1;
    /// The obstacle, when the pose failed on one (else an Obstacle not set).
    Obstacle obstacle() const { return Obstacle{kind == Kind::kObstacle, ka, kb, a, b}; }
  };
  /// verify, also naming the pair the pose failed on, when it failed on one.
  double verify(const PcSet& pcs, const Pose& pose, std::string* why, FailedPair* failed) const;
  /// True when the pair still fails at `pose` as it did where it was recorded: then verify
  /// refuses `pose` too (at that pair or at one listed before it). False proves nothing.
  bool still_fails(const PcSet& pcs, const Pose& pose, const FailedPair& f) const;

  /// The PCs that hold at a pose: every touching pair of open elements (distance within
  /// touch_tol) that no other touching pair dominates. Returns false, with the reason, when
  /// a non-dominated touch is degenerate (v-v, v-e, e-v, parallel e-e) or more than three
  /// PCs hold; `out` is then meaningless. An empty `out` means no contact.
  bool contacts_at(const Pose& pose, PcSet& out, std::string* why = nullptr) const;

  /// A witness for `pcs` near `pose`, a pose where they hold (found by a motion): moved
  /// towards the centre of the translations that keep the contacts, or `pose` itself, when
  /// verified with the contacts at least min_margin inside their elements.
  Witness refine(const PcSet& pcs, const Pose& pose) const;

  /// How far inside their open elements the contacts of `pcs` lie at `pose` (mm): for each
  /// PC the depth of its contact point, of the best of 63 points along its contact edge, or of
  /// the centroid of its contact region, inside both elements; the smallest over the PCs.
  double contact_margin(const PcSet& pcs, const Pose& pose) const;

  /// For a set `find` found no witness for: true when it is proven invalid within the
  /// search's tolerances (a necessary condition fails, or its rotational conditions leave
  /// finitely many rotations and at each the PCs are locally penetrating or cannot be placed
  /// inside their elements). False means undecided: the search gave up without a proof.
  bool refuted(const PcSet& pcs) const;

  /// Cheap necessary conditions on a candidate set (no geometry search).
  bool plausible(const PcSet& pcs) const;

  /// Instantaneous freedoms of the CF at a pose: (dof, translation_dof, pure_rotation).
  void freedoms(const PcSet& pcs, const Pose& pose, CfRecord& out) const;

  /// Contact plane of a PC at a pose (unit normal pointing into A, offset along it).
  std::pair<Vec3, double> contact_plane(const Pc& pc, const Pose& pose) const;

  /// The local non-penetration slack (a sine) a verified pose needs at every contact: half
  /// of sin(angle_margin), the slack the search asks of the rotations it tries.
  double verified_local_slack() const;

  const ModelInfo& a() const { return A_; }
  const ModelInfo& b() const { return B_; }
  const SearchParams& params() const { return p_; }
  double scale() const { return scale_; }

 private:
  // generic_seeds: add each PC's preferred family and a spread of rotations to `seeds`.
  std::vector<Mat3> rotation_candidates(const PcSet& pcs, const std::vector<Mat3>& seeds,
                                        bool generic_seeds = true) const;
  double local_margin(const PcSet& pcs, const Mat3& R) const;
  // Rotations satisfying the PCs' rotational conditions: the seeds projected onto them, and
  // `samples` spins when one face alignment leaves the spin free.
  std::vector<Mat3> family_samples(const PcSet& pcs, const std::vector<Mat3>& seeds, int samples) const;
  // The seeds, each PC's preferred rotations and a fixed spread over SO(3).
  std::vector<Mat3> spread_rotations(const PcSet& pcs, const std::vector<Mat3>& seeds) const;
  // For a set with two point PCs (v-f, f-v, e-e): rotations that place both contacts at
  // sampled points inside their elements, i.e. take the segment between the two points on A
  // onto a segment of the same length between the two points on B, spun about it. Locally
  // penetrating ones dropped, at most max_rotations, spread apart.
  std::vector<Mat3> anchored_rotations(const PcSet& pcs) const;
  // Number of convex pieces of each face slot of the LP (build_lp's `pieces`), in its order.
  std::vector<int> piece_slots(const PcSet& pcs) const;
  // Whether A's and B's tangent cones where element a of A touches element b of B have
  // disjoint interiors (exact for pairs with a face or two edges; vertex-edge and
  // vertex-vertex probe along each cone's inward axis).
  bool cones_disjoint(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b) const;
  // Whether A and B overlap where element a of A touches element b of B, d apart: they
  // touch in open points and their tangent cones there are not disjoint (verify's test for a
  // PC or a pair a PC covers).
  bool overlap_at(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b, double d) const;
  // extra_vars: variables after the program's own, for the caller (no rows use them).
  LinearProgram build_lp(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces,
                         int extra_vars = 0) const;
  // The largest margin of the contacts inside their elements at rotation R, negative (down
  // to -scale) when they cannot be placed: how far R is from placing them. -inf when even
  // that fails (e.g. parallel contact planes).
  double signed_margin(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces) const;
  // Rotations near R that satisfy the PCs' rotational conditions: R turned by +-h about
  // each axis the conditions leave free, projected back onto them.
  std::vector<Mat3> rotation_steps(const PcSet& pcs, const Mat3& R, double h) const;
  // Candidate translations for rotation R, best first; empty when the contacts cannot hold
  // with min_margin. `margin` receives the largest margin.
  // near_boundary: instead, extremes that keep only 5% of the margin (a contact that must sit
  // close to its element's boundary, e.g. A in a slot barely wider than itself).
  // cuts: extra rows on the translation (variables 0..2), e.g. from separating_cut.
  // memo: empty, or the programs of an earlier call for the same set, rotation and pieces
  // without cuts (filled by that call): the largest margin and the extremes that keep half
  // of it, which both passes start from, solved once.
  struct TranslationMemo {
    bool set = false;
    LpResult best;
    std::vector<LpVector> half;
  };
  std::vector<Vec3> translations(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces,
                                 double& margin, bool near_boundary,
                                 const std::vector<LinearProgram::Row>& cuts = {},
                                 TranslationMemo* memo = nullptr) const;
  // A half-space of translations t (a row n.t >= h) in which the obstacle's two elements, A
  // rotated by R, are separated by at least min_clearance: the separating axis (face normals,
  // edge cross products, edge-vertex and vertex-vertex directions of their closures) that
  // needs the smallest move from t. False when no axis separates them.
  bool separating_cut(const Mat3& R, const Vec3& t, const Obstacle& o, LinearProgram::Row& cut) const;
  // The largest s such that, at rotation R, the contacts sit s inside their elements and each
  // obstacle's two elements are s - min_margin farther apart than its separating cuts ask:
  // s >= min_margin places the contacts and clears every obstacle. An obstacle's face that
  // is not convex (a hole, a reflex corner) is cut piece by piece, each convex piece against
  // each of the other element's, along the axis that needs the smallest move from t_axes,
  // never along a contact's normal (an obstacle next to a contact keeps no gap along it).
  // -inf when no translation is feasible even with s negative, or a pair of pieces has no
  // separating axis. `x` receives the program's solution (t, s, the contacts' parameters),
  // `cuts` the cuts at R and `cut_points` the points of A's piece of each (A's frame).
  double obstacle_margin(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces,
                         const std::vector<Obstacle>& obstacles, const Vec3& t_axes, LpVector& x,
                         std::vector<LinearProgram::Row>& cuts,
                         std::vector<std::vector<Vec3>>& cut_points) const;
  // One step of the climb past obstacles: from rotation R with obstacle_margin's solution x,
  // cuts and cut points, the turn (at most `turn` rad about each axis) that the program
  // linearised in the turn says raises that margin most, kept on the rotational conditions.
  // False when the conditions leave no turn or the program fails.
  bool obstacle_step(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces,
                     const LpVector& x, const std::vector<LinearProgram::Row>& cuts,
                     const std::vector<std::vector<Vec3>>& cut_points, double turn,
                     Mat3& next) const;

  const ModelInfo& A_;
  const ModelInfo& B_;
  SearchParams p_;
  double scale_;
  bool debug_;  // CFGEN_DEBUG set: explain every attempt on stderr
};

}  // namespace cf::gen
