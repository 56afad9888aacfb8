#include "classify.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace oracle {

// ---------------------------------------------------------------------------------------
// names and small helpers
// ---------------------------------------------------------------------------------------

const char* type_name(PcType t) {
  switch (t) {
    case PcType::FF:
      return "f-f";
    case PcType::EF:
      return "e-f";
    case PcType::FE:
      return "f-e";
    case PcType::VF:
      return "v-f";
    case PcType::FV:
      return "f-v";
    case PcType::EE:
      return "e-e";
    case PcType::VV:
      return "v-v";
    case PcType::VE:
      return "v-e";
    case PcType::EV:
      return "e-v";
    case PcType::EEC:
      return "e-e(collinear)";
  }
  return "?";
}

bool parse_type(const std::string& s, PcType* t) {
  static const PcType all[] = {PcType::FF, PcType::EF, PcType::FE,
                               PcType::VF, PcType::FV, PcType::EE};
  for (PcType x : all)
    if (s == type_name(x)) {
      *t = x;
      return true;
    }
  return false;
}

int kind_a(PcType t) {
  switch (t) {
    case PcType::FF:
    case PcType::FE:
    case PcType::FV:
      return 2;
    case PcType::EF:
    case PcType::EE:
    case PcType::EV:
    case PcType::EEC:
      return 1;
    default:
      return 0;
  }
}
int kind_b(PcType t) {
  switch (t) {
    case PcType::FF:
    case PcType::EF:
    case PcType::VF:
      return 2;
    case PcType::FE:
    case PcType::EE:
    case PcType::VE:
    case PcType::EEC:
      return 1;
    default:
      return 0;
  }
}

std::string key_string(const CfKey& k) {
  std::string s;
  for (const Pc& p : k) {
    if (!s.empty()) s += ' ';
    s += std::string(type_name(p.type)) + ":" + std::to_string(p.a) + ":" + std::to_string(p.b);
  }
  return s;
}

std::string pose_string(const Pose& X) {
  Eigen::Quaterniond q(X.R);
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "R=[[%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g],[%.17g,%.17g,%.17g]] t=[%.17g,%.17g,%.17g] "
      "(quaternion w,x,y,z = %.12g,%.12g,%.12g,%.12g)",
      X.R(0, 0), X.R(0, 1), X.R(0, 2), X.R(1, 0), X.R(1, 1), X.R(1, 2), X.R(2, 0), X.R(2, 1),
      X.R(2, 2), X.t.x(), X.t.y(), X.t.z(), q.w(), q.x(), q.y(), q.z());
  return buf;
}

Tolerances default_tolerances(const Poly& A, const Poly& B) {
  Tolerances t;
  t.len = 1e-7 * std::min(A.diag, B.diag);
  t.ang = 1e-6;
  t.gap = 100 * t.len;
  return t;
}

Vec3 normal_into_a(const Poly& B, const Touch& t) {
  Vec3 m = t.normal;
  if (t.type == PcType::FE || t.type == PcType::FV) m = -m;
  if (t.type == PcType::EE) {
    const Edge& eb = B.E[t.b];
    if (m.dot(B.F[eb.face[0]].n + B.F[eb.face[1]].n) < 0) m = -m;
  }
  return m;
}

CfKey Verdict::key() const {
  CfKey k;
  for (int i : pcs) k.push_back(Pc{touches[i].type, touches[i].a, touches[i].b});
  std::sort(k.begin(), k.end());
  return k;
}

std::string Verdict::describe() const {
  std::ostringstream o;
  if (penetrating) {
    o << "penetrating (" << why << ")";
    return o.str();
  }
  if (touches.empty()) return "free (no contact)";
  CfKey k;
  for (int i : pcs) k.push_back(Pc{touches[i].type, touches[i].a, touches[i].b});
  std::sort(k.begin(), k.end());
  o << "PCs {" << key_string(k) << "}";
  if (degenerate) o << " [degenerate PC]";
  if (too_many) o << " [more than 3 PCs]";
  if (same_plane) o << " [two PCs share a contact plane]";
  for (const auto& u : uncertain) o << " [uncertain: " << u << "]";
  char buf[64];
  std::snprintf(buf, sizeof buf, " clearance %.3g mm", clearance);
  o << buf;
  if (!clearance_what.empty()) o << " (" << clearance_what << ")";
  return o.str();
}

