#include <cf/geometry.hpp>

#include "check.hpp"
#include "model/point_location.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace cf {
namespace {

using Vec2 = Eigen::Vector2d;

// Relative tolerance below which two segment directions count as parallel in the
// closest-point solve (squared sine of the angle between them): below it the 2x2 system is
// ill-conditioned and the parallel branch gives an equally valid closest pair.
constexpr double kParallelSin2 = 1e-20;

// Maps a closest-point result computed in A's frame to the world frame.
ClosestPoints to_world(const ClosestPoints& c, const Pose& pose) {
  return {c.distance, pose.apply(c.p_a), pose.apply(c.p_b)};
}

ClosestPoints swapped(const ClosestPoints& c) { return {c.distance, c.p_b, c.p_a}; }

}  // namespace

FaceLocation locate_in_face(const Polyhedron& m, FaceId f, const Vec2& q) {
  const Face& F = m.face(f);
  internal::PointLocator loc(q);
  for (std::size_t l = 0; l < F.loops_2d.size(); ++l) {
    const auto& loop = F.loops_2d[l];
    for (std::size_t i = 0, n = loop.size(); i < n; ++i)
      loc.segment(loop[i], loop[i + 1 == n ? 0 : i + 1], static_cast<int>(l), static_cast<int>(i));
  }
  FaceLocation out;
  out.closest = loc.closest;
  out.loop = loc.loop;
  out.segment = loc.index;
  out.boundary_distance = loc.distance();
  // A point exactly on the boundary is not in the open region.
  out.inside = loc.inside && out.boundary_distance > 0;
  return out;
}

ClosestPoints point_segment(const Vec3& p, const Vec3& s0, const Vec3& s1) {
  const Vec3 d = s1 - s0;
  const double len2 = d.squaredNorm();
  const double s = len2 > 0 ? std::clamp((p - s0).dot(d) / len2, 0.0, 1.0) : 0.0;
  const Vec3 c = s0 + s * d;
  return {(c - p).norm(), p, c};
}

ClosestPoints segment_segment(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  // Ericson, Real-Time Collision Detection, 5.1.9, with the parallel case clamped.
  const Vec3 d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 0 && e <= 0) {
    s = t = 0;
  } else if (a <= 0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denom = a * e - b * b;
      if (denom > kParallelSin2 * a * e) {
        s = std::clamp((b * f - c * e) / denom, 0.0, 1.0);
      } else {
        // Parallel: any s works for the infinite lines; pick the one that puts the
        // projection of q's interval midpoint nearest, so overlapping segments give a
        // point inside the overlap.
        const double tm = 0.5;
        s = std::clamp(((q0 + tm * d2) - p0).dot(d1) / a, 0.0, 1.0);
      }
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  const Vec3 cp = p0 + s * d1, cq = q0 + t * d2;
  return {(cp - cq).norm(), cp, cq};
}

ClosestPoints point_face(const Vec3& q, const Polyhedron& m, FaceId f) {
  const Face& F = m.face(f);
  const double h = F.normal.dot(q) - F.offset;
  const Vec2 uv(F.u.dot(q), F.v.dot(q));
  const FaceLocation loc = locate_in_face(m, f, uv);
  if (loc.inside || loc.boundary_distance == 0) return {std::abs(h), q, q - h * F.normal};
  const Vec3 c = loc.closest.x() * F.u + loc.closest.y() * F.v + F.offset * F.normal;
  return {(q - c).norm(), q, c};
}

