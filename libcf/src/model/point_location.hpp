#pragma once
// Point location in a planar polygon with holes, one boundary segment at a time: the
// nearest boundary point and the even-odd inside test over every loop. The one place this
// relation is written; cf::locate_in_face (a face's loops) and internal::locate (the flat
// loops of detection) both run it.

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf::internal {

struct PointLocator {
  explicit PointLocator(const Eigen::Vector2d& query) : q(query) {}

  /// Boundary segment p0 -> p1, the i-th of loop l.
  void segment(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, int l, int i) {
    const Eigen::Vector2d d = p1 - p0;
    const double len2 = d.squaredNorm();
    const double s = len2 > 0 ? std::clamp((q - p0).dot(d) / len2, 0.0, 1.0) : 0.0;
    const Eigen::Vector2d c = p0 + s * d;
    const double d2 = (c - q).squaredNorm();
    if (d2 < best2) {
      best2 = d2;
      closest = c;
      seg_dir = d;
      loop = l;
      index = i;
    }
    // Crossing of the ray from q towards +x.
    if ((p0.y() > q.y()) != (p1.y() > q.y())) {
      const double x = p0.x() + (q.y() - p0.y()) / (p1.y() - p0.y()) * (p1.x() - p0.x());
      if (x > q.x()) inside = !inside;
    }
  }
  /// Distance to the nearest boundary point.
  double distance() const { return std::sqrt(best2); }

  Eigen::Vector2d q;
  double best2 = std::numeric_limits<double>::infinity();
  bool inside = false;  ///< even-odd over the segments seen (on the boundary: either)
  Eigen::Vector2d closest = Eigen::Vector2d::Zero();
  Eigen::Vector2d seg_dir = Eigen::Vector2d::Zero();  ///< the nearest segment's p1 - p0
  int loop = -1, index = -1;                          ///< the nearest segment
};

}  // namespace cf::internal