namespace {

using Interval = std::pair<double, double>;

// {s : a s^2 + b s + c <= 0}, a >= 0. Returns false when empty; [-inf, inf] when everything.
bool quad_le0(double a, double b, double c, Interval* out) {
  const double scale = std::abs(a) + std::abs(b) + std::abs(c);
  if (a <= 1e-15 * scale) {
    if (std::abs(b) <= 1e-15 * scale) {
      if (c <= 0) {
        *out = {-kInf, kInf};
        return true;
      }
      return false;
    }
    double r = -c / b;
    *out = b > 0 ? Interval{-kInf, r} : Interval{r, kInf};
    return true;
  }
  double disc = b * b - 4 * a * c;
  if (disc < 0) return false;
  double sq = std::sqrt(disc);
  *out = {(-b - sq) / (2 * a), (-b + sq) / (2 * a)};
  return true;
}

// Parameters s in R of x(s) = p + s (q - p) within distance r of segment [a, b] (one interval).
bool capsule_interval(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, double r,
                      Interval* out) {
  Vec3 D = q - p;
  double lo = kInf, hi = -kInf;
  auto take = [&](const Interval& iv) {
    if (iv.first > iv.second) return;
    lo = std::min(lo, iv.first);
    hi = std::max(hi, iv.second);
  };
  for (const Vec3* c : {&a, &b}) {
    Vec3 w = p - *c;
    Interval iv;
    if (quad_le0(D.squaredNorm(), 2 * D.dot(w), w.squaredNorm() - r * r, &iv)) take(iv);
  }
  Vec3 ab = b - a;
  double L = ab.norm();
  if (L > 0) {
    Vec3 e = ab / L;
    Vec3 w = p - a;
    Vec3 De = D.cross(e), we = w.cross(e);
    Interval cyl;
    if (quad_le0(De.squaredNorm(), 2 * De.dot(we), we.squaredNorm() - r * r, &cyl)) {
      // projection parameter (x(s) - a).e in [0, L]: linear in s
      double k0 = w.dot(e), k1 = D.dot(e);
      Interval slab;
      if (std::abs(k1) < 1e-300) {
        if (k0 < 0 || k0 > L)
          slab = {1, 0};
        else
          slab = {-kInf, kInf};
      } else {
        double s1 = (0 - k0) / k1, s2 = (L - k0) / k1;
        slab = {std::min(s1, s2), std::max(s1, s2)};
      }
      take({std::max(cyl.first, slab.first), std::min(cyl.second, slab.second)});
    }
  }
  if (lo > hi) return false;
  *out = {lo, hi};
  return true;
}

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Parameters in [0,1] of the 2D segment P->Q that lie inside the loops (even-odd).
std::vector<Interval> clip_to_loops(const std::vector<std::vector<Vec2>>& loops, const Vec2& P,
                                    const Vec2& Q) {
  std::vector<double> ts{0.0, 1.0};
  Vec2 D = Q - P;
  for (const auto& L : loops)
    for (std::size_t i = 0; i < L.size(); ++i) {
      const Vec2& a = L[i];
      const Vec2& b = L[(i + 1) % L.size()];
      Vec2 E = b - a;
      double den = cross2(D, E);
      if (std::abs(den) <= 1e-15 * D.norm() * E.norm()) continue;
      double t = cross2(a - P, E) / den;
      double u = cross2(a - P, D) / den;
      if (u >= -1e-12 && u <= 1 + 1e-12 && t > 0 && t < 1) ts.push_back(t);
    }
  std::sort(ts.begin(), ts.end());
  std::vector<Interval> out;
  for (std::size_t i = 0; i + 1 < ts.size(); ++i) {
    double a = ts[i], b = ts[i + 1];
    if (b - a <= 1e-15) continue;
    Vec2 m = P + 0.5 * (a + b) * D;
    if (inside_loops(loops, m)) {
      if (!out.empty() && std::abs(out.back().second - a) <= 1e-15)
        out.back().second = b;
      else
        out.emplace_back(a, b);
    }
  }
  return out;
}

std::vector<Interval> subtract(const std::vector<Interval>& in, std::vector<Interval> cuts) {
  std::sort(cuts.begin(), cuts.end());
  std::vector<Interval> out;
  for (Interval iv : in) {
    double cur = iv.first;
    for (const Interval& c : cuts) {
      if (c.second <= cur) continue;
      if (c.first >= iv.second) break;
      if (c.first > cur) out.emplace_back(cur, std::min(c.first, iv.second));
      cur = std::max(cur, c.second);
      if (cur >= iv.second) break;
    }
    if (cur < iv.second) out.emplace_back(cur, iv.second);
  }
  return out;
}

struct EFResult {
  int kind = 0;  // 0 none, 1 in the plane (line contact), 2 transversal (penetration)
  double extent = 0;
  double s0 = 0, s1 = 0;  // longest in-plane piece
  double sc = 0;          // transversal: where
};

// Open edge p->q against the open face f (all in f's frame).
EFResult edge_face_test(const Poly& P, const Face& f, const Vec3& p, const Vec3& q, double tol) {
  EFResult r;
  double h0 = f.n.dot(p) - f.d, h1 = f.n.dot(q) - f.d;
  if (std::min(h0, h1) > tol || std::max(h0, h1) < -tol) return r;
  double L = (q - p).norm();
  Vec2 P2 = f.to2(p), Q2 = f.to2(q);
  std::vector<Interval> ins;
  if ((Q2 - P2).norm() < 1e-12 * L) {
    if (inside_loops(f.loops2, P2)) ins.emplace_back(0.0, 1.0);
  } else {
    ins = clip_to_loops(f.loops2, P2, Q2);
  }
  if (ins.empty()) return r;
  std::vector<Interval> cuts{{-1.0, tol / L}, {1.0 - tol / L, 2.0}};
  // Where the edge's foot on the plane is within tol of the face's boundary, the edge meets
  // the boundary, not the open face: an edge nearly parallel to a boundary edge that it crosses
  // (an e-e at a small angle) rises out of the plane within tol over a stretch as long as tol
  // over the angle, always beside the boundary (within tol in the plane, so within sqrt(2) tol
  // in space).
  const Vec3 pf = f.to3(P2), qf = f.to3(Q2);
  for (int e : f.edges) {
    Interval iv;
    const Vec3 a = f.to3(f.to2(P.V[P.E[e].v0].p)), b = f.to3(f.to2(P.V[P.E[e].v1].p));
    if (capsule_interval(pf, qf, a, b, tol, &iv)) cuts.push_back(iv);
  }
  std::vector<Interval> rem = subtract(ins, cuts);
  double best = -1;
  for (const Interval& iv : rem) {
    double a = iv.first, b = iv.second;
    if ((b - a) * L <= tol)
      continue;  // a piece shorter than tol is rounding at a neighbour's contact
    double ha = h0 + a * (h1 - h0), hb = h0 + b * (h1 - h0);
    if (std::max(std::abs(ha), std::abs(hb)) <= tol) {
      if (r.kind < 1) r.kind = 1;
      r.extent += (b - a) * L;
      if (b - a > best) {
        best = b - a;
        r.s0 = a;
        r.s1 = b;
      }
    }
  }
  // Transversal: the open edge crosses the plane at a point of the open face (farther than tol
  // from its boundary and from the edge's ends) and gets deeper than tol before it can leave
  // the ball around that point where B is the half-space below the face.
  if ((h0 < -tol && h1 > tol) || (h0 > tol && h1 < -tol)) {
    double sc = h0 / (h0 - h1);
    Vec3 c = p + sc * (q - p);
    if ((c - p).norm() > tol && (c - q).norm() > tol && inside_loops(f.loops2, f.to2(c))) {
      double m = kInf;
      for (int e : f.edges) m = std::min(m, point_seg_dist(c, P.V[P.E[e].v0].p, P.V[P.E[e].v1].p));
      double sina = std::abs(h1 - h0) / L;
      double reach = std::min({m, sc * L, (1 - sc) * L});
      if (m > tol && reach * sina > tol) {
        r.kind = 2;
        r.sc = sc;
      }
    }
  }
  return r;
}

struct EEResult {
  int kind = 0;  // 0 none, 1 crossing, 2 collinear overlap
  Vec3 point = Vec3::Zero();
  double sin_angle = 1;
  double extent = 0;
  bool near_end = false;
};

EEResult edge_edge_test(const Vec3& a0, const Vec3& a1, const Vec3& b0, const Vec3& b1,
                        double tol) {
  EEResult r;
  double s, t;
  double dist = seg_seg_dist(a0, a1, b0, b1, &s, &t);
  if (dist > tol) return r;
  Vec3 dA = a1 - a0, dB = b1 - b0;
  double LA = dA.norm(), LB = dB.norm();
  Vec3 uA = dA / LA, uB = dB / LB;
  r.sin_angle = uA.cross(uB).norm();
  if (r.sin_angle < 1e-3) {
    double p0 = (b0 - a0).dot(uA), p1 = (b1 - a0).dot(uA);
    double lo = std::max(0.0, std::min(p0, p1)), hi = std::min(LA, std::max(p0, p1));
    if (hi - lo > 2 * tol) {
      Vec3 xl = a0 + lo * uA, xh = a0 + hi * uA;
      auto dline = [&](const Vec3& x) { return (x - b0 - uB * (x - b0).dot(uB)).norm(); };
      if (dline(xl) <= tol && dline(xh) <= tol) {
        r.kind = 2;
        r.extent = hi - lo;
        r.point = 0.5 * (xl + xh);
        return r;
      }
    }
  }
  if (r.sin_angle <= 1e-12) return r;
  Vec3 xa = a0 + s * dA, xb = b0 + t * dB;
  if ((xa - a0).norm() <= tol || (xa - a1).norm() <= tol || (xb - b0).norm() <= tol ||
      (xb - b1).norm() <= tol)
    return r;
  r.kind = 1;
  r.point = 0.5 * (xa + xb);
  double m = std::min({(xa - a0).norm(), (xa - a1).norm(), (xb - b0).norm(), (xb - b1).norm()});
  r.near_end = m < 2 * tol / r.sin_angle || r.sin_angle < 1e-4;
  return r;
}

// Sutherland-Hodgman: convex polygon clipped by a CCW triangle.
double clip_area(std::vector<Vec2> poly, const Vec2 tri[3]) {
  for (int k = 0; k < 3 && !poly.empty(); ++k) {
    const Vec2& a = tri[k];
    const Vec2& b = tri[(k + 1) % 3];
    Vec2 e = b - a;
    std::vector<Vec2> out;
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& p = poly[i];
      const Vec2& q = poly[(i + 1) % n];
      double sp = cross2(e, p - a), sq = cross2(e, q - a);
      if (sp >= 0) out.push_back(p);
      if ((sp >= 0) != (sq >= 0)) {
        double t = sp / (sp - sq);
        out.push_back(p + t * (q - p));
      }
    }
    poly.swap(out);
  }
  double A = 0;
  for (std::size_t i = 0; i < poly.size(); ++i) A += cross2(poly[i], poly[(i + 1) % poly.size()]);
  return A / 2;
}

