#include "cfgen/verify/touch.hpp"

#include "detect/polygon_clipping.hpp"  // libcf's private header: one polygon overlap

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <algorithm>
#include <cmath>

namespace cf::gen {
namespace {

namespace bg = boost::geometry;
using P2 = bg::model::d2::point_xy<double>;
using Poly = bg::model::polygon<P2>;  // clockwise outer ring, closed

// Does the open segment [p, q] (3D, lying in face f's plane) share a point with open face f?
bool segment_in_open_face(const Polyhedron& m, FaceId f, const Vec3& p, const Vec3& q, double tol) {
  const Face& F = m.face(f);
  const Eigen::Vector2d a = m.face_coords(f, p), b = m.face_coords(f, q);
  std::vector<double> cuts{0.0, 1.0};
  const Eigen::Vector2d d = b - a;
  for (const auto& loop : F.loops_2d)
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const Eigen::Vector2d& c = loop[k];
      const Eigen::Vector2d e = loop[(k + 1) % loop.size()] - c;
      const double den = d.x() * e.y() - d.y() * e.x();
      if (std::abs(den) < 1e-15) continue;
      const Eigen::Vector2d w = c - a;
      const double s = (w.x() * e.y() - w.y() * e.x()) / den;
      if (s > 0 && s < 1) cuts.push_back(s);
    }
  std::sort(cuts.begin(), cuts.end());
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    if ((cuts[i + 1] - cuts[i]) * d.norm() <= tol) continue;
    const double s = 0.5 * (cuts[i] + cuts[i + 1]);
    if (m.face_inset_2d(f, a + s * d) > tol) return true;
  }
  return false;
}

// Loops as libcf's flat polygon (outer loop counter-clockwise, holes clockwise), for its
// overlap(), which classifies boundary pieces within a tolerance: Boost.Geometry's
// intersection returns nothing for a face inside another whose sides lie along the other's
// to within float rounding (a cube in a corner read from float32 STL).
struct FlatPolygon {
  std::vector<internal::Vec2> pts;
  std::vector<int> lb{0};
  explicit FlatPolygon(const std::vector<std::vector<Eigen::Vector2d>>& loops) {
    for (std::size_t l = 0; l < loops.size(); ++l) {
      double area2 = 0;
      const auto& loop = loops[l];
      for (std::size_t k = 0; k < loop.size(); ++k)
        area2 += internal::cross2(loop[k], loop[(k + 1) % loop.size()]);
      if ((area2 > 0) == (l == 0))
        pts.insert(pts.end(), loop.begin(), loop.end());
      else
        pts.insert(pts.end(), loop.rbegin(), loop.rend());
      lb.push_back(static_cast<int>(pts.size()));
    }
  }
  internal::Poly2 poly() const { return {pts.data(), lb.data(), static_cast<int>(lb.size()) - 1}; }
};

// The area and centroid of the overlap of two faces' loops in one plane, boundaries that
// run along each other within tol counted once.
internal::Overlap2 loops_overlap(const std::vector<std::vector<Eigen::Vector2d>>& a,
                                 const std::vector<std::vector<Eigen::Vector2d>>& b, double tol) {
  const FlatPolygon pa(a), pb(b);
  std::vector<double> params(2 + 2 * std::max(pa.pts.size(), pb.pts.size()));
  return internal::overlap(pa.poly(), pb.poly(), tol, params.data(), [](const internal::Vec2&) {});
}

Poly face_polygon(const std::vector<std::vector<Eigen::Vector2d>>& loops) {
  Poly poly;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    auto& ring = l == 0 ? poly.outer() : (poly.inners().emplace_back(), poly.inners().back());
    for (const auto& p : loops[l]) ring.push_back(P2(p.x(), p.y()));
    ring.push_back(ring.front());
  }
  bg::correct(poly);
  return poly;
}

}  // namespace

std::optional<Vec3> face_overlap_centroid(const Polyhedron& A, const Pose& pose, int a,
                                          const Polyhedron& B, int b) {
  const Face& fa = A.face(FaceId(a));
  const Face& fb = B.face(FaceId(b));
  std::vector<std::vector<Eigen::Vector2d>> loops_a;
  for (const auto& loop : fa.loops) {
    loops_a.emplace_back();
    for (VertexId v : loop)
      loops_a.back().push_back(B.face_coords(FaceId(b), pose.apply(A.vertex(v).p)));
  }
  const Poly pa = face_polygon(loops_a), pb = face_polygon(fb.loops_2d);
  std::vector<Poly> inter;
  bg::intersection(pa, pb, inter);
  double best = 0, total = 0;
  std::optional<Vec3> out;
  for (const auto& p : inter) {
    const double area = std::abs(bg::area(p));
    total += area;
    if (area <= best) continue;
    P2 c;
    bg::centroid(p, c);
    best = area;
    out = fb.offset * fb.normal + c.x() * fb.u + c.y() * fb.v;
  }
  // Where Boost.Geometry misses area (sides along each other to rounding), the whole
  // overlap's centroid, when it lies in both faces.
  const double tol = 1e-9 * std::max(A.size(), B.size());
  const internal::Overlap2 o = loops_overlap(loops_a, fb.loops_2d, tol);
  if (o.area - total <= tol * std::max(A.size(), B.size())) return out;
  const Vec3 c = fb.offset * fb.normal + o.centroid.x() * fb.u + o.centroid.y() * fb.v;
  if (B.face_inset(FaceId(b), c) > 0 && A.face_inset(FaceId(a), pose.inverse_apply(c)) > 0)
    return c;
  return out;
}

