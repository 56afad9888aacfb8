#pragma once
/// @file
/// Closed-set distances, with closest points, between the elements (vertices, edges, faces)
/// of two polyhedra. Faces are planar polygons with holes; the closed face includes its
/// boundary. Every function is allocation-free and thread-safe.
///
/// Functions named `x_y` return `p_a` on the first element (x) and `p_b` on the second (y).
/// Functions taking a `Polyhedron` and a face work in that model's own frame; the
/// `element_distance` convenience works in the world (B's) frame with A posed.

#include <cf/polyhedron.hpp>
#include <cf/types.hpp>

#include <limits>

namespace cf {

/// Result of a closest-point query.
struct ClosestPoints {
  double distance = std::numeric_limits<double>::infinity();  ///< mm, >= 0
  Vec3 p_a = Vec3::Zero();  ///< closest point on the first element
  Vec3 p_b = Vec3::Zero();  ///< closest point on the second element
};

/// Where a 2D point lies relative to a face region (in the face's (u, v) frame).
struct FaceLocation {
  bool inside = false;  ///< in the open region (not on the boundary, not in a hole)
  double boundary_distance = std::numeric_limits<double>::infinity();  ///< mm, >= 0
  Eigen::Vector2d closest = Eigen::Vector2d::Zero();  ///< nearest boundary point, (u, v)
  int loop = -1;                                      ///< loop holding the nearest boundary segment
  int segment = -1;  ///< that segment: from loops_2d[loop][segment] to the next point
  /// Signed in-plane distance to the boundary: > 0 inside, < 0 outside (as face_inset).
  double inset() const { return inside ? boundary_distance : -boundary_distance; }
};

/// Locates q (face (u, v) coordinates) against face f of m: inside test (even-odd over all
/// loops, so holes are outside) and the nearest boundary point.
FaceLocation locate_in_face(const Polyhedron& m, FaceId f, const Eigen::Vector2d& q);

/// Point p to segment [s0, s1].
ClosestPoints point_segment(const Vec3& p, const Vec3& s0, const Vec3& s1);

/// Segment [p0, p1] to segment [q0, q1]. Robust for parallel, collinear and zero-length
/// segments (for parallel overlapping segments it returns one of the closest pairs).
ClosestPoints segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

/// Point q to the closed face f of m (all in m's frame): the plane distance when q projects
/// inside the face, else the distance to the nearest boundary segment. p_a = q.
ClosestPoints point_face(const Vec3& q, const Polyhedron& m, FaceId f);

/// Segment [s0, s1] to the closed face f of m (all in m's frame); 0 when the segment meets
/// the face.
ClosestPoints segment_face(const Vec3& s0, const Vec3& s1, const Polyhedron& m, FaceId f);

/// Face fa of A, posed by `pose`, to face fb of B, in the world (B) frame: the minimum over
/// the edges of each face against the other face, 0 when they overlap or cross.
ClosestPoints face_face(const Polyhedron& A, const Pose& pose, FaceId fa, const Polyhedron& B,
                        FaceId fb);

/// Distance between element `a` of kind `ka` of A posed by `pose` and element `b` of kind
/// `kb` of B, in the world frame (any of the nine kind pairs). p_a lies on A's element, p_b on
/// B's.
/// @throws cf::Error when an index is out of range for its kind in its model.
ClosestPoints element_distance(const Polyhedron& A, const Pose& pose, ElementKind ka, int a,
                               const Polyhedron& B, ElementKind kb, int b);

}  // namespace cf