// Area of the intersection of two polygon regions (loops with even-odd/orientation), by the
// signed fan decomposition 1_P = sum_i s_i 1_{T_i}.
double overlap_area(const std::vector<std::vector<Vec2>>& P,
                    const std::vector<std::vector<Vec2>>& Q) {
  Vec2 oP = P[0][0], oQ = Q[0][0];
  struct Tri {
    Vec2 v[3];
    double s;
  };
  auto fan = [](const std::vector<std::vector<Vec2>>& loops, const Vec2& o) {
    std::vector<Tri> T;
    for (const auto& L : loops)
      for (std::size_t i = 0; i < L.size(); ++i) {
        const Vec2& a = L[i];
        const Vec2& b = L[(i + 1) % L.size()];
        double c = cross2(a - o, b - o);
        if (std::abs(c) <= 1e-300) continue;
        Tri t;
        if (c > 0) {
          t.v[0] = o;
          t.v[1] = a;
          t.v[2] = b;
          t.s = 1;
        } else {
          t.v[0] = o;
          t.v[1] = b;
          t.v[2] = a;
          t.s = -1;
        }
        T.push_back(t);
      }
    return T;
  };
  std::vector<Tri> TP = fan(P, oP), TQ = fan(Q, oQ);
  double total = 0;
  for (const Tri& a : TP)
    for (const Tri& b : TQ) {
      std::vector<Vec2> poly{a.v[0], a.v[1], a.v[2]};
      total += a.s * b.s * clip_area(poly, b.v);
    }
  return std::abs(total);
}

