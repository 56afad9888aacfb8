#pragma once
// Private: 2D polygons with holes as flat arrays, point location, clipping of a segment
// against a polygon, and the area and centroid of the intersection of two polygons by
// Green's theorem over the clipped boundaries. Allocation-free: the caller passes scratch.
//
// Why not Boost.Geometry here: its intersection allocates internally (turn lists, output
// rings), and the servo step must not allocate (docs/spec.md, section 7).
// tests/libcf/detector_test.cpp checks this code against boost::geometry::intersection.

#include "model/point_location.hpp"
#include "tolerances.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf::internal {

using Vec2 = Eigen::Vector2d;

/// Loops l in [0, num_loops): points pts[lb[l]] .. pts[lb[l + 1] - 1]; outer loop
/// counter-clockwise, holes clockwise.
struct Poly2 {
  const Vec2* pts = nullptr;
  const int* lb = nullptr;
  int num_loops = 0;
};

struct Loc2 {
  bool inside = false;                                    // even-odd over all loops
  double dist = std::numeric_limits<double>::infinity();  // to the boundary
  Vec2 closest = Vec2::Zero();
  Vec2 seg_dir = Vec2::Zero();  // direction (not normalised) of the nearest boundary segment
};

inline Loc2 locate(const Poly2& P, const Vec2& q) {
  PointLocator loc(q);
  for (int l = 0; l < P.num_loops; ++l) {
    const int b = P.lb[l], e = P.lb[l + 1];
    for (int i = b; i < e; ++i) loc.segment(P.pts[i], P.pts[i + 1 == e ? b : i + 1], l, i - b);
  }
  Loc2 out;
  out.inside = loc.inside;
  out.dist = loc.distance();
  out.closest = loc.closest;
  out.seg_dir = loc.seg_dir;
  return out;
}

inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// How a piece of the segment lying on P's boundary (within tol) is classified.
enum class OnBoundary { kInclude, kSameDirection, kExclude };

/// Calls piece(t0, t1) for every maximal piece [t0, t1] of segment a->b (t in [0, 1]) inside
/// P. `params` is scratch with room for 2 + 2 * (number of P's vertices) doubles.
template <class Piece>
void clip_segment(const Vec2& a, const Vec2& b, const Poly2& P, double tol, OnBoundary mode,
                  double* params, Piece&& piece) {
  const Vec2 r = b - a;
  const double rlen = r.norm();
  if (!(rlen > 0)) return;
  int n = 0;
  params[n++] = 0;
  params[n++] = 1;
  for (int l = 0; l < P.num_loops; ++l) {
    const int lb = P.lb[l], le = P.lb[l + 1];
    for (int i = lb; i < le; ++i) {
      const Vec2& c = P.pts[i];
      const Vec2& d = P.pts[i + 1 == le ? lb : i + 1];
      const Vec2 s = d - c;
      const Vec2 qa = c - a;
      const double denom = cross2(r, s);
      const double slen = s.norm();
      if (std::abs(denom) > internal::kRelativeRounding * rlen * slen) {
        const double t = cross2(qa, s) / denom;
        const double u = cross2(qa, r) / denom;
        if (u >= -internal::kRelativeRounding && u <= 1 + internal::kRelativeRounding && t > 0 &&
            t < 1)
          params[n++] = t;
      } else if (std::abs(cross2(qa, r)) / rlen <= tol) {
        // Collinear within tol: the overlap's ends split the segment.
        const double tc = qa.dot(r) / (rlen * rlen);
        const double td = (d - a).dot(r) / (rlen * rlen);
        if (tc > 0 && tc < 1) params[n++] = tc;
        if (td > 0 && td < 1) params[n++] = td;
      }
    }
  }
  // Insertion sort: few parameters in practice.
  for (int i = 1; i < n; ++i) {
    const double v = params[i];
    int j = i - 1;
    while (j >= 0 && params[j] > v) {
      params[j + 1] = params[j];
      --j;
    }
    params[j + 1] = v;
  }
  const double tmin = internal::kRelativeRounding;  // a segment parameter
  double run0 = -1, run1 = -1;                      // current run of included pieces, merged
  for (int i = 0; i + 1 < n; ++i) {
    const double t0 = params[i], t1 = params[i + 1];
    if (t1 - t0 <= tmin) continue;
    const Vec2 m = a + (0.5 * (t0 + t1)) * r;
    const Loc2 loc = locate(P, m);
    bool in;
    if (loc.dist <= tol) {
      in = mode == OnBoundary::kInclude ||
           (mode == OnBoundary::kSameDirection && loc.seg_dir.dot(r) > 0);
    } else {
      in = loc.inside;
    }
    if (in) {
      if (run0 >= 0 && std::abs(run1 - t0) <= tmin) {
        run1 = t1;
      } else {
        if (run0 >= 0) piece(run0, run1);
        run0 = t0;
        run1 = t1;
      }
    }
  }
  if (run0 >= 0) piece(run0, run1);
}

