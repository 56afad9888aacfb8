#pragma once
/// @file
/// Penetration shown over a whole cell of poses (docs/generator.md, "Refuting a set over cells
/// of rotation space"): a point of one solid's boundary strictly inside the other solid, by
/// more than the cell lets it move, puts the two interiors into each other at every pose of
/// the cell (near that point the first solid's interior is inside the second's open
/// interior too).

#include "cfgen/verify/analysis.hpp"

#include <optional>
#include <vector>

namespace cf::gen {

/// mm: how far p lies inside the solid m (its distance to m's boundary), 0 when p is not
/// strictly inside.
double depth_inside(const Polyhedron& m, const Vec3& p);

/// A's rotation about a pivot and the range of the pivot's position: the poses
/// x_B = R (x_A - pivot) + t with R within `beta` (turn_bound) of R_c and t in [t_lo, t_hi].
struct PoseCell {
  Mat3 R_c = Mat3::Identity();
  double beta = 0;
  Vec3 pivot = Vec3::Zero();                      // mm, A's frame
  Vec3 t_lo = Vec3::Zero(), t_hi = Vec3::Zero();  // mm, B's frame
  double extra = 0;  // mm: a point must lie this much deeper than the cell lets it move
};

class DeepPoints {
 public:
  /// a, b: the analyses of A and B, which must outlive this object. The points tried: each
  /// solid's vertices, edge midpoints and the centroids of its faces' convex pieces.
  DeepPoints(const ModelInfo& a, const ModelInfo& b);

  struct Hit {
    bool of_a = true;  // a point of A inside B, else of B inside A
    int index = -1;    // in points(of_a)
    double depth = 0;  // mm, at the cell's centre pose
    double reach = 0;  // mm, how far the point can move over the cell
  };
  /// A point deeper inside the other solid, at the cell's centre pose, than it can move over
  /// the cell; std::nullopt when none is.
  std::optional<Hit> find(const PoseCell& cell) const;

  const std::vector<Vec3>& points(bool of_a) const { return of_a ? a_points_ : b_points_; }

 private:
  const ModelInfo& A_;
  const ModelInfo& B_;
  std::vector<Vec3> a_points_, b_points_;  // each in its own model's frame
};

}  // namespace cf::gen