bool seg2_cross(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b, Vec2* x) {
  Vec2 D = q - p, E = b - a;
  double den = cross2(D, E);
  if (std::abs(den) <= 1e-15 * D.norm() * E.norm()) return false;
  double t = cross2(a - p, E) / den, u = cross2(a - p, D) / den;
  if (t < 0 || t > 1 || u < 0 || u > 1) return false;
  *x = p + t * D;
  return true;
}

}  // namespace

// ---------------------------------------------------------------------------------------

bool point_in_solid(const Poly& P, const Vec3& x) {
  static const Vec3 dirs[] = {
      Vec3(0.31, 0.77, 0.56).normalized(),    Vec3(-0.62, 0.21, 0.75).normalized(),
      Vec3(0.13, -0.91, 0.39).normalized(),   Vec3(0.83, 0.35, -0.43).normalized(),
      Vec3(-0.27, -0.44, -0.86).normalized(), Vec3(0.57, -0.58, 0.59).normalized()};
  const double eps = 1e-9 * P.diag;
  for (const Vec3& w : dirs) {
    int count = 0;
    bool bad = false;
    for (const Face& f : P.F) {
      double den = f.n.dot(w), num = f.d - f.n.dot(x);
      if (std::abs(den) < 1e-9) {
        if (std::abs(num) < eps) {
          bad = true;
          break;
        }
        continue;
      }
      double s = num / den;
      if (s <= 0) continue;
      Vec2 h = f.to2(x + s * w);
      if (dist_to_loops(f.loops2, h) < eps) {
        bad = true;
        break;
      }
      if (inside_loops(f.loops2, h)) ++count;
    }
    if (!bad) return count % 2 == 1;
  }
  return false;
}

