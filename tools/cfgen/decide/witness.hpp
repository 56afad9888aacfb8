#pragma once
/// @file
/// Witness search for one candidate set of principal contacts: rotations that satisfy the
/// rotational conditions of its f-f / e-f / f-e contacts, a linear program for the translation
/// with the largest margin inside the touching elements, and the verifier's judgement of the
/// whole pose. Its parts: find.cpp (the search's stages), witness.cpp (refinement, proofs,
/// necessary conditions), rotations.cpp (the
/// rotations tried), translations.cpp (the programs and the climb past obstacles).

#include "cfgen/verify/lp.hpp"
#include "cfgen/verify/verifier.hpp"

#include <cf/graph.hpp>

#include <optional>
#include <string>
#include <vector>

namespace cf::gen {

namespace internal {
class FindRun;
}

/// The outcome of a search: whether a witness was found, and its quality.
struct Witness {
  bool found = false;
  Pose pose;
  double clearance =
      0;              // mm, smallest distance between elements not part of a PC, <= good_clearance
  double margin = 0;  // mm, the LP margin of the contacts inside their elements
};

/// The necessary conditions that prove a candidate set invalid without a search of its poses
/// (docs/generator.md, "When a candidate is declared invalid"; docs/certificates.md, "Rules").
enum class Rule {
  kNone,                  // no rule applies
  kVertexInTwoPcs,        // one vertex in two PCs
  kDominatedPc,           // a PC's elements lie in the closures of another's
  kOneContactPlane,       // two PCs' faces of A, or of B, in one plane
  kHeightsOverFf,         // another PC's elements cannot meet at one height over an f-f
  kRotationalConditions,  // no rotation meets the rotational conditions
  kFiniteRotations,       // finitely many rotations, none with room for the contacts
  kMirrorCorners,         // two e-e PCs at mirror corners (mirror_corners.hpp)
};

/// The rule's name in the certificate file: "vertex-in-two-pcs", ... ("" for kNone).
const char* rule_name(Rule rule);

/// A rule that holds, and the indices (in the set) of the PCs it concerns (-1: none).
struct RuleVerdict {
  Rule rule = Rule::kNone;
  int first = -1, second = -1;
};

/// The search for witnesses (docs/generator.md, "Layers", decide): rotations from the PCs'
/// conditions, seeds and samples, translations from linear programs, climbs past obstacles;
/// every pose it returns is one its Verifier accepts.
class WitnessSearch : public Verifier {
 public:
  WitnessSearch(const ModelInfo& a, const ModelInfo& b, const SearchParams& p);

  /// Searches a witness for `pcs`, trying the seed rotations (witnesses of sub-sets) first.
  /// With `seeds_only`, a search near given rotations: tries only the seeds and rotations
  /// 0.01 and 0.025 rad about each axis from them (projected onto the PCs' rotational
  /// conditions), then climbs past the obstacles met there.
  /// When no witness is found and `blocked` is given, it receives the poses where the
  /// contacts were placed and the centred translation touched another pair of elements (up
  /// to 4).
  Witness find(const PcSet& pcs, const std::vector<Mat3>& seeds, bool seeds_only = false,
               std::vector<Pose>* blocked = nullptr) const;

  /// A witness for `pcs` near `pose`, a pose where they hold (found by a motion): moved
  /// towards the centre of the translations that keep the contacts, or `pose` itself, when
  /// verified with the contacts at least min_margin inside their elements.
  Witness refine(const PcSet& pcs, const Pose& pose) const;

  /// A witness for `pcs` at `image`, the image of another CF's witness under a symmetry of
  /// the models: `image` itself when it verifies; else, since a symmetry found only to the
  /// files' precision turns and moves the witness by about that much, `image` with its
  /// rotation projected onto the PCs' rotational conditions and its translation re-solved
  /// (refine). found: false when neither verifies.
  Witness image_witness(const PcSet& pcs, const Pose& image) const;

  /// For a set `find` found no witness for: true when it is proven invalid within the
  /// search's tolerances (a necessary condition fails, or its rotational conditions leave
  /// finitely many rotations (finite_rotations) and at each the PCs are locally penetrating or
  /// cannot be placed inside their elements with a THIN pose's margin, thin_params). False means
  /// undecided: the search gave up without a proof.
  bool refuted(const PcSet& pcs) const { return refuted_by(pcs).rule != Rule::kNone; }
  /// The rule that proves `pcs` invalid, as refuted() decides it; kNone: undecided.
  RuleVerdict refuted_by(const PcSet& pcs) const;

  /// The rotations that meet the set's rotational conditions when they are finitely many
  /// (two alignments; an alignment and a condition that fixes its spin; three
  /// perpendicularities), possibly none; nothing when they leave a continuum.
  std::optional<std::vector<Mat3>> finite_rotations(const PcSet& pcs) const;

  /// Cheap necessary conditions on a candidate set (no geometry search).
  bool plausible(const PcSet& pcs) const { return implausible_by(pcs).rule == Rule::kNone; }
  /// The first cheap condition that fails (vertex in two PCs, dominated PC, one contact
  /// plane, heights over an f-f), or kNone.
  RuleVerdict implausible_by(const PcSet& pcs) const;

 private:
  friend class internal::FindRun;  // find's stages (find.cpp)
  // generic_seeds: add each PC's preferred family and a spread of rotations to `seeds`.
  std::vector<Mat3> rotation_candidates(const PcSet& pcs, const std::vector<Mat3>& seeds,
                                        bool generic_seeds = true) const;
  // Rotations satisfying the PCs' rotational conditions: the seeds projected onto them, and
  // `samples` spins when one face alignment leaves the spin free.
  std::vector<Mat3> family_samples(const PcSet& pcs, const std::vector<Mat3>& seeds,
                                   int samples) const;
  // The seeds, each PC's preferred rotations and a fixed spread over SO(3).
  std::vector<Mat3> spread_rotations(const PcSet& pcs, const std::vector<Mat3>& seeds) const;
  // For a set with two point PCs (v-f, f-v, e-e): rotations that place both contacts at
  // sampled points inside their elements, i.e. take the segment between the two points on A
  // onto a segment of the same length between the two points on B, spun about it. Locally
  // penetrating ones dropped, at most max_rotations, spread apart. near_miss: when none is
  // locally admissible, receives the one nearest to it (the largest local margin evaluated),
  // if any was evaluated.
  std::vector<Mat3> anchored_rotations(const PcSet& pcs,
                                       std::optional<Mat3>* near_miss = nullptr) const;
  // Number of convex pieces of each face slot of the LP (build_lp's `pieces`), in its order.
  std::vector<int> piece_slots(const PcSet& pcs) const;
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
  bool separating_cut(const Mat3& R, const Vec3& t, const Obstacle& o,
                      LinearProgram::Row& cut) const;
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

  bool debug_;  // CFGEN_DEBUG set: explain every attempt on stderr
};

}  // namespace cf::gen