/// Area, centroid and the points' extent of the intersection of P and Q (both positively
/// oriented), accumulated from the boundary pieces of each inside the other. `visit(p)`
/// sees every vertex of the intersection's boundary (e.g. to take the deepest point).
struct Overlap2 {
  double area = 0;
  Vec2 centroid = Vec2::Zero();
  Vec2 lo = Vec2::Constant(std::numeric_limits<double>::infinity());
  Vec2 hi = Vec2::Constant(-std::numeric_limits<double>::infinity());
};

template <class Visit>
Overlap2 overlap(const Poly2& P, const Poly2& Q, double tol, double* params, Visit&& visit) {
  double a2 = 0, cx = 0, cy = 0;
  Overlap2 out;
  auto add = [&](const Vec2& p, const Vec2& q) {
    const double c = cross2(p, q);
    a2 += c;
    cx += (p.x() + q.x()) * c;
    cy += (p.y() + q.y()) * c;
    out.lo = out.lo.cwiseMin(p).cwiseMin(q);
    out.hi = out.hi.cwiseMax(p).cwiseMax(q);
    visit(p);
    visit(q);
  };
  auto edges_of = [&](const Poly2& S, const Poly2& T, OnBoundary mode) {
    for (int l = 0; l < S.num_loops; ++l) {
      const int lb = S.lb[l], le = S.lb[l + 1];
      for (int i = lb; i < le; ++i) {
        const Vec2& a = S.pts[i];
        const Vec2& b = S.pts[i + 1 == le ? lb : i + 1];
        const Vec2 r = b - a;
        clip_segment(a, b, T, tol, mode, params,
                     [&](double t0, double t1) { add(a + t0 * r, a + t1 * r); });
      }
    }
  };
  // Shared boundary running the same way is taken once (from P); opposite ways cancel.
  edges_of(P, Q, OnBoundary::kSameDirection);
  edges_of(Q, P, OnBoundary::kExclude);
  out.area = 0.5 * a2;
  if (a2 > 0) out.centroid = Vec2(cx, cy) / (3.0 * a2);
  return out;
}

/// clip_segment with OnBoundary::kInclude for a convex P (is_convex: one loop, counter-
/// clockwise): the piece [*t0, *t1] of segment a->b within tol of P, cut by each edge's
/// line moved out by tol (Cyrus-Beck). False when it is no longer than the general
/// routine's shortest piece (kRelativeRounding of the segment).
inline bool clip_segment_convex(const Vec2& a, const Vec2& b, const Poly2& P, double tol,
                                double* t0, double* t1) {
  const Vec2 r = b - a;
  double lo = 0, hi = 1;
  const int lb = P.lb[0], le = P.lb[1];
  for (int i = lb; i < le; ++i) {
    const Vec2& c = P.pts[i];
    const Vec2 s = P.pts[i + 1 == le ? lb : i + 1] - c;
    // Inside the moved line: f0 + t * fr >= 0 at a + t r.
    const double f0 = cross2(s, a - c) + tol * s.norm();
    const double fr = cross2(s, r);
    if (fr > 0)
      lo = std::max(lo, -f0 / fr);
    else if (fr < 0)
      hi = std::min(hi, -f0 / fr);
    else if (f0 < 0)
      return false;
    if (hi - lo <= internal::kRelativeRounding) return false;  // segment parameters
  }
  *t0 = lo;
  *t1 = hi;
  return true;
}

