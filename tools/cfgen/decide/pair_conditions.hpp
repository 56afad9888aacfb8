#pragma once
// Necessary conditions for two PCs to hold at once, checked before any witness search. Each
// compares a quantity that a rigid motion of A keeps (a distance, an angle, a height) between
// what A's two elements allow and what B's two elements allow; when the ranges do not meet,
// no pose makes both PCs hold and the pair is invalid. They are relaxations of one exact
// condition (a rotation takes A's contact normals and the vector between A's contact points
// onto B's), so they never reject a valid pair; tolerances only widen the ranges.

#include "cfgen/verify/analysis.hpp"

#include <cf/pc.hpp>

#include <array>
#include <vector>

namespace cf::gen {

/// The outward unit normals a solid can have at an element where another solid touches it
/// without penetrating (its normal cone): one normal for a face, the arc between the two face
/// normals of a convex edge, the polar of the tangent cone of a pointed vertex. Spherically
/// convex, inside an open hemisphere.
struct NormalCone {
  std::vector<Vec3> gens;    // unit generators (extreme rays)
  std::vector<Vec3> facets;  // unit h: the cone is { u : h . u >= shift } (three or more gens)
  double shift = 0;          // sin of the margin the cone was shrunk by
};

class PairConditions {
 public:
  /// length_tol (mm) and angle_tol (rad) widen every range: a pair is rejected only when its
  /// ranges miss each other by more. cone_margin (rad) shrinks the normal cones of edges and
  /// vertices: the generator verifies a witness only when every contact normal is at least
  /// that far inside them (WitnessSearch::verify's local non-penetration slack), so a pair
  /// that needs a normal closer to a cone's boundary cannot be in the graph.
  /// contact_margin (mm): the generator verifies a witness only with each contact point at
  /// least min_margin inside its elements (the witness search's LP, refine's check), so the
  /// distances and heights range over those points (inset_closure_points); pass at most
  /// min_margin, less to allow for the LP's rounding.
  /// Precomputes what each model allows for every ordered pair of its elements (memory and
  /// time quadratic in the number of elements), so `compatible` is a few comparisons. A and
  /// B must outlive this object.
  PairConditions(const ModelInfo& A, const ModelInfo& B, double length_tol, double angle_tol,
                 double cone_margin = 0, double contact_margin = 0);

  /// False when x and y cannot hold at one pose: the distance between the contact points,
  /// the angle between the contact normals, or the height of one contact point over the
  /// other's contact plane has no value both A and B allow; or one is an e-e whose contact
  /// normal the other's rotational condition fixes (forced_normal_fails).
  bool compatible(const Pc& x, const Pc& y) const;

  /// True when `e` is an e-e PC whose two edges the rotational condition of `x` (an f-f, e-f
  /// or f-e) holds perpendicular to one direction, so that its contact normal is that
  /// direction or its opposite (docs/generator.md, "Enumeration"), and neither lies as far
  /// inside the two edges' normal cones as verify's local slack asks: an e-f edge parallel
  /// to the e-e's edge of A with B's edge parallel to the face (normal: the face's), an f-e
  /// edge parallel to the e-e's edge of B with A's edge parallel to the face, or an f-f with
  /// each edge parallel to its solid's face. The cone in the frame the normal is fixed in is
  /// checked directly; for an e-f or f-e the other one over every turn about the parallel
  /// edges that the PC's own local margin allows. The directions are within kParallel of
  /// parallel or perpendicular; the slack then bounds how far the normal can be from the
  /// direction.
  bool forced_normal_fails(const Pc& x, const Pc& e) const;

  /// True when x and y are e-e PCs whose edges of A are parallel and whose edges of B are
  /// parallel (within kParallel), so that their contact normals, each perpendicular to both
  /// of its edges, are parallel or opposite, and neither angle (0 or pi, within what the
  /// edges' residuals over verify's slack allow) is one both models' cones allow.
  bool parallel_normals_fail(const Pc& x, const Pc& y) const;

  /// Edges within this sine of parallel, or of perpendicular to a normal, in forced_normal_fails.
  static constexpr double kParallel = 1e-9;

  /// The normal cone of element i of kind k (of A when of_a, else of B), shrunk by the cone
  /// margin; no generators for elements no PC can use (non-convex edges, vertices that are
  /// not pointed, cones narrower than twice the margin).
  const NormalCone& cone(bool of_a, ElementKind k, int i) const;

  /// What one model allows for two of its elements x and y touched by two PCs (mm, rad).
  struct Allowed {
    double dist_lo = 0, dist_hi = 0;      // distance between a point of x and a point of y
    double angle_lo = 0, angle_hi = 0;    // angle between a normal of x's cone and one of y's
    double height_lo = 0, height_hi = 0;  // (point of y - point of x) . (normal of x's cone)
    bool usable = false;                  // both cones have directions
  };

 private:
  struct Side {
    std::array<std::vector<NormalCone>, 3> cones;  // by element kind
    std::array<int, 3> offset{};                   // first index of each kind in the table
    int n = 0;                                     // elements of all kinds
    std::vector<Allowed> table;                    // n x n, ordered pairs
    const Allowed& at(ElementKind kx, int x, ElementKind ky, int y) const {
      return table[static_cast<std::size_t>(offset[static_cast<int>(kx)] + x) *
                       static_cast<std::size_t>(n) +
                   static_cast<std::size_t>(offset[static_cast<int>(ky)] + y)];
    }
  };
  static Side build(const ModelInfo& m, double cone_margin, double angle_tol,
                    double contact_margin);
  // rad: what x's rotational condition may leave (condition_tol), 0 for a point PC.
  double condition_turn(const Pc& x) const;

  const ModelInfo& A_;
  const ModelInfo& B_;
  Side a_, b_;
  double length_tol_, angle_tol_;
  double slack_;  // sine: the cone margin's, at most verify's local slack
};

/// Spherical distance (rad) from unit p to a normal cone (0 inside, within `tol`).
double cone_distance(const Vec3& p, const NormalCone& c, double tol);
/// Smallest angle (rad) between a direction of cone p and one of cone q (0 when they meet).
double cone_cone_distance(const NormalCone& p, const NormalCone& q, double tol);

}  // namespace cf::gen
