#pragma once
// CGAL-free interface to the two CGAL services the generator needs: an exact linear-program
// solver and convex partitions of face polygons. Everything CGAL lives in cgal_support.cpp so
// that only one translation unit of the generator pays CGAL's compile time.

#include <Eigen/Core>

#include <vector>

namespace cf::gen {

/// minimise c.x subject to rows (a_i . x  REL_i  b_i) and per-variable bounds.
struct LinearProgram {
  enum class Rel { kLessEq, kEq, kGreaterEq };
  struct Row {
    std::vector<std::pair<int, double>> a;  // sparse coefficients (variable, value)
    Rel rel;
    double b;
  };
  int num_vars = 0;
  std::vector<Row> rows;
  std::vector<double> c;                  // objective, size num_vars
  std::vector<std::pair<bool, double>> lower, upper;  // (finite?, value) per variable

  explicit LinearProgram(int n)
      : num_vars(n), c(n, 0.0), lower(n, {false, 0.0}), upper(n, {false, 0.0}) {}
  void add(std::vector<std::pair<int, double>> a, Rel rel, double b) {
    rows.push_back({std::move(a), rel, b});
  }
};

struct LpResult {
  enum class Status { kOptimal, kInfeasible, kUnbounded } status = Status::kInfeasible;
  Eigen::VectorXd x;  // the optimum, rounded to double from the exact solution
};

/// Solves exactly (CGAL's QP solver over Gmpzf) and rounds the optimum to double.
LpResult solve(const LinearProgram& lp);

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
