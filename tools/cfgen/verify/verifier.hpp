#pragma once
/// @file
/// What a witness is (docs/generator.md, "Layers"): the one gate to the graph. A pose is a
/// witness of a set of PCs when exactly those PCs hold there, locally without penetration,
/// on pairwise distinct contact planes, every other pair of elements at least min_clearance
/// apart, and neither solid inside the other. The search (cfgen/decide) proposes poses; only
/// what Verifier::verify accepts enters a graph. Usable on its own by any program that has
/// the two models' analyses (analysis.hpp).

#include "cfgen/verify/analysis.hpp"
#include "cfgen/verify/turn_bound.hpp"

#include <cf/graph.hpp>

#include <string>
#include <utility>

namespace cf::gen {

/// The tolerances of verification, and the limits of the search that uses them.
struct SearchParams {
  double touch_tol = 1e-9;      // mm: element pairs closer than this touch
  double min_clearance = 1e-2;  // mm: every pair not part of a PC at least this far apart
  double good_clearance = 1.0;  // mm: stop searching once a witness is this clear
  double min_margin = 1e-2;     // mm: contact point at least this far inside its elements
  double angle_margin = 1e-3;   // rad: local non-penetration with this much slack
  int theta_samples = 24;       // samples of a one-parameter rotation family
  int max_rotations = 64;       // rotations tried per candidate
  int max_piece_combinations = 4;
};

/// The floor, in touch tolerances, of a THIN pose's clearance and contact margin: above the
/// touch tolerance with room for the rounding of the pose as written, so that the pose
/// realises exactly its PCs, yet far below any margin a witness is asked for.
inline constexpr double kThinFloorTouchTols = 4.0;

/// The tolerances a THIN pose verifies with (docs/generator.md, "Thin sets"): those of `p`
/// with min_clearance and min_margin lowered to kThinFloorTouchTols x touch_tol, and a search
/// that stops at the first pose as clear as `p` asks.
inline SearchParams thin_params(const SearchParams& p) {
  SearchParams t = p;
  t.min_clearance = t.min_margin = kThinFloorTouchTols * p.touch_tol;
  t.good_clearance = p.min_clearance;
  return t;
}

/// Whether a PC of `pcs` covers the pair (element a of A, element b of B): each element lies
/// in the closure of that PC's element on its side (a PC covers its own pair). Touching such
/// a pair does not change the contact set.
bool covered_by(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs, ElementKind ka, int a,
                ElementKind kb, int b);

/// An upper bound, over a set of rotations that turn each vector x of A's frame at most
/// turn(x) from where R turns it, of the PCs' local non-penetration margin
/// (Verifier::local_margin: a sine, negative when a contact is penetrating or degenerate).
/// turn = {} gives the margin at R. which: when given, the index in `pcs` of the PC whose
/// term is smallest (-1 when none is below 1). An e-e's term is the lesser of two bounds
/// (docs/certificates.md, "The local margin") where the turn moves its contact normal's
/// direction far, e.g. near parallel edges; kDirect keeps the first, cheaper one, for a
/// search that only prunes with the bound.
enum class EeBound { kTightest, kDirect };
double local_margin_bound(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs, const Mat3& R,
                          const TurnBound& turn, int* which = nullptr,
                          EeBound ee = EeBound::kTightest);

class Verifier {
 public:
  /// a, b: the analyses of A (moving) and B (fixed); they must outlive the verifier.
  Verifier(const ModelInfo& a, const ModelInfo& b, const SearchParams& p);

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
  /// True when the obstacle's pair touches at `pose` in open points (within touch_tol): a
  /// contact the pose makes besides the PCs it was verified for.
  bool obstacle_touches(const Pose& pose, const Obstacle& o) const;

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

  /// How far inside their open elements the contacts of `pcs` lie at `pose` (mm): for each
  /// PC the depth of its contact point, of the best of 63 points along its contact edge, or of
  /// the centroid of its contact region, inside both elements; the smallest over the PCs.
  double contact_margin(const PcSet& pcs, const Pose& pose) const;

  /// Instantaneous freedoms of the CF at a pose: (dof, translation_dof, pure_rotation).
  void freedoms(const PcSet& pcs, const Pose& pose, CfRecord& out) const;

  /// Contact plane of a PC at a pose (unit normal pointing into A, offset along it).
  std::pair<Vec3, double> contact_plane(const Pc& pc, const Pose& pose) const;

  /// The local non-penetration margin of the PCs at rotation R (a sine: the smallest over
  /// the PCs of how far each contact's tangent cones are from meeting), negative when one is
  /// penetrating or degenerate.
  double local_margin(const PcSet& pcs, const Mat3& R) const;

  /// The local non-penetration slack (a sine) a verified pose needs at every contact: half
  /// of sin(angle_margin), the slack the search asks of the rotations it tries.
  double verified_local_slack() const;

  const ModelInfo& a() const { return A_; }
  const ModelInfo& b() const { return B_; }
  const SearchParams& params() const { return p_; }
  /// mm: the larger model's size.
  double scale() const { return scale_; }

 protected:
  // Whether A's and B's tangent cones where element a of A touches element b of B have
  // disjoint interiors (exact for pairs with a face or two edges; vertex-edge and
  // vertex-vertex probe along each cone's inward axis).
  bool cones_disjoint(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b) const;
  // Whether A and B overlap where element a of A touches element b of B, d apart: they
  // touch in open points (within tol) and their tangent cones there are not disjoint
  // (verify's test for a PC or a pair a PC covers).
  bool overlap_at(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b, double d,
                  double tol) const;

  const ModelInfo& A_;
  const ModelInfo& B_;
  SearchParams p_;
  double scale_;
  double direction_tol_;  // on unit directions: rounding, or the models' precision over extent
};

/// "v", "e" or "f": the letter of an element's kind in messages.
std::string kind_name(ElementKind k);

}  // namespace cf::gen