struct Classifier::Scene {
  Pose X;
  std::vector<Vec3> pa;    // A's vertices, world
  std::vector<Vec3> pb_a;  // B's vertices in A's frame
  std::vector<Box3> av, ae, af;
  std::vector<Vec3> an;  // A's face normals, world
  std::vector<double> ad;
};

Classifier::Classifier(const Poly& A, const Poly& B, Tolerances tol) : A_(A), B_(B), tol_(tol) {
  for (const auto& v : B_.V) {
    Box3 b;
    b.add(v.p);
    bv_.push_back(b);
  }
  for (const auto& e : B_.E) {
    Box3 b;
    b.add(B_.V[e.v0].p);
    b.add(B_.V[e.v1].p);
    be_.push_back(b);
  }
  for (const auto& f : B_.F) bf_.push_back(f.box);
}

void Classifier::touches(const Scene& S, Verdict& V) const {
  const double tol = tol_.len;
  const Poly& A = A_;
  const Poly& B = B_;
  const Mat3& R = S.X.R;
  auto add = [&](Touch t) { V.touches.push_back(t); };
  // v-v, v-e, v-f (A's vertices)
  for (std::size_t va = 0; va < A.V.size(); ++va) {
    const Vec3& x = S.pa[va];
    for (std::size_t vb = 0; vb < B.V.size(); ++vb) {
      if (S.av[va].dist(bv_[vb]) > tol) continue;
      if ((x - B.V[vb].p).norm() <= tol) {
        Touch t{PcType::VV, (int)va, (int)vb};
        t.p0 = x;
        add(t);
      }
    }
    for (std::size_t eb = 0; eb < B.E.size(); ++eb) {
      if (S.av[va].dist(be_[eb]) > tol) continue;
      const Vec3& b0 = B.V[B.E[eb].v0].p;
      const Vec3& b1 = B.V[B.E[eb].v1].p;
      if (point_seg_dist(x, b0, b1) <= tol && (x - b0).norm() > tol && (x - b1).norm() > tol) {
        Touch t{PcType::VE, (int)va, (int)eb};
        t.p0 = x;
        add(t);
      }
    }
    for (std::size_t fb = 0; fb < B.F.size(); ++fb) {
      if (S.av[va].dist(bf_[fb]) > tol) continue;
      const Face& f = B.F[fb];
      double h = f.n.dot(x) - f.d;
      if (std::abs(h) > tol) continue;
      if (!inside_loops(f.loops2, f.to2(x))) continue;
      bool near = false;
      for (int e : f.edges)
        if (point_seg_dist(x, B.V[B.E[e].v0].p, B.V[B.E[e].v1].p) <= tol) {
          near = true;
          break;
        }
      if (near) continue;
      Touch t{PcType::VF, (int)va, (int)fb};
      t.p0 = x;
      t.normal = f.n;
      add(t);
    }
  }
  // e-v, f-v (B's vertices)
  for (std::size_t vb = 0; vb < B.V.size(); ++vb) {
    const Vec3& xw = B.V[vb].p;
    const Vec3& y = S.pb_a[vb];
    for (std::size_t ea = 0; ea < A.E.size(); ++ea) {
      if (S.ae[ea].dist(bv_[vb]) > tol) continue;
      const Vec3& a0 = S.pa[A.E[ea].v0];
      const Vec3& a1 = S.pa[A.E[ea].v1];
      if (point_seg_dist(xw, a0, a1) <= tol && (xw - a0).norm() > tol && (xw - a1).norm() > tol) {
        Touch t{PcType::EV, (int)ea, (int)vb};
        t.p0 = xw;
        add(t);
      }
    }
    for (std::size_t fa = 0; fa < A.F.size(); ++fa) {
      if (S.af[fa].dist(bv_[vb]) > tol) continue;
      const Face& f = A.F[fa];
      double h = f.n.dot(y) - f.d;
      if (std::abs(h) > tol) continue;
      if (!inside_loops(f.loops2, f.to2(y))) continue;
      bool near = false;
      for (int e : f.edges)
        if (point_seg_dist(y, A.V[A.E[e].v0].p, A.V[A.E[e].v1].p) <= tol) {
          near = true;
          break;
        }
      if (near) continue;
      Touch t{PcType::FV, (int)fa, (int)vb};
      t.p0 = xw;
      t.normal = R * f.n;
      add(t);
    }
  }
  // e-e, e-f
  for (std::size_t ea = 0; ea < A.E.size(); ++ea) {
    const Vec3& a0 = S.pa[A.E[ea].v0];
    const Vec3& a1 = S.pa[A.E[ea].v1];
    for (std::size_t eb = 0; eb < B.E.size(); ++eb) {
      if (S.ae[ea].dist(be_[eb]) > tol) continue;
      const Vec3& b0 = B.V[B.E[eb].v0].p;
      const Vec3& b1 = B.V[B.E[eb].v1].p;
      EEResult r = edge_edge_test(a0, a1, b0, b1, tol);
      if (r.kind == 0) continue;
      Touch t{r.kind == 1 ? PcType::EE : PcType::EEC, (int)ea, (int)eb};
      t.p0 = r.point;
      t.sin_angle = r.sin_angle;
      t.extent = r.extent;
      if (r.kind == 1) {
        t.normal = (a1 - a0).cross(b1 - b0).normalized();
        t.near_end = r.near_end;
      }
      add(t);
    }
    for (std::size_t fb = 0; fb < B.F.size(); ++fb) {
      if (S.ae[ea].dist(bf_[fb]) > tol) continue;
      EFResult r = edge_face_test(B, B.F[fb], a0, a1, tol);
      if (r.kind == 0) continue;
      Touch t{PcType::EF, (int)ea, (int)fb};
      t.normal = B.F[fb].n;
      if (r.kind == 2) {
        t.transversal = true;
        t.p0 = a0 + r.sc * (a1 - a0);
      } else {
        t.extent = r.extent;
        t.p0 = a0 + r.s0 * (a1 - a0);
        t.p1 = a0 + r.s1 * (a1 - a0);
      }
      add(t);
    }
  }
  // f-e (B's edges against A's faces, in A's frame)
  for (std::size_t eb = 0; eb < B.E.size(); ++eb) {
    const Vec3& b0 = S.pb_a[B.E[eb].v0];
    const Vec3& b1 = S.pb_a[B.E[eb].v1];
    for (std::size_t fa = 0; fa < A.F.size(); ++fa) {
      if (S.af[fa].dist(be_[eb]) > tol) continue;
      EFResult r = edge_face_test(A, A.F[fa], b0, b1, tol);
      if (r.kind == 0) continue;
      Touch t{PcType::FE, (int)fa, (int)eb};
      t.normal = R * A.F[fa].n;
      const Vec3& w0 = B.V[B.E[eb].v0].p;
      const Vec3& w1 = B.V[B.E[eb].v1].p;
      if (r.kind == 2) {
        t.transversal = true;
        t.p0 = w0 + r.sc * (w1 - w0);
      } else {
        t.extent = r.extent;
        t.p0 = w0 + r.s0 * (w1 - w0);
        t.p1 = w0 + r.s1 * (w1 - w0);
      }
      add(t);
    }
  }
  // f-f (in A's frame)
  for (std::size_t fa = 0; fa < A.F.size(); ++fa) {
    const Face& F = A.F[fa];
    for (std::size_t fb = 0; fb < B.F.size(); ++fb) {
      if (S.af[fa].dist(bf_[fb]) > tol) continue;
      const Face& G = B.F[fb];
      Vec3 nBa = R.transpose() * G.n;
      double dBa = G.d - G.n.dot(S.X.t);
      if (std::abs(F.n.dot(nBa)) < 0.99) continue;
      // quick height rejections
      bool all_up = true, all_dn = true;
      for (int v : G.verts) {
        double h = F.n.dot(S.pb_a[v]) - F.d;
        if (h <= tol) all_up = false;
        if (h >= -tol) all_dn = false;
      }
      if (all_up || all_dn) continue;
      std::vector<std::vector<Vec2>> Q;
      for (const auto& L : G.loops) {
        std::vector<Vec2> q;
        for (int v : L) q.push_back(F.to2(S.pb_a[v]));
        Q.push_back(std::move(q));
      }
      // An overlap narrower than tol is no overlap at the tolerance's scale (faces side by side
      // along a common edge give rounding noise here); between 1e-3 of that and that, it is a
      // sliver: near-degenerate.
      double area = overlap_area(F.loops2, Q);
      const double thr = tol * std::min(F.perimeter, G.perimeter) / 2;
      if (area <= 1e-3 * thr) continue;
      const bool sliver = area <= thr;
      double maxabs = 0;
      Vec3 acc = Vec3::Zero();
      int cnt = 0;
      for (int v : F.verts) {
        Vec2 y2 = F.loops2.empty() ? Vec2::Zero() : F.to2(A.V[v].p);
        if (inside_loops(Q, y2) || dist_to_loops(Q, y2) <= tol) {
          maxabs = std::max(maxabs, std::abs(nBa.dot(A.V[v].p) - dBa));
          acc += A.V[v].p;
          ++cnt;
        }
      }
      for (int v : G.verts) {
        Vec2 z2 = F.to2(S.pb_a[v]);
        if (inside_loops(F.loops2, z2) || dist_to_loops(F.loops2, z2) <= tol) {
          maxabs = std::max(maxabs, std::abs(F.n.dot(S.pb_a[v]) - F.d));
          acc += S.pb_a[v];
          ++cnt;
        }
      }
      for (const auto& L : F.loops2)
        for (std::size_t i = 0; i < L.size(); ++i)
          for (const auto& M : Q)
            for (std::size_t j = 0; j < M.size(); ++j) {
              Vec2 c2;
              if (seg2_cross(L[i], L[(i + 1) % L.size()], M[j], M[(j + 1) % M.size()], &c2)) {
                Vec3 y = F.to3(c2);
                maxabs = std::max(maxabs, std::abs(nBa.dot(y) - dBa));
                acc += y;
                ++cnt;
              }
            }
      if (maxabs > tol) continue;  // tilted: touches (if at all) along edges or at points
      if (sliver) {
        V.uncertain.push_back("f-f:" + std::to_string(fa) + ":" + std::to_string(fb) +
                              " overlap is a sliver");
        continue;
      }
      Touch t{PcType::FF, (int)fa, (int)fb};
      t.extent = area;
      t.normal = G.n;
      t.p0 = S.X.apply(cnt ? Vec3(acc / cnt) : F.centroid);
      add(t);
    }
  }
}

