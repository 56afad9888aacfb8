// Tangent cones of polyhedral elements and the exact test whether two cones with a common
// apex have intersecting interiors.
//
// Half-space vs anything and wedge vs wedge have closed forms (separating planes). The general
// case (vertex cones, possibly non-convex) uses the same characterisation as the polyhedron
// level, one dimension down: two cones overlap iff at some common boundary point other than the
// apex their local cones (half-spaces or edge wedges) overlap, or the boundary of one lies
// inside the other. The boundary cells of a cone are its rays (edges) and open sectors (faces).

#include "classify.hpp"

#include <cmath>

namespace oracle {

Cone face_cone(const Poly& P, int f, const Mat3& R) {
  Cone c;
  c.kind = 0;
  c.n = R * P.F[f].n;
  return c;
}

static Wedge wedge_of(const Poly& P, int e, const Mat3& R) {
  const Edge& E = P.E[e];
  Wedge w;
  w.d = R * E.dir;
  w.n1 = R * P.F[E.face[0]].n;
  w.n2 = R * P.F[E.face[1]].n;
  w.m1 = R * E.m[0];
  w.m2 = R * E.m[1];
  w.convex = E.convex;
  return w;
}

Cone edge_cone(const Poly& P, int e, const Mat3& R) {
  Cone c;
  c.kind = 1;
  c.w = wedge_of(P, e, R);
  return c;
}

Cone vertex_cone(const Poly& P, int v, const Mat3& R) {
  Cone c;
  c.kind = 2;
  for (const Corner& k : P.V[v].corners) {
    Sector s;
    s.n = R * P.F[k.face].n;
    s.r1 = R * k.r1;
    s.r2 = R * k.r2;
    s.span = k.span;
    c.sectors.push_back(s);
  }
  for (int e : P.V[v].edges) {
    const Edge& E = P.E[e];
    Vec3 d = E.v0 == v ? E.dir : Vec3(-E.dir);
    c.rays.emplace_back(R * d, wedge_of(P, e, R));
  }
  return c;
}

namespace {

Cone half(const Vec3& n) {
  Cone c;
  c.kind = 0;
  c.n = n;
  return c;
}
Cone wedge_cone(const Wedge& w) {
  Cone c;
  c.kind = 1;
  c.w = w;
  return c;
}

// Convex wedge W inside the closed half-space {n.x >= 0}?
bool half_wedge_overlap(const Vec3& n, const Wedge& W, double slack) {
  if (!W.convex) return true;
  if (std::abs(n.dot(W.d)) > slack) return true;
  if (n.dot(W.m1) < -slack || n.dot(W.m2) < -slack) return true;
  return false;
}

// Smallest value of n.x over the unit arc of sector S.
double sector_min(const Vec3& n, const Sector& S) {
  Vec3 q = S.n.cross(S.r1);
  double a = n.dot(S.r1), b = n.dot(q);
  double v0 = a, v1 = a * std::cos(S.span) + b * std::sin(S.span);
  double m = std::min(v0, v1);
  double phi = std::atan2(b, a) + kPi;  // minimiser of a cos + b sin
  phi = std::fmod(phi + 4 * kPi, 2 * kPi);
  if (phi <= S.span) m = std::min(m, -std::sqrt(a * a + b * b));
  return m;
}

bool half_vertex_overlap(const Vec3& n, const Cone& K, double slack) {
  for (const Sector& S : K.sectors)
    if (sector_min(n, S) < -slack) return true;
  // Boundary in {n.x >= 0}: K is inside it, or K contains the whole open other side.
  return point_in_cone(K, -n);
}

// Solid's angular range about axis a for wedge W (a parallel to W.d): start vector and span.
void wedge_arc(const Wedge& W, const Vec3& a, Vec3* start, double* span) {
  if (a.cross(W.m1).dot(W.n1) < 0) {
    *start = W.m1;
    *span = ccw_angle(W.m1, W.m2, a);
  } else {
    *start = W.m2;
    *span = ccw_angle(W.m2, W.m1, a);
  }
}

bool arcs_overlap(double spanX, double offset, double spanY, double slack) {
  if (offset < spanX - slack) return true;
  if (offset > 2 * kPi - spanY + slack) return true;
  return false;
}

bool wedge_wedge_overlap(const Wedge& X, const Wedge& Y, double slack) {
  Vec3 c = X.d.cross(Y.d);
  if (c.norm() > slack) {
    if (!X.convex || !Y.convex) return true;
    Vec3 s = c.normalized();
    for (double sg : {1.0, -1.0}) {
      Vec3 p = sg * s;
      if (p.dot(X.m1) <= slack && p.dot(X.m2) <= slack && p.dot(Y.m1) >= -slack &&
          p.dot(Y.m2) >= -slack)
        return false;
    }
    return true;
  }
  const Vec3& a = X.d;
  Vec3 sx, sy;
  double spx, spy;
  wedge_arc(X, a, &sx, &spx);
  wedge_arc(Y, a, &sy, &spy);
  double off = ccw_angle(sx, sy, a);
  return arcs_overlap(spx, off, spy, slack);
}

struct Cells {
  std::vector<std::pair<Vec3, Cone>> rays;
  std::vector<Sector> sectors;
};

Cells cells_of(const Cone& K) {
  Cells c;
  if (K.kind == 1) {
    const Wedge& W = K.w;
    c.rays.emplace_back(W.d, K);
    c.rays.emplace_back(-W.d, K);
    Sector s1;
    s1.n = W.n1;
    s1.r1 = W.n1.cross(W.d).dot(W.m1) > 0 ? W.d : Vec3(-W.d);
    s1.r2 = -s1.r1;
    s1.span = kPi;
    Sector s2;
    s2.n = W.n2;
    s2.r1 = W.n2.cross(W.d).dot(W.m2) > 0 ? W.d : Vec3(-W.d);
    s2.r2 = -s2.r1;
    s2.span = kPi;
    c.sectors = {s1, s2};
  } else {
    for (const auto& r : K.rays) c.rays.emplace_back(r.first, wedge_cone(r.second));
    c.sectors = K.sectors;
  }
  return c;
}

bool in_open_sector(const Vec3& x, const Sector& S, double slack) {
  if (std::abs(S.n.dot(x)) > slack) return false;
  double a = ccw_angle(S.r1, x, S.n);
  return a > slack && a < S.span - slack;
}

bool general_overlap(const Cone& X, const Cone& Y, double slack) {
  Cells cx = cells_of(X), cy = cells_of(Y);
  bool incidence = false;
  const double cs = std::cos(slack);
  for (const auto& rx : cx.rays)
    for (const auto& ry : cy.rays)
      if (rx.first.dot(ry.first) >= cs) {
        incidence = true;
        if (cones_overlap(rx.second, ry.second, slack)) return true;
      }
  for (const auto& rx : cx.rays)
    for (const Sector& s : cy.sectors)
      if (in_open_sector(rx.first, s, slack)) {
        incidence = true;
        if (cones_overlap(rx.second, half(s.n), slack)) return true;
      }
  for (const auto& ry : cy.rays)
    for (const Sector& s : cx.sectors)
      if (in_open_sector(ry.first, s, slack)) {
        incidence = true;
        if (cones_overlap(half(s.n), ry.second, slack)) return true;
      }
  for (const Sector& sx : cx.sectors)
    for (const Sector& sy : cy.sectors) {
      Vec3 c = sx.n.cross(sy.n);
      if (c.norm() > slack) {
        Vec3 l = c.normalized();
        for (double sg : {1.0, -1.0})
          if (in_open_sector(sg * l, sx, slack) && in_open_sector(sg * l, sy, slack)) return true;
      } else {
        Vec3 start;
        if (sx.n.dot(sy.n) > 0)
          start = sy.r1;
        else
          start = sy.r2;
        double off = ccw_angle(sx.r1, start, sx.n);
        if (arcs_overlap(sx.span, off, sy.span, slack)) {
          incidence = true;
          if (sx.n.dot(sy.n) > 0) return true;
        }
      }
    }
  if (!incidence) {
    if (!cx.rays.empty() && point_in_cone(Y, cx.rays[0].first)) return true;
    if (!cy.rays.empty() && point_in_cone(X, cy.rays[0].first)) return true;
  }
  return false;
}

}  // namespace

bool point_in_cone(const Cone& K, const Vec3& u) {
  if (K.kind == 0) return K.n.dot(u) < 0;
  if (K.kind == 1) {
    bool a = K.w.n1.dot(u) < 0, b = K.w.n2.dot(u) < 0;
    return K.w.convex ? (a && b) : (a || b);
  }
  // Vertex cone: count crossings of the sectors along the segment from u to a direction just
  // outside the cone (above the middle of one of its sectors); a ray to infinity would not do,
  // since a ray may end inside an unbounded cone.
  for (const Sector& S0 : K.sectors) {
    double h = 0.5 * S0.span;
    Vec3 b = S0.r1 * std::cos(h) + S0.n.cross(S0.r1) * std::sin(h);
    Vec3 out = (b + 1e-3 * S0.n).normalized();
    if ((u + out).norm() < 1e-3) continue;  // segment would pass the apex
    int count = 0;
    bool bad = false;
    for (const Sector& S : K.sectors) {
      double n0 = S.n.dot(u), n1 = S.n.dot(out);
      if (std::abs(n0) < 1e-12) {
        // u lies in the sector's plane: on the sector means on the boundary (not inside)
        double a = ccw_angle(S.r1, u, S.n);
        if (a <= S.span + 1e-9 || a >= 2 * kPi - 1e-9) return false;
        continue;
      }
      if (std::abs(n1) < 1e-12) {
        bad = true;
        break;
      }
      if ((n0 > 0) == (n1 > 0)) continue;
      double t = n0 / (n0 - n1);
      Vec3 x = u + t * (out - u);
      if (x.norm() < 1e-6) {
        bad = true;
        break;
      }
      double a = ccw_angle(S.r1, x, S.n);
      if (a < 1e-9 || std::abs(a - S.span) < 1e-9 || a > 2 * kPi - 1e-9) {
        bad = true;
        break;
      }
      if (a < S.span) ++count;
    }
    if (!bad) return count % 2 == 1;
  }
  return false;
}

bool cones_overlap(const Cone& X, const Cone& Y, double slack) {
  if (X.kind == 0 && Y.kind == 0) return !(X.n.dot(Y.n) <= -std::cos(slack));
  if (X.kind == 0 && Y.kind == 1) return half_wedge_overlap(X.n, Y.w, slack);
  if (X.kind == 1 && Y.kind == 0) return half_wedge_overlap(Y.n, X.w, slack);
  if (X.kind == 0 && Y.kind == 2) return half_vertex_overlap(X.n, Y, slack);
  if (X.kind == 2 && Y.kind == 0) return half_vertex_overlap(Y.n, X, slack);
  if (X.kind == 1 && Y.kind == 1) return wedge_wedge_overlap(X.w, Y.w, slack);
  return general_overlap(X, Y, slack);
}

}  // namespace oracle
