#include "pair_conditions.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace cf::gen {
namespace {

double angle(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Distance from unit p to the shorter great-circle arc from unit a to unit b.
double point_arc(const Vec3& p, const Vec3& a, const Vec3& b) {
  Vec3 n = a.cross(b);
  if (n.norm() < 1e-12) return angle(p, a);
  n.normalize();
  const Vec3 q = p - p.dot(n) * n;  // projection onto the arc's great circle
  if (q.norm() < 1e-12) return M_PI / 2;
  // Inside the arc when a, q, b turn the same way about n: q nearest on the whole circle.
  if (a.cross(q).dot(n) >= 0 && q.cross(b).dot(n) >= 0) return angle(p, q);
  // Otherwise the nearest point is an end: cos(distance) falls monotonically away from q.
  return std::min(angle(p, a), angle(p, b));
}

bool in_arc(const Vec3& s, const Vec3& a, const Vec3& b, const Vec3& n) {
  return a.cross(s).dot(n) >= 0 && s.cross(b).dot(n) >= 0;
}

// Smallest distance between two arcs: 0 where they cross, else at an end of one of them
// (the distance from a point moving along a great circle to another great circle has no
// interior minimum but its zeros).
double arc_arc(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const Vec3 n1 = a.cross(b), n2 = c.cross(d);
  const Vec3 x = n1.cross(n2);
  if (n1.norm() > 1e-12 && n2.norm() > 1e-12 && x.norm() > 1e-12) {
    const Vec3 s = x.normalized();
    if ((in_arc(s, a, b, n1) && in_arc(s, c, d, n2)) || (in_arc(-s, a, b, n1) && in_arc(-s, c, d, n2)))
      return 0;
  }
  return std::min({point_arc(a, c, d), point_arc(b, c, d), point_arc(c, a, b), point_arc(d, a, b)});
}

NormalCone point_cone(const Vec3& n) { return NormalCone{{n.normalized()}, {}}; }

// Polar of the cone spanned by unit rays: its extreme rays are the normals of the planes
// through two rays with every ray on one side.
NormalCone polar_cone(const std::vector<Vec3>& rays) {
  NormalCone c;
  for (std::size_t i = 0; i < rays.size(); ++i)
    for (std::size_t j = i + 1; j < rays.size(); ++j) {
      const Vec3 n = rays[i].cross(rays[j]);
      if (n.norm() < 1e-12) continue;
      for (double sign : {1.0, -1.0}) {
        const Vec3 u = sign * n.normalized();
        bool ok = true;
        for (const Vec3& r : rays) ok = ok && r.dot(u) <= 1e-9;
        bool dup = false;
        for (const Vec3& g : c.gens) dup = dup || angle(g, u) < 1e-9;
        if (ok && !dup) c.gens.push_back(u);
      }
    }
  for (const Vec3& r : rays) c.facets.push_back(-r);
  return c;
}

// The directions at least `margin` (rad) inside a cone: a face's normal stays; an edge's arc
// loses `margin` at both ends; a vertex's polar cone keeps { u : h . u >= sin(margin) } for
// its facets h, whose corners are where two shifted facet planes meet on the sphere. Empty
// when nothing is that far inside.
NormalCone shrink(const NormalCone& c, double margin) {
  if (margin <= 0 || c.gens.size() < 2) return c;
  if (c.gens.size() == 2) {
    const Vec3 &a = c.gens[0], &b = c.gens[1];
    const double len = angle(a, b);
    if (len <= 2 * margin) return {};
    const Vec3 w = (b - a.dot(b) * a).normalized();  // unit tangent at a towards b
    const Vec3 v = (a - b.dot(a) * b).normalized();  // unit tangent at b towards a
    return {{std::cos(margin) * a + std::sin(margin) * w, std::cos(margin) * b + std::sin(margin) * v}, {}};
  }
  const double s = std::sin(margin);
  NormalCone out;
  for (std::size_t i = 0; i < c.facets.size(); ++i)
    for (std::size_t j = i + 1; j < c.facets.size(); ++j) {
      const Vec3 &hi = c.facets[i], &hj = c.facets[j];
      const double g = hi.dot(hj);
      const Vec3 x = hi.cross(hj);
      if (x.norm() < 1e-12) continue;
      // u = k (hi + hj) + c x with hi . u = hj . u = s and |u| = 1.
      const double k = s / (1 + g);
      const double c2 = (1 - 2 * k * k * (1 + g)) / x.squaredNorm();
      if (c2 < 0) continue;
      for (double sign : {1.0, -1.0}) {
        const Vec3 u = k * (hi + hj) + sign * std::sqrt(c2) * x;
        bool inside = true;
        for (const Vec3& h : c.facets) inside = inside && h.dot(u) >= s - 1e-12;
        bool dup = false;
        for (const Vec3& q : out.gens) dup = dup || angle(q, u) < 1e-9;
        if (inside && !dup) out.gens.push_back(u.normalized());
      }
    }
  if (out.gens.empty()) return {};
  out.facets = c.facets;
  out.shift = s;
  return out;
}

std::array<std::vector<NormalCone>, 3> cones_of(const ModelInfo& info, double margin) {
  const Polyhedron& m = *info.model;
  std::array<std::vector<NormalCone>, 3> out;
  auto& verts = out[static_cast<int>(ElementKind::kVertex)];
  auto& edges = out[static_cast<int>(ElementKind::kEdge)];
  auto& faces = out[static_cast<int>(ElementKind::kFace)];
  for (std::size_t v = 0; v < m.num_vertices(); ++v)
    verts.push_back(info.cones[v].pointed ? shrink(polar_cone(info.cones[v].rays), margin) : NormalCone{});
  for (const Edge& e : m.edges())
    edges.push_back(e.convex ? shrink(NormalCone{{m.face(e.left).normal, m.face(e.right).normal}, {}}, margin)
                             : NormalCone{});
  for (const Face& f : m.faces()) faces.push_back(point_cone(f.normal));
  return out;
}

// Arcs between every two generators: they cover the cone's boundary (the others lie inside).
template <class Fn>
void for_each_arc(const NormalCone& c, Fn fn) {
  for (std::size_t i = 0; i < c.gens.size(); ++i)
    for (std::size_t j = i + 1; j < c.gens.size(); ++j) fn(c.gens[i], c.gens[j]);
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double l, double h) { lo = std::min(lo, l), hi = std::max(hi, h); }
};

// Range of v . u over unit u in cone c, widened by angle_tol.
void add_dot_range(Range& r, const Vec3& v, const NormalCone& c, double angle_tol) {
  const double len = v.norm();
  if (len < 1e-300) return r.add(0, 0);
  const Vec3 d = v / len;
  const double near = std::max(0.0, cone_distance(d, c, angle_tol) - angle_tol);
  const double far = std::max(0.0, cone_distance(-d, c, angle_tol) - angle_tol);
  r.add(-len * std::cos(far), len * std::cos(near));
}

// Range of (y - x) . u over points x of the first closure, y of the second, u in cone c.
Range height_range(const std::vector<Vec3>& xs, const std::vector<Vec3>& ys, const NormalCone& c,
                   double angle_tol) {
  Range r;
  if (c.gens.size() == 1) {
    // One normal: the range splits into the two closures' ranges along it.
    const Vec3& n = c.gens[0];
    Range rx, ry;
    for (const Vec3& x : xs) rx.add(n.dot(x), n.dot(x));
    for (const Vec3& y : ys) ry.add(n.dot(y), n.dot(y));
    r.add(ry.lo - rx.hi, ry.hi - rx.lo);
    return r;
  }
  for (const Vec3& x : xs)
    for (const Vec3& y : ys) add_dot_range(r, y - x, c, angle_tol);
  return r;
}

}  // namespace

