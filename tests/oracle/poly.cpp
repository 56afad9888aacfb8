#include "poly.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace oracle {

namespace {
std::string fmt_err(const std::string& name, const std::string& what) {
  return "model '" + name + "': " + what;
}
}  // namespace

double ccw_angle(const Vec3& a, const Vec3& b, const Vec3& n) {
  Vec3 ap = a - n * n.dot(a), bp = b - n * n.dot(b);
  double s = ap.cross(bp).dot(n), c = ap.dot(bp);
  double ang = std::atan2(s, c);
  if (ang < 0) ang += 2 * kPi;
  return ang;
}

Vec3 any_perp(const Vec3& n) {
  Vec3 a = std::abs(n.x()) < 0.6 ? Vec3(1, 0, 0)
                                 : (std::abs(n.y()) < 0.6 ? Vec3(0, 1, 0) : Vec3(0, 0, 1));
  return n.cross(a).normalized();
}

bool inside_loops(const std::vector<std::vector<Vec2>>& loops, const Vec2& p) {
  bool in = false;
  for (const auto& L : loops) {
    const std::size_t n = L.size();
    for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
      const Vec2& a = L[i];
      const Vec2& b = L[j];
      if ((a.y() > p.y()) != (b.y() > p.y())) {
        double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
        if (p.x() < x) in = !in;
      }
    }
  }
  return in;
}

