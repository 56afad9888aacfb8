#pragma once
// The cheap rejections of detection: necessary conditions of each type's exact test (same
// tolerances, looser or equal), so that most pairs the boxes pass are turned away before
// an exact test loads the features (on 2,000-face spheres about 1 pair in 80 is a contact).
// They read compact copies of the planes and segments (a few contiguous bytes rather than
// the polyhedra's feature records): B's fixed, A's posed on first use per pose. With
// kCertify a pair turned away also gets its certificate (exact.hpp, Cert).

#include "exact.hpp"
#include "tolerances.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace cf::internal {

class CheapRejections {
 public:
  explicit CheapRejections(const PairTables& t) {
    for (const Face& F : t.b->faces()) plane_b.push_back({F.normal, F.offset, 0});
    for (const Edge& E : t.b->edges()) seg_b.push_back({t.b->vertex(E.v0).p, E.dir, E.length, 0});
    plane_a.resize(t.a->num_faces());
    seg_a.resize(t.a->num_edges());
  }

  // With kCertify, a pair turned away also gets its certificate in *ct. A height over B's
  // plane moves at most as far as A's points. A unit vector of A turns by at most
  // |R1 - R0|_F, so a dot product's margin d is a rotational certificate d. A height over
  // A's plane of B's point q is (R n_A).(q - o) up to a constant (o: A's origin posed), so
  // it moves by at most the motion bound times max(1, |q - o| / r_a). Where two conditions
  // fail, either one keeps the pair away.
  template <bool kCertify>
  __attribute__((always_inline)) bool may_touch(const PairTables& t, PosedA& p, ElementKind ka,
                                                int ia, ElementKind kb, int ib, Cert* ct) {
    using K = ElementKind;
    if (ka == K::kVertex) {  // v-f
      const Plane& B = plane_b[static_cast<std::size_t>(ib)];
      const double h = B.n.dot(p.world(*t.a, VertexId(ia))) - B.off;
      if (near_band(t, h)) return true;
      if constexpr (kCertify) ct->lin = band_gap(t, h, h) - t.geo_tol;
      return false;
    }
    if (ka == K::kEdge) {
      const Seg& A = posed_seg_a(t, p, ia);
      if (kb == K::kFace) {  // e-f
        const Plane& B = plane_b[static_cast<std::size_t>(ib)];
        const double tilt =
            std::abs(A.dir.dot(B.n)) - (t.sin_max_tol + internal::kRelativeRounding);
        if constexpr (!kCertify) {
          return tilt <= 0 && segment_in_band(t, A.p0, A.dir, A.len, B.n, B.off);
        } else {
          const double h0 = B.n.dot(A.p0) - B.off, h1 = h0 + A.len * B.n.dot(A.dir);
          const double gap = band_gap(t, std::min(h0, h1), std::max(h0, h1));
          if (tilt <= 0 && gap <= 0) return true;
          ct->lin = gap - t.geo_tol;
          ct->rot = tilt - t.geo_tol;
          return false;
        }
      }
      // e-e: not near-parallel, and the lines within the band of each other.
      const Seg& B = seg_b[static_cast<std::size_t>(ib)];
      const Vec3 n = A.dir.cross(B.dir);
      const double sn = n.norm();
      const double parallel = std::max(t.sin_tol_edge_a[static_cast<std::size_t>(ia)],
                                       t.sin_tol_edge_b[static_cast<std::size_t>(ib)]) -
                              internal::kRelativeRounding - sn;
      if (parallel >= 0) {
        // n turns by at most as much as A's direction.
        if constexpr (kCertify) ct->rot = parallel - t.geo_tol;
        return false;
      }
      const Vec3 r = A.p0 - B.p0;
      const double band = std::max(t.eps, t.depth) + t.geo_tol;
      const double apart = std::abs(n.dot(r)) - band * sn;
      if (apart > 0) {
        // n.r moves by at most |dn| |r| + |dr| (|n| <= 1, |dn| <= bound / t.r_a, |dr| <=
        // bound), band sn by band |dn|.
        if constexpr (kCertify) ct->lin = apart / (1 + (r.norm() + band) / t.r_a) - t.geo_tol;
        return false;
      }
      // The lines' closest points (as in ee) beyond the segments by at most t.in_plane.
      const double bb = A.dir.dot(B.dir), c = A.dir.dot(r), f = B.dir.dot(r);
      const double den = 1 - bb * bb;
      const double s = (bb * f - c) / den, u = (f - bb * c) / den;
      if (std::max({0.0, -s, s - A.len}) + std::max({0.0, -u, u - B.len}) <= t.in_plane + t.geo_tol)
        return true;
      // No certificate: the closest points move too fast near parallel.
      return false;
    }
    const Plane& A = posed_plane_a(t, p, ia);
    if (kb == K::kFace) {  // f-f
      const double tilt = t.cos_max_tol - internal::kRelativeRounding +
                          A.n.dot(plane_b[static_cast<std::size_t>(ib)].n);
      if (tilt <= 0) return true;
      if constexpr (kCertify) ct->rot = tilt - t.geo_tol;
      return false;
    }
    if (kb == K::kEdge) {  // f-e
      const Seg& B = seg_b[static_cast<std::size_t>(ib)];
      const double tilt = std::abs(A.n.dot(B.dir)) - (t.sin_max_tol + internal::kRelativeRounding);
      if constexpr (!kCertify) {
        return tilt <= 0 && segment_in_band(t, B.p0, B.dir, B.len, A.n, A.off);
      } else {
        const double h0 = A.n.dot(B.p0) - A.off, h1 = h0 + B.len * A.n.dot(B.dir);
        const double gap = band_gap(t, std::min(h0, h1), std::max(h0, h1));
        if (tilt <= 0 && gap <= 0) return true;
        const double reach = std::max((B.p0 - p.origin_posed).norm(),
                                      (B.p0 + B.len * B.dir - p.origin_posed).norm());
        ct->lin = t.seen_from_a(gap, reach);
        ct->rot = tilt - t.geo_tol;
        return false;
      }
    }
    const Vec3& q = t.b->vertex(VertexId(ib)).p;  // f-v
    const double h = A.n.dot(q) - A.off;
    if (near_band(t, h)) return true;
    if constexpr (kCertify) ct->lin = t.seen_from_a(band_gap(t, h, h), (q - p.origin_posed).norm());
    return false;
  }