double cone_distance(const Vec3& p, const NormalCone& c, double tol) {
  if (c.gens.empty()) return 0;
  if (c.gens.size() == 1) return angle(p, c.gens[0]);
  if (c.gens.size() == 2) return point_arc(p, c.gens[0], c.gens[1]);
  bool inside = true;
  for (const Vec3& h : c.facets) inside = inside && h.dot(p) >= c.shift - tol;
  if (inside) return 0;
  double d = std::numeric_limits<double>::infinity();
  for_each_arc(c, [&](const Vec3& a, const Vec3& b) { d = std::min(d, point_arc(p, a, b)); });
  return d;
}

double cone_cone_distance(const NormalCone& p, const NormalCone& q, double tol) {
  if (p.gens.empty() || q.gens.empty()) return 0;
  if (p.gens.size() == 1) return cone_distance(p.gens[0], q, tol);
  if (q.gens.size() == 1) return cone_distance(q.gens[0], p, tol);
  for (const Vec3& g : p.gens)
    if (cone_distance(g, q, tol) <= tol) return 0;
  for (const Vec3& g : q.gens)
    if (cone_distance(g, p, tol) <= tol) return 0;
  double d = std::numeric_limits<double>::infinity();
  for_each_arc(p, [&](const Vec3& a, const Vec3& b) {
    for_each_arc(q, [&](const Vec3& c, const Vec3& e) { d = std::min(d, arc_arc(a, b, c, e)); });
  });
  return d;
}

