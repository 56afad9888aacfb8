#include "cfgen/decide/deep_points.hpp"

#include <algorithm>
#include <cmath>

namespace cf::gen {
namespace {

std::vector<Vec3> boundary_points(const ModelInfo& info) {
  const Polyhedron& m = *info.model;
  std::vector<Vec3> out;
  for (const Vertex& v : m.vertices()) out.push_back(v.p);
  for (std::size_t e = 0; e < m.num_edges(); ++e)
    out.push_back(0.5 * (m.edge_point(EdgeId(static_cast<int>(e)), 0) +
                         m.edge_point(EdgeId(static_cast<int>(e)), 1)));
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    const Face& F = m.faces()[f];
    for (const ConvexPiece& piece : info.pieces[f]) {
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (const auto& q : piece.points) c += q;
      c /= static_cast<double>(piece.points.size());
      out.push_back(F.offset * F.normal + c.x() * F.u + c.y() * F.v);
    }
  }
  return out;
}

// mm: p's distance to face f's closed polygon.
double face_distance(const Polyhedron& m, std::size_t f, const Vec3& p) {
  const Face& F = m.faces()[f];
  const double h = F.normal.dot(p) - F.offset;
  const double out = std::max(0.0, -m.face_inset(FaceId(static_cast<int>(f)), p));
  return std::sqrt(h * h + out * out);
}

// depth_inside(m, p) when it exceeds `need`, else 0; most points tried are not that deep, and
// are turned away without the point-in-solid test: the depth is at most the distance to the
// bounding box's sides (m lies inside it) and to any face, and a face's plane is no farther
// than the face.
double depth_beyond(const Polyhedron& m, const Vec3& p, double need) {
  const Vec3 lo = m.bbox_min(), hi = m.bbox_max();
  if (std::min((p - lo).minCoeff(), (hi - p).minCoeff()) <= need) return 0;
  double d = HUGE_VAL;
  for (std::size_t f = 0; f < m.num_faces(); ++f) {
    const Face& F = m.faces()[f];
    if (std::abs(F.normal.dot(p) - F.offset) >= d) continue;
    d = std::min(d, face_distance(m, f, p));
    if (d <= need) return 0;
  }
  return point_inside(m, p, 0.0) ? d : 0;
}

}  // namespace

double depth_inside(const Polyhedron& m, const Vec3& p) { return depth_beyond(m, p, 0); }

DeepPoints::DeepPoints(const ModelInfo& a, const ModelInfo& b)
    : A_(a), B_(b), a_points_(boundary_points(a)), b_points_(boundary_points(b)) {}

std::optional<DeepPoints::Hit> DeepPoints::find(const PoseCell& c) const {
  const Vec3 t_mid = 0.5 * (c.t_lo + c.t_hi);
  const double spread = 0.5 * (c.t_hi - c.t_lo).norm();  // |t - t_mid| over the box
  // A's points in B: R (x - pivot) + t is within beta |x - pivot| + spread of its image at
  // the centre pose.
  for (std::size_t i = 0; i < a_points_.size(); ++i) {
    const Vec3 arm = a_points_[i] - c.pivot;
    const Vec3 y = c.R_c * arm + t_mid;
    const double reach = c.beta * arm.norm() + spread + c.extra;
    const double depth = depth_beyond(*B_.model, y, reach);
    if (depth > reach) return Hit{true, static_cast<int>(i), depth, reach};
  }
  // B's points in A: R^T (w - t) + pivot moves by at most beta |w - t| + |t - t_mid|, with
  // |w - t| <= |w - t_mid| + spread.
  const Mat3 Rt = c.R_c.transpose();
  for (std::size_t i = 0; i < b_points_.size(); ++i) {
    const Vec3 arm = b_points_[i] - t_mid;
    const Vec3 x = Rt * arm + c.pivot;
    const double reach = c.beta * (arm.norm() + spread) + spread + c.extra;
    const double depth = depth_beyond(*A_.model, x, reach);
    if (depth > reach) return Hit{false, static_cast<int>(i), depth, reach};
  }
  return std::nullopt;
}

}  // namespace cf::gen