void Classifier::cone_checks(const Scene& S, Verdict& V) const {
  const Mat3& R = S.X.R;
  const double tol = tol_.len;
  for (const Touch& t : V.touches) {
    if (t.transversal) {
      V.penetrating = true;
      V.why = std::string("open ") +
              (t.type == PcType::EF ? "edge of A through open face of B"
                                    : "edge of B through open face of A") +
              " (" + type_name(t.type) + ":" + std::to_string(t.a) + ":" + std::to_string(t.b) +
              ")";
      return;
    }
    Cone ca, cb;
    const int ka = kind_a(t.type), kb = kind_b(t.type);
    ca = ka == 2   ? face_cone(A_, t.a, R)
         : ka == 1 ? edge_cone(A_, t.a, R)
                   : vertex_cone(A_, t.a, R);
    const Mat3 I = Mat3::Identity();
    cb = kb == 2   ? face_cone(B_, t.b, I)
         : kb == 1 ? edge_cone(B_, t.b, I)
                   : vertex_cone(B_, t.b, I);
    double slack = tol_.ang;
    if ((t.type == PcType::EF || t.type == PcType::FE) && t.extent > 0)
      slack = std::max(slack, 2 * tol / t.extent);
    if (t.type == PcType::FF && t.extent > 0)
      slack = std::max(slack, 4 * tol / std::sqrt(t.extent));
    if (cones_overlap(ca, cb, slack)) {
      V.penetrating = true;
      V.why = std::string("tangent cones overlap at ") + type_name(t.type) + ":" +
              std::to_string(t.a) + ":" + std::to_string(t.b);
      return;
    }
  }
}