PairConditions::PairConditions(const ModelInfo& A, const ModelInfo& B, double length_tol, double angle_tol,
                               double cone_margin)
    : a_cones_(cones_of(A, cone_margin)), b_cones_(cones_of(B, cone_margin)), A_(A), B_(B),
      length_tol_(length_tol), angle_tol_(angle_tol) {
  for (int k = 0; k < 3; ++k) {
    const auto kind = static_cast<ElementKind>(k);
    for (std::size_t i = 0; i < a_cones_[k].size(); ++i)
      a_points_[k].push_back(closure_points(*A.model, kind, static_cast<int>(i)));
    for (std::size_t i = 0; i < b_cones_[k].size(); ++i)
      b_points_[k].push_back(closure_points(*B.model, kind, static_cast<int>(i)));
  }
}

const NormalCone& PairConditions::cone(bool of_a, ElementKind k, int i) const {
  return (of_a ? a_cones_ : b_cones_)[static_cast<int>(k)][static_cast<std::size_t>(i)];
}

bool PairConditions::compatible(const Pc& x, const Pc& y) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  const ElementKind kax = a_kind(x.type), kay = a_kind(y.type), kbx = b_kind(x.type), kby = b_kind(y.type);
  const auto& pax = a_points_[static_cast<int>(kax)][static_cast<std::size_t>(x.a)];
  const auto& pay = a_points_[static_cast<int>(kay)][static_cast<std::size_t>(y.a)];
  const auto& pbx = b_points_[static_cast<int>(kbx)][static_cast<std::size_t>(x.b)];
  const auto& pby = b_points_[static_cast<int>(kby)][static_cast<std::size_t>(y.b)];

  // Distance between the two contact points, the same measured in A and in B.
  {
    auto range = [](const Polyhedron& m, ElementKind k1, int i1, ElementKind k2, int i2,
                    const std::vector<Vec3>& p1, const std::vector<Vec3>& p2) {
      Range r;
      double dmax = 0;
      for (const Vec3& p : p1)
        for (const Vec3& q : p2) dmax = std::max(dmax, (p - q).norm());
      r.add(element_distance(m, Pose(), k1, i1, m, k2, i2).distance, dmax);
      return r;
    };
    const Range ra = range(A, kax, x.a, kay, y.a, pax, pay), rb = range(B, kbx, x.b, kby, y.b, pbx, pby);
    if (ra.lo > rb.hi + length_tol_ || rb.lo > ra.hi + length_tol_) return false;
  }

  const NormalCone& ax = cone(true, kax, x.a);
  const NormalCone& ay = cone(true, kay, y.a);
  const NormalCone& bx = cone(false, kbx, x.b);
  const NormalCone& by = cone(false, kby, y.b);
  // An element with no direction inside its cone cannot take part in a verified contact.
  if (ax.gens.empty() || ay.gens.empty() || bx.gens.empty() || by.gens.empty()) return false;

  // Angle between the contact normals: R maps A's outward normal u at each contact onto
  // -m, m B's outward normal there, so the angle between u_x and u_y equals that between m_x
  // and m_y. Each side's angles form the interval [smallest, pi - smallest to the opposite].
  {
    auto neg = [](const NormalCone& c) {
      NormalCone n = c;
      for (Vec3& g : n.gens) g = -g;
      for (Vec3& h : n.facets) h = -h;
      return n;
    };
    const double a_lo = cone_cone_distance(ax, ay, angle_tol_);
    const double a_hi = M_PI - cone_cone_distance(ax, neg(ay), angle_tol_);
    const double b_lo = cone_cone_distance(bx, by, angle_tol_);
    const double b_hi = M_PI - cone_cone_distance(bx, neg(by), angle_tol_);
    if (a_lo > b_hi + 2 * angle_tol_ || b_lo > a_hi + 2 * angle_tol_) return false;
  }

  // Height of one contact point over the other's contact plane: with q = R p + t on both
  // contacts, (q_y - q_x) . m_x = -(p_y - p_x) . u_x.
  auto heights_meet = [&](const std::vector<Vec3>& pa1, const std::vector<Vec3>& pa2, const NormalCone& ca,
                          const std::vector<Vec3>& pb1, const std::vector<Vec3>& pb2, const NormalCone& cb) {
    const Range ra = height_range(pa1, pa2, ca, angle_tol_);  // (p_2 - p_1) . u
    const Range rb = height_range(pb1, pb2, cb, angle_tol_);  // (q_2 - q_1) . m
    // rb must meet -ra.
    return !(rb.lo > -ra.lo + length_tol_ || -ra.hi > rb.hi + length_tol_);
  };
  return heights_meet(pax, pay, ax, pbx, pby, bx) && heights_meet(pay, pax, ay, pby, pbx, by);
}

}  // namespace cf::gen
