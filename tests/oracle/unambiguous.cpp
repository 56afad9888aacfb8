#include "unambiguous.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace oracle {

double band_tolerance(const BandParams& p, double L) {
  return std::clamp(std::atan(p.eps / std::max(L, 1e-12)), p.min_tol, p.max_tol);
}

double seg_face_dist(const Poly& P, const Face& f, const Vec3& p, const Vec3& q) {
  const double hp = f.n.dot(p) - f.d, hq = f.n.dot(q) - f.d;
  // Through the plane at a point of the closed face: they meet.
  if (((hp <= 0 && hq >= 0) || (hp >= 0 && hq <= 0)) && hp != hq) {
    const Vec3 x = p + hp / (hp - hq) * (q - p);
    if (inside_loops(f.loops2, f.to2(x))) return 0;
  }
  // Otherwise the closest points are an end of the segment and the face, or the segment
  // and the face's boundary (an interior point of both is closest only when they meet or
  // run parallel, and then an end is as close).
  double d = std::min(point_face_dist(P, f, p), point_face_dist(P, f, q));
  for (int e : f.edges)
    d = std::min(d, seg_seg_dist(p, q, P.V[P.E[e].v0].p, P.V[P.E[e].v1].p, nullptr, nullptr));
  return d;
}

namespace {

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Parameters in [0, 1] where the 2D segment P->Q crosses the boundary of the loops.
std::vector<double> crossings(const std::vector<std::vector<Vec2>>& loops, const Vec2& P,
                              const Vec2& Q) {
  std::vector<double> ts{0.0, 1.0};
  const Vec2 D = Q - P;
  for (const auto& L : loops)
    for (std::size_t i = 0; i < L.size(); ++i) {
      const Vec2& a = L[i];
      const Vec2 E = L[(i + 1) % L.size()] - a;
      const double den = cross2(D, E);
      if (std::abs(den) <= 1e-15 * D.norm() * E.norm()) continue;
      const double t = cross2(a - P, E) / den, u = cross2(a - P, D) / den;
      if (u >= 0 && u <= 1 && t > 0 && t < 1) ts.push_back(t);
    }
  std::sort(ts.begin(), ts.end());
  return ts;
}

// The share of the segment P->Q from the first to the last of its points inside the closed
// loops (0 when none is).
double span_inside(const std::vector<std::vector<Vec2>>& loops, const Vec2& P, const Vec2& Q) {
  if ((Q - P).norm() <= 1e-12) return 0;
  const std::vector<double> ts = crossings(loops, P, Q);
  double first = 2, last = -1;
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    const double a = ts[i], b = ts[i + 1];
    if (b - a <= 1e-15) continue;
    if (inside_loops(loops, P + 0.5 * (a + b) * (Q - P))) {
      first = std::min(first, a);
      last = std::max(last, b);
    }
  }
  return last > first ? last - first : 0.0;
}

// The run time's extent of an edge (ends p, q, in the face's frame) over the face f: the part
// whose projection lies over the face, else the whole edge.
double line_extent(const Face& f, const Vec3& p, const Vec3& q) {
  const double len = (q - p).norm();
  const double s = span_inside(f.loops2, f.to2(p), f.to2(q));
  return s > 0 ? s * len : len;
}

struct Posed {
  std::vector<Vec3> pa;                      // A's vertices, world
  std::vector<Vec3> pb_a;                    // B's vertices, A's frame
  std::vector<Box3> av, ae, af, bv, be, bf;  // world boxes
};

}  // namespace

