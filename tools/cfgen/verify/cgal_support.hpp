#pragma once
// CGAL-free interface to the CGAL service the generator needs: convex partitions of face
// polygons. Everything CGAL lives in cgal_support.cpp so that only one translation unit of the
// generator pays CGAL's compile time.

#include <Eigen/Core>

#include <vector>

namespace cf::gen {

/// A convex piece of a face polygon, in the face's 2D (u, v) frame, counter-clockwise.
/// boundary[k] tells whether side k (point k to point k+1) lies on the face's real boundary
/// (true) or is a diagonal added by the partition (false).
struct ConvexPiece {
  std::vector<Eigen::Vector2d> points;
  std::vector<bool> boundary;
};

/// Partitions a polygon with holes (outer loop CCW, holes CW, as in cf::Face::loops_2d) into
/// convex pieces: constrained Delaunay triangulation, then Hertel-Mehlhorn merging.
std::vector<ConvexPiece> convex_partition(const std::vector<std::vector<Eigen::Vector2d>>& loops);

}  // namespace cf::gen