void Classifier::containment(const Scene& S, Verdict& V) const {
  if (!V.touches.empty()) return;
  if (point_in_solid(B_, S.pa[0])) {
    V.penetrating = true;
    V.why = "A lies inside B";
    return;
  }
  if (point_in_solid(A_, S.pb_a[0])) {
    V.penetrating = true;
    V.why = "B lies inside A";
  }
}

void Classifier::pcs_and_planes(const Scene& S, Verdict& V) const {
  const int n = static_cast<int>(V.touches.size());
  for (int i = 0; i < n; ++i) {
    const Touch& ti = V.touches[i];
    bool dom = false;
    for (int j = 0; j < n && !dom; ++j) {
      if (j == i) continue;
      const Touch& tj = V.touches[j];
      if (A_.in_closure(kind_a(ti.type), ti.a, kind_a(tj.type), tj.a) &&
          B_.in_closure(kind_b(ti.type), ti.b, kind_b(tj.type), tj.b))
        dom = true;
    }
    if (!dom) V.pcs.push_back(i);
  }
  const double tol = tol_.len;
  for (int i : V.pcs) {
    const Touch& t = V.touches[i];
    if (!nondegenerate(t.type)) V.degenerate = true;
    if (t.type == PcType::EE && t.near_end)
      V.uncertain.push_back("e-e crossing close to an edge end or at a small angle");
    if ((t.type == PcType::EF || t.type == PcType::FE) && t.extent < 10 * tol)
      V.uncertain.push_back("line contact of tiny length");
  }
  if (V.pcs.size() > 3) V.too_many = true;
  if (V.degenerate) return;
  // contact planes (world): normal and a point
  struct Pl {
    Vec3 n, p;
  };
  std::vector<Pl> pl;
  for (int i : V.pcs) {
    const Touch& t = V.touches[i];
    pl.push_back({t.normal.normalized(), t.p0});
  }
  (void)S;
  for (std::size_t i = 0; i < pl.size(); ++i)
    for (std::size_t j = i + 1; j < pl.size(); ++j) {
      double s = pl[i].n.cross(pl[j].n).norm();
      double off = std::max(std::abs(pl[i].n.dot(pl[j].p - pl[i].p)),
                            std::abs(pl[j].n.dot(pl[i].p - pl[j].p)));
      if (s <= 1e-6 && off <= 4 * tol)
        V.same_plane = true;
      else if (!(s > 1e-4 || off > 100 * tol))
        V.uncertain.push_back("two contact planes nearly coincide");
    }
}

