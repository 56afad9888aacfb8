#pragma once
// Necessary conditions for two PCs to hold at once, checked before any witness search. Each
// compares a quantity that a rigid motion of A keeps (a distance, an angle, a height) between
// what A's two elements allow and what B's two elements allow; when the ranges do not meet,
// no pose makes both PCs hold and the pair is invalid. They are relaxations of one exact
// condition (a rotation takes A's contact normals and the vector between A's contact points
// onto B's), so they never reject a valid pair; tolerances only widen the ranges.

#include "analysis.hpp"

#include <cf/pc.hpp>

#include <array>
#include <vector>

namespace cf::gen {

/// The outward unit normals a solid can have at an element where another solid touches it
/// without penetrating (its normal cone): one normal for a face, the arc between the two face
/// normals of a convex edge, the polar of the tangent cone of a pointed vertex. Spherically
/// convex, inside an open hemisphere.
struct NormalCone {
  std::vector<Vec3> gens;     // unit generators (extreme rays)
  std::vector<Vec3> facets;   // unit h: the cone is { u : h . u >= shift } (three or more gens)
  double shift = 0;           // sin of the margin the cone was shrunk by
};

class PairConditions {
 public:
  /// length_tol (mm) and angle_tol (rad) widen every range: a pair is rejected only when its
  /// ranges miss each other by more. cone_margin (rad) shrinks the normal cones of edges and
  /// vertices: the generator verifies a witness only when every contact normal is at least
  /// that far inside them (WitnessSearch::verify's local non-penetration slack), so a pair
  /// that needs a normal closer to a cone's boundary cannot be in the graph.
  PairConditions(const ModelInfo& A, const ModelInfo& B, double length_tol, double angle_tol,
                 double cone_margin = 0);

  /// False when x and y cannot hold at one pose: the distance between the contact points,
  /// the angle between the contact normals, or the height of one contact point over the
  /// other's contact plane has no value both A and B allow.
  bool compatible(const Pc& x, const Pc& y) const;

  /// The normal cone of element i of kind k (of A when of_a, else of B), shrunk by the cone
  /// margin; no generators for elements no PC can use (non-convex edges, vertices that are
  /// not pointed, cones narrower than twice the margin).
  const NormalCone& cone(bool of_a, ElementKind k, int i) const;

 private:
  std::array<std::vector<NormalCone>, 3> a_cones_, b_cones_;  // by element kind
  std::array<std::vector<std::vector<Vec3>>, 3> a_points_, b_points_;  // closure vertices, by kind
  const ModelInfo& A_;
  const ModelInfo& B_;
  double length_tol_, angle_tol_;
};

/// Spherical distance (rad) from unit p to a normal cone (0 inside, within `tol`).
double cone_distance(const Vec3& p, const NormalCone& c, double tol);
/// Smallest angle (rad) between a direction of cone p and one of cone q (0 when they meet).
double cone_cone_distance(const NormalCone& p, const NormalCone& q, double tol);

}  // namespace cf::gen