Ambiguity check_unambiguous(const Poly& A, const Poly& B, const Pose& X, const CfKey& cf,
                            const BandParams& p) {
  Ambiguity r;
  const double band = p.eps + p.dist_margin;
  char buf[256];
  auto fail = [&](const char* type, int a, int b, const char* what, double x, double y) {
    r.unambiguous = false;
    std::snprintf(buf, sizeof buf, "%s:%d:%d %s %.6g (limit %.6g)", type, a, b, what, x, y);
    r.why = buf;
  };
  // 1. the CF's e-e PCs cross at an angle beyond their near-parallel tolerance
  for (const Pc& pc : cf) {
    if (pc.type != PcType::EE) continue;
    const Vec3 ua = X.R * A.E[pc.a].dir, ub = B.E[pc.b].dir;
    const double ang = std::asin(std::min(1.0, ua.cross(ub).norm()));
    const double tol = std::max(band_tolerance(p, A.E[pc.a].len), band_tolerance(p, B.E[pc.b].len));
    if (!(ang > (1 + p.ang_margin) * tol)) {
      fail("e-e", pc.a, pc.b, "PC crossing angle", ang, (1 + p.ang_margin) * tol);
      return r;
    }
  }
  // 2. every pair the CF's PCs do not dominate
  Posed S;
  for (const Vertex& v : A.V) {
    S.pa.push_back(X.apply(v.p));
    Box3 b;
    b.add(S.pa.back());
    S.av.push_back(b);
  }
  for (const Edge& e : A.E) {
    Box3 b;
    b.add(S.pa[e.v0]);
    b.add(S.pa[e.v1]);
    S.ae.push_back(b);
  }
  for (const Face& f : A.F) {
    Box3 b;
    for (int v : f.verts) b.add(S.pa[v]);
    S.af.push_back(b);
  }
  for (const Vertex& v : B.V) {
    S.pb_a.push_back(X.inv(v.p));
    Box3 b;
    b.add(v.p);
    S.bv.push_back(b);
  }
  for (const Edge& e : B.E) {
    Box3 b;
    b.add(B.V[e.v0].p);
    b.add(B.V[e.v1].p);
    S.be.push_back(b);
  }
  for (const Face& f : B.F) S.bf.push_back(f.box);
  auto dominated = [&](int ka, int a, int kb, int b) {
    for (const Pc& pc : cf)
      if (A.in_closure(ka, a, kind_a(pc.type), pc.a) && B.in_closure(kb, b, kind_b(pc.type), pc.b))
        return true;
    return false;
  };
  const int nva = static_cast<int>(A.V.size()), nea = static_cast<int>(A.E.size()),
            nfa = static_cast<int>(A.F.size());
  const int nvb = static_cast<int>(B.V.size()), neb = static_cast<int>(B.E.size()),
            nfb = static_cast<int>(B.F.size());
  // v-f
  for (int va = 0; va < nva; ++va)
    for (int fb = 0; fb < nfb; ++fb) {
      if (S.av[va].dist(S.bf[fb]) > band || dominated(0, va, 2, fb)) continue;
      const double d = point_face_dist(B, B.F[fb], S.pa[va]);
      if (d <= band) {
        fail("v-f", va, fb, "distance", d, band);
        return r;
      }
    }
  // f-v (in A's frame)
  for (int fa = 0; fa < nfa; ++fa)
    for (int vb = 0; vb < nvb; ++vb) {
      if (S.af[fa].dist(S.bv[vb]) > band || dominated(2, fa, 0, vb)) continue;
      const double d = point_face_dist(A, A.F[fa], S.pb_a[vb]);
      if (d <= band) {
        fail("f-v", fa, vb, "distance", d, band);
        return r;
      }
    }
  // e-e
  for (int ea = 0; ea < nea; ++ea)
    for (int eb = 0; eb < neb; ++eb) {
      if (S.ae[ea].dist(S.be[eb]) > band || dominated(1, ea, 1, eb)) continue;
      const double d = seg_seg_dist(S.pa[A.E[ea].v0], S.pa[A.E[ea].v1], B.V[B.E[eb].v0].p,
                                    B.V[B.E[eb].v1].p, nullptr, nullptr);
      if (d <= band) {
        fail("e-e", ea, eb, "distance", d, band);
        return r;
      }
    }
  // e-f: within the band only when tilted beyond the tolerance
  for (int ea = 0; ea < nea; ++ea)
    for (int fb = 0; fb < nfb; ++fb) {
      if (S.ae[ea].dist(S.bf[fb]) > band || dominated(1, ea, 2, fb)) continue;
      const Face& f = B.F[fb];
      const Vec3& p0 = S.pa[A.E[ea].v0];
      const Vec3& p1 = S.pa[A.E[ea].v1];
      const double d = seg_face_dist(B, f, p0, p1);
      if (d > band) continue;
      const double ang = std::asin(std::min(1.0, std::abs((X.R * A.E[ea].dir).dot(f.n))));
      const double lim = (1 + p.ang_margin) * band_tolerance(p, line_extent(f, p0, p1));
      if (!(ang > lim)) {
        fail("e-f", ea, fb, "within the band at angle", ang, lim);
        return r;
      }
      ++r.leaning;
    }
  // f-e (in A's frame)
  for (int fa = 0; fa < nfa; ++fa)
    for (int eb = 0; eb < neb; ++eb) {
      if (S.af[fa].dist(S.be[eb]) > band || dominated(2, fa, 1, eb)) continue;
      const Face& f = A.F[fa];
      const Vec3& q0 = S.pb_a[B.E[eb].v0];
      const Vec3& q1 = S.pb_a[B.E[eb].v1];
      const double d = seg_face_dist(A, f, q0, q1);
      if (d > band) continue;
      const double ang = std::asin(std::min(1.0, std::abs(B.E[eb].dir.dot(X.R * f.n))));
      const double lim = (1 + p.ang_margin) * band_tolerance(p, line_extent(f, q0, q1));
      if (!(ang > lim)) {
        fail("f-e", fa, eb, "within the band at angle", ang, lim);
        return r;
      }
      ++r.leaning;
    }
  // f-f
  for (int fa = 0; fa < nfa; ++fa)
    for (int fb = 0; fb < nfb; ++fb) {
      if (S.af[fa].dist(S.bf[fb]) > band || dominated(2, fa, 2, fb)) continue;
      const Face& F = A.F[fa];
      const Face& G = B.F[fb];
      double d = kInf;
      for (int e : F.edges) d = std::min(d, seg_face_dist(B, G, S.pa[A.E[e].v0], S.pa[A.E[e].v1]));
      for (int e : G.edges)
        d = std::min(d, seg_face_dist(A, F, S.pb_a[B.E[e].v0], S.pb_a[B.E[e].v1]));
      if (d > band) continue;
      const Vec3 nA = X.R * F.n;
      const double c = -nA.dot(G.n);
      const double ang = std::acos(std::clamp(c, -1.0, 1.0));
      // The overlap of A's face projected on B's plane with B's face, its extent along the
      // tilt (the gradient of A's plane's height over B's plane).
      std::vector<std::vector<Vec2>> Q;
      for (const auto& loop : F.loops) {
        Q.emplace_back();
        for (int v : loop) Q.back().push_back(G.to2(S.pa[v]));
      }
      Vec2 g(nA.dot(G.u), nA.dot(G.w));
      g = g.norm() > 1e-12 ? Vec2(g.normalized()) : Vec2(1, 0);
      double lo = kInf, hi = -kInf;
      auto take = [&](const Vec2& x) {
        lo = std::min(lo, x.dot(g));
        hi = std::max(hi, x.dot(g));
      };
      for (const auto& L : Q)
        for (const Vec2& x : L)
          if (inside_loops(G.loops2, x)) take(x);
      for (const auto& L : G.loops2)
        for (const Vec2& x : L)
          if (inside_loops(Q, x)) take(x);
      for (const auto& L : Q)
        for (std::size_t i = 0; i < L.size(); ++i) {
          const Vec2& a = L[i];
          const Vec2& b = L[(i + 1) % L.size()];
          for (double t : crossings(G.loops2, a, b))
            if (t > 0 && t < 1) take(a + t * (b - a));
        }
      const double L = hi >= lo ? hi - lo : 0.0;
      const double tol = hi >= lo ? band_tolerance(p, L) : p.max_tol;
      const double lim = (1 + p.ang_margin) * tol;
      if (!(ang > lim)) {
        fail("f-f", fa, fb, "within the band at angle", ang, lim);
        return r;
      }
      ++r.leaning;
    }
  return r;
}

}  // namespace oracle