bool open_touch(const Polyhedron& A, const Pose& pose, ElementKind ka, int a, const Polyhedron& B,
                ElementKind kb, int b, double tol) {
  using K = ElementKind;
  auto vA = [&](int i) { return pose.apply(A.vertices()[i].p); };
  auto edge_param_interior = [&](const Vec3& p, const Vec3& e0, const Vec3& e1) {
    const double len = (e1 - e0).norm();
    const double s = (p - e0).dot(e1 - e0) / len;
    return s > tol && s < len - tol;
  };
  if (ka == K::kVertex && kb == K::kVertex) return true;
  if (ka == K::kVertex && kb == K::kEdge)
    return edge_param_interior(vA(a), B.edge_point(EdgeId(b), 0), B.edge_point(EdgeId(b), 1));
  if (ka == K::kEdge && kb == K::kVertex)
    return edge_param_interior(B.vertices()[b].p, pose.apply(A.edge_point(EdgeId(a), 0)),
                               pose.apply(A.edge_point(EdgeId(a), 1)));
  if (ka == K::kVertex && kb == K::kFace) return B.face_inset(FaceId(b), vA(a)) > tol;
  if (ka == K::kFace && kb == K::kVertex)
    return A.face_inset(FaceId(a), pose.inverse_apply(B.vertices()[b].p)) > tol;
  if (ka == K::kEdge && kb == K::kEdge) {
    const Vec3 p0 = pose.apply(A.edge_point(EdgeId(a), 0)),
               p1 = pose.apply(A.edge_point(EdgeId(a), 1));
    const Vec3 q0 = B.edge_point(EdgeId(b), 0), q1 = B.edge_point(EdgeId(b), 1);
    const Vec3 da = (p1 - p0).normalized(), db = (q1 - q0).normalized();
    if (da.cross(db).norm() > 1e-9) {
      const ClosestPoints cp = segment_segment(p0, p1, q0, q1);
      return edge_param_interior(cp.p_a, p0, p1) && edge_param_interior(cp.p_b, q0, q1);
    }
    // Parallel and within tol: collinear; open intervals must overlap by more than tol.
    const double la = (p1 - p0).norm();
    double s0 = (q0 - p0).dot(da), s1 = (q1 - p0).dot(da);
    if (s0 > s1) std::swap(s0, s1);
    return std::min(la, s1) - std::max(0.0, s0) > tol;
  }
  if ((ka == K::kEdge && kb == K::kFace) || (ka == K::kFace && kb == K::kEdge)) {
    // Work in the face's model frame.
    const bool a_is_edge = ka == K::kEdge;
    const Polyhedron& fm = a_is_edge ? B : A;
    const FaceId f(a_is_edge ? b : a);
    Vec3 p, q;
    if (a_is_edge) {
      p = vA(A.edges()[a].v0.value());
      q = vA(A.edges()[a].v1.value());
    } else {
      p = pose.inverse_apply(B.edge_point(EdgeId(b), 0));
      q = pose.inverse_apply(B.edge_point(EdgeId(b), 1));
    }
    const Face& F = fm.face(f);
    const double hp = F.normal.dot(p) - F.offset, hq = F.normal.dot(q) - F.offset;
    if (std::abs(hp) <= tol && std::abs(hq) <= tol) return segment_in_open_face(fm, f, p, q, tol);
    if ((hp > tol && hq < -tol) || (hp < -tol && hq > tol)) {
      const Vec3 x = p + (hp / (hp - hq)) * (q - p);
      return fm.face_inset(f, x) > tol;
    }
    return false;  // meets the plane at an end point only: a vertex touch, not the edge's
  }
  // Face-face: only coplanar faces can share open points without an edge crossing a face
  // (which the edge pairs report).
  const Face& fa = A.face(FaceId(a));
  const Face& fb = B.face(FaceId(b));
  const Vec3 na = pose.R_BA * fa.normal;
  if (std::abs(na.dot(fb.normal)) < 1 - 1e-9) return false;
  for (VertexId v : fa.vertices)
    if (std::abs(fb.normal.dot(vA(v.value())) - fb.offset) > tol) return false;
  std::vector<std::vector<Eigen::Vector2d>> loops_a;
  for (const auto& loop : fa.loops) {
    loops_a.emplace_back();
    for (VertexId v : loop) loops_a.back().push_back(B.face_coords(FaceId(b), vA(v.value())));
  }
  return loops_overlap(loops_a, fb.loops_2d, tol).area > tol * std::max(A.size(), B.size());
}

}  // namespace cf::gen