 private:
  struct Plane {
    Vec3 n;          // unit outward normal, B's frame
    double off = 0;  // mm: plane { x : n . x == off }
    std::uint64_t stamp = 0;
  };
  struct Seg {
    Vec3 p0, dir;    // mm, B's frame; dir unit
    double len = 0;  // mm
    std::uint64_t stamp = 0;
  };
  const Plane& posed_plane_a(const PairTables& t, PosedA& p, int f) {
    Plane& P = plane_a[static_cast<std::size_t>(f)];
    if (P.stamp != p.stamp) {
      const Face& F = t.a->faces()[static_cast<std::size_t>(f)];
      P.n = p.pose.R_BA * F.normal;
      P.off = F.offset + P.n.dot(p.pose.t_BA);
      P.stamp = p.stamp;
    }
    return P;
  }
  const Seg& posed_seg_a(const PairTables& t, PosedA& p, int e) {
    Seg& S = seg_a[static_cast<std::size_t>(e)];
    if (S.stamp != p.stamp) {
      const Edge& E = t.a->edges()[static_cast<std::size_t>(e)];
      S.p0 = p.world(*t.a, E.v0);
      S.dir = p.pose.R_BA * E.dir;
      S.len = E.length;
      S.stamp = p.stamp;
    }
    return S;
  }
  // Does the segment reach the band of the plane (n, off)?
  static bool segment_in_band(const PairTables& t, const Vec3& p0, const Vec3& dir, double len,
                              const Vec3& n, double off) {
    const double h0 = n.dot(p0) - off, h1 = h0 + len * n.dot(dir);
    return std::min(h0, h1) <= t.eps + t.geo_tol && std::max(h0, h1) >= -t.depth - t.geo_tol;
  }
  // in_band with room for the rounding of a differently ordered computation.
  static bool near_band(const PairTables& t, double d) {
    return d <= t.eps + t.geo_tol && d >= -t.depth - t.geo_tol;
  }
  // How far heights h0 <= h1 (or one height) lie outside near_band's band.
  static double band_gap(const PairTables& t, double lo, double hi) {
    return std::max(lo - t.eps - t.geo_tol, -t.depth - t.geo_tol - hi);
  }

  std::vector<Plane> plane_b, plane_a;
  std::vector<Seg> seg_b, seg_a;
};

}  // namespace cf::internal
