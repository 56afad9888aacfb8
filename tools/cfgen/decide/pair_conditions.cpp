#include "cfgen/decide/pair_conditions.hpp"
#include "cfgen/verify/rotation_conditions.hpp"

#include <cf/geometry.hpp>

#include <algorithm>
#include <array>
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
    if ((in_arc(s, a, b, n1) && in_arc(s, c, d, n2)) ||
        (in_arc(-s, a, b, n1) && in_arc(-s, c, d, n2)))
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
    return {
        {std::cos(margin) * a + std::sin(margin) * w, std::cos(margin) * b + std::sin(margin) * v},
        {}};
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
    verts.push_back(info.cones[v].pointed ? shrink(polar_cone(info.cones[v].rays), margin)
                                          : NormalCone{});
  for (const Edge& e : m.edges())
    edges.push_back(
        e.convex ? shrink(NormalCone{{m.face(e.left).normal, m.face(e.right).normal}, {}}, margin)
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

// Whether some unit v perpendicular to the unit d keeps the wedge `own` at least own_need on
// v's side (w . v >= own_need for both its into-vectors) and the wedge `other` at least
// `need` on sg v's side, each into-vector perpendicular to d (to rounding). Each of the four
// conditions holds on an arc of the circle of such v, and arcs that meet share an end of one
// of them, or a centre when one covers the circle.
bool turn_allows(const Vec3& d, const EdgeWedge& own, double own_need, const EdgeWedge& other,
                 double sg, double need) {
  const std::array<std::pair<Vec3, double>, 4> conds{{{own.into_left, own_need},
                                                      {own.into_right, own_need},
                                                      {sg * other.into_left, need},
                                                      {sg * other.into_right, need}}};
  const Vec3 e1 = (std::abs(d.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(d).normalized();
  const Vec3 e2 = d.cross(e1);
  std::array<double, 1 + 3 * conds.size()> at{};  // 0, then each arc's centre and ends
  std::size_t n = 1;
  for (const auto& [w, c] : conds) {
    const double a = w.dot(e1), b = w.dot(e2), r = std::hypot(a, b);
    if (r < c) return false;
    const double centre = std::atan2(b, a), half = std::acos(std::clamp(c / r, -1.0, 1.0));
    at[n++] = centre;
    at[n++] = centre - half;
    at[n++] = centre + half;
  }
  constexpr double kRound = 1e-12;  // an arc's own end meets its condition to rounding
  return std::any_of(at.begin(), at.end(), [&](double t) {
    const Vec3 v = std::cos(t) * e1 + std::sin(t) * e2;
    return std::all_of(conds.begin(), conds.end(),
                       [&](const auto& wc) { return wc.first.dot(v) >= wc.second - kRound; });
  });
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

PairConditions::Side PairConditions::build(const ModelInfo& info, double cone_margin,
                                           double angle_tol, double contact_margin) {
  const Polyhedron& m = *info.model;
  Side side;
  side.cones = cones_of(info, cone_margin);
  std::vector<std::pair<ElementKind, int>> elems;
  std::vector<std::vector<Vec3>> points;
  for (int k = 0; k < 3; ++k) {
    side.offset[static_cast<std::size_t>(k)] = static_cast<int>(elems.size());
    for (std::size_t i = 0; i < side.cones[static_cast<std::size_t>(k)].size(); ++i) {
      elems.push_back({static_cast<ElementKind>(k), static_cast<int>(i)});
      points.push_back(inset_closure_points(m, static_cast<ElementKind>(k), static_cast<int>(i),
                                            contact_margin));
    }
  }
  side.n = static_cast<int>(elems.size());
  side.table.resize(static_cast<std::size_t>(side.n) * static_cast<std::size_t>(side.n));
  auto cone_of = [&](std::size_t e) -> const NormalCone& {
    return side.cones[static_cast<int>(elems[e].first)][static_cast<std::size_t>(elems[e].second)];
  };
  for (std::size_t x = 0; x < elems.size(); ++x)
    for (std::size_t y = 0; y < elems.size(); ++y) {
      Allowed& al = side.table[x * elems.size() + y];
      const NormalCone &cx = cone_of(x), &cy = cone_of(y);
      al.usable = !cx.gens.empty() && !cy.gens.empty();
      if (!al.usable) continue;
      if (y < x) {
        // Distances and angles are symmetric: copied from (y, x), computed first.
        const Allowed& yx = side.table[y * elems.size() + x];
        al.dist_lo = yx.dist_lo, al.dist_hi = yx.dist_hi, al.angle_lo = yx.angle_lo,
        al.angle_hi = yx.angle_hi;
      } else {
        al.dist_lo = element_distance(m, Pose(), elems[x].first, elems[x].second, m, elems[y].first,
                                      elems[y].second)
                         .distance;
        for (const Vec3& p : points[x])
          for (const Vec3& q : points[y]) al.dist_hi = std::max(al.dist_hi, (p - q).norm());
        NormalCone neg_y = cy;
        for (Vec3& g : neg_y.gens) g = -g;
        for (Vec3& h : neg_y.facets) h = -h;
        al.angle_lo = cone_cone_distance(cx, cy, angle_tol);
        al.angle_hi = M_PI - cone_cone_distance(cx, neg_y, angle_tol);
      }
      const Range h = height_range(points[x], points[y], cx, angle_tol);
      al.height_lo = h.lo, al.height_hi = h.hi;
    }
  return side;
}

PairConditions::PairConditions(const ModelInfo& A, const ModelInfo& B, double length_tol,
                               double angle_tol, double cone_margin, double contact_margin)
    : A_(A),
      B_(B),
      a_(build(A, cone_margin, angle_tol, contact_margin)),
      b_(build(B, cone_margin, angle_tol, contact_margin)),
      length_tol_(length_tol),
      angle_tol_(angle_tol),
      slack_(std::sin(cone_margin)) {}

bool PairConditions::forced_normal_fails(const Pc& x, const Pc& e) const {
  if (e.type != PcType::kEE || slack_ <= 0) return false;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  const Vec3& da = A.edges()[e.a].dir;
  const Vec3& db = B.edges()[e.b].dir;
  // At a witness the rotational condition holds to its tolerance and the e-e's edges are at
  // least the slack (a sine) from parallel, so the contact plane's normal N is within
  // 2 (tolerance + 2 kParallel) / slack of the direction (its component in the plane of the
  // two edges is at most their residuals over the sine between them).
  const double rot_tol = condition_tol(A_, a_kind(x.type), x.a, B_, b_kind(x.type), x.b);
  const double off = 2 * (rot_tol + 2 * kParallel) / slack_;
  const double need = slack_ - off;
  // verify's e-e terms with N = m (B's frame; B's edge's faces on the far side of it) and
  // with R^T N = u (A's frame; A's edge's faces on the near side).
  const EdgeWedge& wa = A_.wedges[e.a];
  const EdgeWedge& wb = B_.wedges[e.b];
  auto b_side = [&](const Vec3& m) {
    return std::min(-wb.into_left.dot(m), -wb.into_right.dot(m)) >= need;
  };
  auto a_side = [&](const Vec3& u) {
    return std::min(wa.into_left.dot(u), wa.into_right.dot(u)) >= need;
  };
  switch (x.type) {
    case PcType::kEF: {  // R d_x . n = 0 with d_x along da and db . n = 0: N = +-n
      const Vec3& n = B.faces()[x.b].normal;
      if (A.edges()[x.a].dir.cross(da).norm() > kParallel || std::abs(db.dot(n)) > kParallel)
        return false;
      // v = R^T n, perpendicular to the edges (to rot_tol): the e-f's own local margin
      // (its wedge on n's side) and the e-e's terms of A with N = sg n.
      auto turn = [&](double sg) {
        return turn_allows(da, A_.wedges[x.a], slack_ - rot_tol, wa, sg, need);
      };
      return !(b_side(n) && turn(1)) && !(b_side(-n) && turn(-1));
    }
    case PcType::kFE: {  // (R n) . d_x = 0 with d_x along db and da . n = 0: N = +-R n
      const Vec3& n = A.faces()[x.a].normal;
      if (B.edges()[x.b].dir.cross(db).norm() > kParallel || std::abs(da.dot(n)) > kParallel)
        return false;
      // u = R n, perpendicular to the edges: the f-e's local margin and the e-e's terms of B
      // with N = sg u (B's faces on the far side).
      auto turn = [&](double sg) {
        return turn_allows(db, B_.wedges[x.b], slack_ - rot_tol, wb, -sg, need);
      };
      return !(a_side(n) && turn(1)) && !(a_side(-n) && turn(-1));
    }
    case PcType::kFF: {  // R n_a = -n_b, da . n_a = 0, db . n_b = 0: N = +-n_b, R^T N = -+n_a
      const Vec3& na = A.faces()[x.a].normal;
      const Vec3& nb = B.faces()[x.b].normal;
      if (std::abs(da.dot(na)) > kParallel || std::abs(db.dot(nb)) > kParallel) return false;
      return !(b_side(nb) && a_side(-na)) && !(b_side(-nb) && a_side(na));
    }
    default:
      return false;
  }
}

const NormalCone& PairConditions::cone(bool of_a, ElementKind k, int i) const {
  return (of_a ? a_ : b_).cones[static_cast<int>(k)][static_cast<std::size_t>(i)];
}

bool PairConditions::parallel_normals_fail(const Pc& x, const Pc& y) const {
  if (x.type != PcType::kEE || y.type != PcType::kEE || slack_ <= 0) return false;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  if (A.edges()[x.a].dir.cross(A.edges()[y.a].dir).norm() > kParallel ||
      B.edges()[x.b].dir.cross(B.edges()[y.b].dir).norm() > kParallel)
    return false;
  // Each normal is its edges' cross product over its length, at least the slack at a
  // witness: edges kParallel from parallel on each side turn the two normals at most
  // 2 (2 kParallel) / slack from parallel.
  const double off = 4 * kParallel / slack_ + 2 * angle_tol_;
  const Allowed& a = a_.at(ElementKind::kEdge, x.a, ElementKind::kEdge, y.a);
  const Allowed& b = b_.at(ElementKind::kEdge, x.b, ElementKind::kEdge, y.b);
  const double lo = std::max(a.angle_lo, b.angle_lo), hi = std::min(a.angle_hi, b.angle_hi);
  return lo > off && hi < M_PI - off;
}

double PairConditions::condition_turn(const Pc& x) const {
  if (x.type != PcType::kFF && x.type != PcType::kEF && x.type != PcType::kFE) return 0;
  return condition_tol(A_, a_kind(x.type), x.a, B_, b_kind(x.type), x.b);
}

bool PairConditions::compatible(const Pc& x, const Pc& y) const {
  const ElementKind kax = a_kind(x.type), kay = a_kind(y.type), kbx = b_kind(x.type),
                    kby = b_kind(y.type);
  const Allowed& a = a_.at(kax, x.a, kay, y.a);
  const Allowed& b = b_.at(kbx, x.b, kby, y.b);
  // An element with no direction inside its cone cannot take part in a verified contact.
  if (!a.usable || !b.usable) return false;
  // Distance between the two contact points, the same measured in A and in B.
  if (a.dist_lo > b.dist_hi + length_tol_ || b.dist_lo > a.dist_hi + length_tol_) return false;
  // Angle between the contact normals: R maps A's outward normal u at each contact onto
  // -m, m B's outward normal there, so the angle between u_x and u_y equals that between m_x
  // and m_y. A line or plane PC holds its rotational condition only to its tolerance
  // (rotation_conditions.hpp), so its normal on one side is that far from the other side's
  // cone, and the angles may differ by as much.
  const double turn_x = condition_turn(x), turn_y = condition_turn(y);
  const double angle_tol = 2 * angle_tol_ + turn_x + turn_y;
  if (a.angle_lo > b.angle_hi + angle_tol || b.angle_lo > a.angle_hi + angle_tol) return false;
  // Height of one contact point over the other's contact plane: with q = R p + t on both
  // contacts, (q_y - q_x) . m_x = -(p_y - p_x) . u_x, so B's range must meet minus A's; and
  // the same over y's plane. Over a line or plane PC's plane the two sides differ by its
  // condition's tolerance times the distance between the points.
  auto heights_meet = [&](const Allowed& ha, const Allowed& hb, double turn) {
    const double tol = length_tol_ + turn * ha.dist_hi;
    return !(hb.height_lo > -ha.height_lo + tol || -ha.height_hi > hb.height_hi + tol);
  };
  // Last, a normal the rotation cannot choose: a few products, where the above are look-ups.
  return heights_meet(a, b, turn_x) &&
         heights_meet(a_.at(kay, y.a, kax, x.a), b_.at(kby, y.b, kbx, x.b), turn_y) &&
         !forced_normal_fails(x, y) && !forced_normal_fails(y, x) && !parallel_normals_fail(x, y);
}

}  // namespace cf::gen