ClosestPoints segment_face(const Vec3& s0, const Vec3& s1, const Polyhedron& m, FaceId f) {
  const Face& F = m.face(f);
  const double h0 = F.normal.dot(s0) - F.offset;
  const double h1 = F.normal.dot(s1) - F.offset;
  // Crossing the plane inside the face: distance 0.
  if ((h0 <= 0 && h1 >= 0) || (h0 >= 0 && h1 <= 0)) {
    if (h0 != h1) {
      const Vec3 x = s0 + (h0 / (h0 - h1)) * (s1 - s0);
      const FaceLocation loc = locate_in_face(m, f, Vec2(F.u.dot(x), F.v.dot(x)));
      if (loc.inside || loc.boundary_distance == 0) return {0.0, x, x};
    }
  }
  // Otherwise the minimum is at an end point projecting inside, or against the boundary.
  ClosestPoints best;
  const Vec3* ends[2] = {&s0, &s1};
  const double hs[2] = {h0, h1};
  for (int i = 0; i < 2; ++i) {
    const Vec3& p = *ends[i];
    const FaceLocation loc = locate_in_face(m, f, Vec2(F.u.dot(p), F.v.dot(p)));
    if ((loc.inside || loc.boundary_distance == 0) && std::abs(hs[i]) < best.distance)
      best = {std::abs(hs[i]), p, p - hs[i] * F.normal};
  }
  for (EdgeId e : F.edges) {
    const ClosestPoints c = segment_segment(s0, s1, m.edge_point(e, 0), m.edge_point(e, 1));
    if (c.distance < best.distance) best = c;
  }
  return best;
}

ClosestPoints face_face(const Polyhedron& A, const Pose& pose, FaceId fa, const Polyhedron& B,
                        FaceId fb) {
  ClosestPoints best;
  for (EdgeId e : A.face(fa).edges) {
    const ClosestPoints c =
        segment_face(pose.apply(A.edge_point(e, 0)), pose.apply(A.edge_point(e, 1)), B, fb);
    if (c.distance < best.distance) best = c;
  }
  for (EdgeId e : B.face(fb).edges) {
    const ClosestPoints c = segment_face(pose.inverse_apply(B.edge_point(e, 0)),
                                         pose.inverse_apply(B.edge_point(e, 1)), A, fa);
    if (c.distance < best.distance) best = swapped(to_world(c, pose));
  }
  return best;
}

namespace {
bool in_range(const Polyhedron& m, ElementKind k, int i) {
  return i >= 0 && static_cast<std::size_t>(i) < m.num_elements(k);
}
}  // namespace

ClosestPoints element_distance(const Polyhedron& A, const Pose& pose, ElementKind ka, int a,
                               const Polyhedron& B, ElementKind kb, int b) {
  using K = ElementKind;
  CF_REQUIRE(in_range(A, ka, a) && in_range(B, kb, b),
             "element_distance: element index " + std::to_string(in_range(A, ka, a) ? b : a) +
                 " is out of range for its model's " + (in_range(A, ka, a) ? "B" : "A") +
                 " elements of that kind");
  if (ka == K::kFace && kb == K::kFace) return face_face(A, pose, FaceId(a), B, FaceId(b));
  if (ka == K::kFace) {
    // Work in A's frame against A's face; the B element is mapped there.
    const FaceId f(a);
    if (kb == K::kVertex) {
      const Vec3 q = pose.inverse_apply(B.vertex(VertexId(b)).p);
      return swapped(to_world(point_face(q, A, f), pose));
    }
    const EdgeId e(b);
    return swapped(to_world(segment_face(pose.inverse_apply(B.edge_point(e, 0)),
                                         pose.inverse_apply(B.edge_point(e, 1)), A, f),
                            pose));
  }
  if (kb == K::kFace) {
    const FaceId f(b);
    if (ka == K::kVertex) return point_face(pose.apply(A.vertex(VertexId(a)).p), B, f);
    const EdgeId e(a);
    return segment_face(pose.apply(A.edge_point(e, 0)), pose.apply(A.edge_point(e, 1)), B, f);
  }
  // Vertices and edges: points and segments in the world frame.
  Vec3 a0, a1, b0, b1;
  if (ka == K::kVertex) {
    a0 = a1 = pose.apply(A.vertex(VertexId(a)).p);
  } else {
    a0 = pose.apply(A.edge_point(EdgeId(a), 0));
    a1 = pose.apply(A.edge_point(EdgeId(a), 1));
  }
  if (kb == K::kVertex) {
    b0 = b1 = B.vertex(VertexId(b)).p;
  } else {
    b0 = B.edge_point(EdgeId(b), 0);
    b1 = B.edge_point(EdgeId(b), 1);
  }
  return segment_segment(a0, a1, b0, b1);
}

}  // namespace cf