/// Is P one loop without reflex corners (collinear corners allowed, within rounding)?
inline bool is_convex(const Poly2& P) {
  if (P.num_loops != 1) return false;
  const int b = P.lb[0], e = P.lb[1], n = e - b;
  if (n < 3) return false;
  for (int i = 0; i < n; ++i) {
    const Vec2 u = P.pts[b + (i + 1) % n] - P.pts[b + i];
    const Vec2 v = P.pts[b + (i + 2) % n] - P.pts[b + (i + 1) % n];
    if (cross2(u, v) < -internal::kRelativeRounding * u.norm() * v.norm()) return false;
  }
  return true;
}

/// overlap() for two convex polygons (is_convex), by clipping Q by each edge of P
/// (Sutherland-Hodgman): the same area and centroid, and `visit(p)` sees every vertex of the
/// intersection. Far cheaper than the general routine on the few-sided faces of fine meshes.
/// `buf` is scratch of 2 * cap points, cap >= |P| + |Q|. Returns false, having visited
/// nothing, if rounding on a near-degenerate input would overflow it (then use overlap()).
template <class Visit>
bool overlap_convex(const Poly2& P, const Poly2& Q, Vec2* buf, int cap, Overlap2& o,
                    Visit&& visit) {
  const int pb = P.lb[0], np = P.lb[1] - pb;
  const int qb = Q.lb[0], nq = Q.lb[1] - qb;
  if (np + nq > cap) return false;
  Vec2* in = buf;
  Vec2* out = buf + cap;
  int n = nq;
  for (int i = 0; i < nq; ++i) in[i] = Q.pts[qb + i];
  for (int k = 0; k < np && n > 0; ++k) {
    const Vec2& c = P.pts[pb + k];
    const Vec2 edge = P.pts[pb + (k + 1) % np] - c;
    if (!(edge.squaredNorm() > 0)) continue;
    int m = 0;
    double s_prev = cross2(edge, in[n - 1] - c);
    for (int i = 0; i < n; ++i) {
      if (m + 2 > cap) return false;
      const Vec2& prev = in[i == 0 ? n - 1 : i - 1];
      const Vec2& cur = in[i];
      const double s_cur = cross2(edge, cur - c);  // >= 0: on the inner side of the edge
      if ((s_prev >= 0) != (s_cur >= 0))
        out[m++] = prev + (s_prev / (s_prev - s_cur)) * (cur - prev);
      if (s_cur >= 0) out[m++] = cur;
      s_prev = s_cur;
    }
    std::swap(in, out);
    n = m;
  }
  o = Overlap2();
  if (n < 3) return true;
  double a2 = 0, cx = 0, cy = 0;
  for (int i = 0; i < n; ++i) {
    const Vec2& p = in[i];
    const Vec2& q = in[i + 1 == n ? 0 : i + 1];
    const double c = cross2(p, q);
    a2 += c;
    cx += (p.x() + q.x()) * c;
    cy += (p.y() + q.y()) * c;
    o.lo = o.lo.cwiseMin(p);
    o.hi = o.hi.cwiseMax(p);
    visit(p);
  }
  o.area = 0.5 * a2;
  if (a2 > 0) o.centroid = Vec2(cx, cy) / (3.0 * a2);
  return true;
}

}  // namespace cf::internal