static double pt_seg2(const Vec2& p, const Vec2& a, const Vec2& b) {
  Vec2 ab = b - a;
  double L2 = ab.squaredNorm();
  double s = L2 > 0 ? std::clamp((p - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  return (a + s * ab - p).norm();
}

double dist_to_loops(const std::vector<std::vector<Vec2>>& loops, const Vec2& p) {
  double best = kInf;
  for (const auto& L : loops)
    for (std::size_t i = 0; i < L.size(); ++i)
      best = std::min(best, pt_seg2(p, L[i], L[(i + 1) % L.size()]));
  return best;
}

double point_seg_dist(const Vec3& p, const Vec3& a, const Vec3& b, double* sp) {
  Vec3 ab = b - a;
  double L2 = ab.squaredNorm();
  double s = L2 > 0 ? std::clamp((p - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
  if (sp) *sp = s;
  return (a + s * ab - p).norm();
}

// Ericson, Real-Time Collision Detection, 5.1.9.
double seg_seg_dist(const Vec3& p1, const Vec3& q1, const Vec3& p2, const Vec3& q2, double* sp,
                    double* tp) {
  Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0, t = 0;
  if (a <= 1e-300 && e <= 1e-300) {
    s = t = 0;
  } else if (a <= 1e-300) {
    s = 0;
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    double c = d1.dot(r);
    if (e <= 1e-300) {
      t = 0;
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
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
  if (sp) *sp = s;
  if (tp) *tp = t;
  return (p1 + s * d1 - (p2 + t * d2)).norm();
}

double point_face_dist(const Poly& /*P*/, const Face& f, const Vec3& x) {
  double h = f.n.dot(x) - f.d;
  Vec2 p = f.to2(x);
  if (inside_loops(f.loops2, p)) return std::abs(h);
  double d2 = dist_to_loops(f.loops2, p);
  return std::sqrt(h * h + d2 * d2);
}

int Poly::edge_index(int a, int b) const {
  auto it = edge_of.find({std::min(a, b), std::max(a, b)});
  return it == edge_of.end() ? -1 : it->second;
}

bool Poly::vertex_on_face(int v, int f) const {
  const auto& vs = F[f].verts;
  return std::find(vs.begin(), vs.end(), v) != vs.end();
}

bool Poly::in_closure(int ka, int a, int kb, int b) const {
  if (ka == kb) return a == b;
  if (ka > kb) return false;
  if (ka == 0 && kb == 1) return vertex_on_edge(a, b);
  if (ka == 0 && kb == 2) return vertex_on_face(a, b);
  if (ka == 1 && kb == 2) return edge_on_face(a, b);
  return false;
}

double Poly::volume() const {
  // Divergence theorem: sum over faces of d * area / 3 (faces with holes: signed loop areas).
  double v = 0;
  for (const auto& f : F) v += f.d * f.area / 3.0;
  return v;
}

double Poly::surface_area() const {
  double a = 0;
  for (const auto& f : F) a += f.area;
  return a;
}

Poly build_poly(const std::vector<Vec3>& verts, const std::vector<std::array<int, 2>>& edges,
                const std::vector<std::vector<std::vector<int>>>& faces, const std::string& name) {
  Poly P;
  P.name = name;
  const int nv = static_cast<int>(verts.size());
  if (nv < 4) throw std::runtime_error(fmt_err(name, "fewer than 4 vertices"));
  P.V.resize(nv);
  for (int i = 0; i < nv; ++i) {
    P.V[i].p = verts[i];
    P.box.add(verts[i]);
  }
  P.diag = P.box.diag();
  P.E.resize(edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e) {
    int a = edges[e][0], b = edges[e][1];
    if (a < 0 || b < 0 || a >= nv || b >= nv || a == b)
      throw std::runtime_error(
          fmt_err(name, "edge " + std::to_string(e) + " has bad vertex indices"));
    if (P.edge_of.count({std::min(a, b), std::max(a, b)}))
      throw std::runtime_error(
          fmt_err(name, "edge " + std::to_string(e) + " repeats another edge"));
    P.edge_of[{std::min(a, b), std::max(a, b)}] = static_cast<int>(e);
    Edge& E = P.E[e];
    E.v0 = a;
    E.v1 = b;
    Vec3 d = verts[b] - verts[a];
    E.len = d.norm();
    if (!(E.len > 0))
      throw std::runtime_error(fmt_err(name, "edge " + std::to_string(e) + " has zero length"));
    E.dir = d / E.len;
    P.V[a].edges.push_back(static_cast<int>(e));
    P.V[b].edges.push_back(static_cast<int>(e));
  }
  P.min_edge = kInf;
  for (const auto& E : P.E) P.min_edge = std::min(P.min_edge, E.len);

  P.F.resize(faces.size());
  for (std::size_t fi = 0; fi < faces.size(); ++fi) {
    Face& F = P.F[fi];
    F.loops = faces[fi];
    if (F.loops.empty())
      throw std::runtime_error(fmt_err(name, "face " + std::to_string(fi) + " has no loop"));
    // Newell normal of the outer loop.
    Vec3 nn = Vec3::Zero();
    const auto& outer = F.loops[0];
    if (outer.size() < 3)
      throw std::runtime_error(
          fmt_err(name, "face " + std::to_string(fi) + " outer loop has < 3 vertices"));
    for (std::size_t i = 0; i < outer.size(); ++i) {
      int a = outer[i], b = outer[(i + 1) % outer.size()];
      if (a < 0 || a >= nv || b < 0 || b >= nv)
        throw std::runtime_error(
            fmt_err(name, "face " + std::to_string(fi) + " has a bad vertex index"));
      nn += verts[a].cross(verts[b]);
    }
    if (nn.norm() <= 0)
      throw std::runtime_error(fmt_err(name, "face " + std::to_string(fi) + " has zero area"));
    F.n = nn.normalized();
    Vec3 c = Vec3::Zero();
    int cnt = 0;
    std::set<int> vs;
    for (const auto& L : F.loops)
      for (int v : L) {
        if (v < 0 || v >= nv)
          throw std::runtime_error(
              fmt_err(name, "face " + std::to_string(fi) + " has a bad vertex index"));
        c += verts[v];
        ++cnt;
        vs.insert(v);
      }
    c /= cnt;
    F.verts.assign(vs.begin(), vs.end());
    F.d = F.n.dot(c);
    F.o = verts[outer[0]];
    F.u = any_perp(F.n);
    F.w = F.n.cross(F.u);
    // Planarity check (relative): every loop vertex within 1e-6 diag of the plane.
    for (int v : F.verts)
      if (std::abs(F.n.dot(verts[v]) - F.d) > 1e-6 * P.diag)
        throw std::runtime_error(fmt_err(name, "face " + std::to_string(fi) + " is not planar"));
    double area = 0;
    Vec3 ac = Vec3::Zero();
    for (std::size_t li = 0; li < F.loops.size(); ++li) {
      const auto& L = F.loops[li];
      std::vector<Vec2> L2;
      for (int v : L) {
        L2.push_back(F.to2(verts[v]));
        F.box.add(verts[v]);
      }
      double la = 0;
      for (std::size_t i = 0; i < L2.size(); ++i) {
        const Vec2& a = L2[i];
        const Vec2& b = L2[(i + 1) % L2.size()];
        double cr = a.x() * b.y() - a.y() * b.x();
        la += cr / 2;
        Vec2 cc = (a + b) * cr / 6;
        ac += cc.x() * F.u + cc.y() * F.w;
        F.perimeter += (b - a).norm();
      }
      if (li == 0 && la <= 0)
        throw std::runtime_error(
            fmt_err(name, "face " + std::to_string(fi) + " outer loop is not counter-clockwise"));
      if (li > 0 && la >= 0)
        throw std::runtime_error(
            fmt_err(name, "face " + std::to_string(fi) + " hole loop is not clockwise"));
      area += la;
      F.loops2.push_back(std::move(L2));
    }
    F.area = area;
    F.centroid = F.o + ac / area;
    // Edges of the face and their orientation.
    for (const auto& L : F.loops)
      for (std::size_t i = 0; i < L.size(); ++i) {
        int a = L[i], b = L[(i + 1) % L.size()];
        int e = P.edge_index(a, b);
        if (e < 0)
          throw std::runtime_error(fmt_err(name, "face " + std::to_string(fi) + " runs " +
                                                     std::to_string(a) + "-" + std::to_string(b) +
                                                     " which is not an edge"));
        Edge& E = P.E[e];
        int slot = (E.v0 == a) ? 0 : 1;
        if (E.face[slot] >= 0)
          throw std::runtime_error(
              fmt_err(name, "edge " + std::to_string(e) + " is run the same way by two faces"));
        E.face[slot] = static_cast<int>(fi);
        F.edges.push_back(e);
      }
  }
  for (std::size_t e = 0; e < P.E.size(); ++e) {
    Edge& E = P.E[e];
    if (E.face[0] < 0 || E.face[1] < 0)
      throw std::runtime_error(
          fmt_err(name, "edge " + std::to_string(e) + " does not have two faces"));
    if (E.face[0] == E.face[1])
      throw std::runtime_error(
          fmt_err(name, "edge " + std::to_string(e) + " has the same face on both sides"));
    const Vec3& n0 = P.F[E.face[0]].n;
    const Vec3& n1 = P.F[E.face[1]].n;
    E.m[0] = n0.cross(E.dir).normalized();
    E.m[1] = (-n1.cross(E.dir)).normalized();
    E.convex = E.m[0].dot(n1) < 0;
  }
  // Vertex corners.
  for (std::size_t fi = 0; fi < P.F.size(); ++fi) {
    const Face& F = P.F[fi];
    for (const auto& L : F.loops) {
      const std::size_t n = L.size();
      for (std::size_t k = 0; k < n; ++k) {
        int v = L[k], nx = L[(k + 1) % n], pv = L[(k + n - 1) % n];
        Corner c;
        c.face = static_cast<int>(fi);
        c.r1 = (P.V[nx].p - P.V[v].p).normalized();
        c.r2 = (P.V[pv].p - P.V[v].p).normalized();
        c.span = ccw_angle(c.r1, c.r2, F.n);
        if (c.span <= 0) c.span = 2 * kPi;
        c.e_next = P.edge_index(v, nx);
        c.e_prev = P.edge_index(pv, v);
        P.V[v].corners.push_back(c);
      }
    }
  }
  for (int v = 0; v < nv; ++v)
    if (P.V[v].edges.size() < 3 || P.V[v].corners.size() < 3)
      throw std::runtime_error(
          fmt_err(name, "vertex " + std::to_string(v) + " has fewer than 3 edges/faces"));
  if (P.volume() <= 0)
    throw std::runtime_error(fmt_err(name, "non-positive volume (inward orientation?)"));
  return P;
}

}  // namespace oracle