void Classifier::clearance(const Scene& S, Verdict& V, const CfKey* outside) const {
  const double tol = tol_.len;
  double best = kInf;
  std::string what;
  const Poly& A = A_;
  const Poly& B = B_;
  // With `outside`: only pairs that no PC of it dominates (x in the closure of its A
  // element and y in the closure of its B element).
  auto dominated = [&](int kx, int x, int ky, int y) {
    if (outside == nullptr) return false;
    for (const Pc& pc : *outside)
      if (A.in_closure(kx, x, kind_a(pc.type), pc.a) && B.in_closure(ky, y, kind_b(pc.type), pc.b))
        return true;
    return false;
  };
  for (std::size_t va = 0; va < A.V.size(); ++va)
    for (std::size_t fb = 0; fb < B.F.size(); ++fb) {
      if (S.av[va].dist(bf_[fb]) >= best) continue;
      if (dominated(0, static_cast<int>(va), 2, static_cast<int>(fb))) continue;
      double d = point_face_dist(B, B.F[fb], S.pa[va]);
      if (d > tol && d < best) {
        best = d;
        what = "v" + std::to_string(va) + " of A to f" + std::to_string(fb) + " of B";
      }
    }
  for (std::size_t vb = 0; vb < B.V.size(); ++vb)
    for (std::size_t fa = 0; fa < A.F.size(); ++fa) {
      if (S.af[fa].dist(bv_[vb]) >= best) continue;
      if (dominated(2, static_cast<int>(fa), 0, static_cast<int>(vb))) continue;
      double d = point_face_dist(A, A.F[fa], S.pb_a[vb]);
      if (d > tol && d < best) {
        best = d;
        what = "f" + std::to_string(fa) + " of A to v" + std::to_string(vb) + " of B";
      }
    }
  for (std::size_t ea = 0; ea < A.E.size(); ++ea)
    for (std::size_t eb = 0; eb < B.E.size(); ++eb) {
      if (S.ae[ea].dist(be_[eb]) >= best) continue;
      if (dominated(1, static_cast<int>(ea), 1, static_cast<int>(eb))) continue;
      double d = seg_seg_dist(S.pa[A.E[ea].v0], S.pa[A.E[ea].v1], B.V[B.E[eb].v0].p,
                              B.V[B.E[eb].v1].p, nullptr, nullptr);
      if (d > tol && d < best) {
        best = d;
        what = "e" + std::to_string(ea) + " of A to e" + std::to_string(eb) + " of B";
      }
    }
  V.clearance = best;
  V.clearance_what = what;
}

double Classifier::clearance_outside(const Pose& X, const CfKey& pcs) const {
  const Scene S = scene(X);
  Verdict V;
  clearance(S, V, &pcs);
  return V.clearance;
}

Classifier::Scene Classifier::scene(const Pose& X) const {
  Scene S;
  S.X = X;
  const Poly& A = A_;
  S.pa.resize(A.V.size());
  S.av.resize(A.V.size());
  for (std::size_t i = 0; i < A.V.size(); ++i) {
    S.pa[i] = X.apply(A.V[i].p);
    S.av[i] = Box3();
    S.av[i].add(S.pa[i]);
  }
  for (const auto& e : A.E) {
    Box3 b;
    b.add(S.pa[e.v0]);
    b.add(S.pa[e.v1]);
    S.ae.push_back(b);
  }
  for (const auto& f : A.F) {
    Box3 b;
    for (int v : f.verts) b.add(S.pa[v]);
    S.af.push_back(b);
  }
  S.pb_a.resize(B_.V.size());
  for (std::size_t i = 0; i < B_.V.size(); ++i) S.pb_a[i] = X.inv(B_.V[i].p);
  return S;
}

Verdict Classifier::classify(const Pose& X, bool with_clearance) const {
  const Scene S = scene(X);
  Verdict V;
  touches(S, V);
  cone_checks(S, V);
  if (!V.penetrating) containment(S, V);
  if (V.penetrating) return V;
  pcs_and_planes(S, V);
  if (with_clearance) clearance(S, V);
  return V;
}

bool Classifier::interiors_disjoint(const Pose& X, std::string* why) const {
  Verdict V = classify(X, false);
  if (why) *why = V.why;
  return !V.penetrating;
}

}  // namespace oracle
