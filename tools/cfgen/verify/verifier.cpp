#include "cfgen/verify/verifier.hpp"

#include "cfgen/verify/near_pairs.hpp"
#include "cfgen/verify/rotation_conditions.hpp"
#include "cfgen/verify/touch.hpp"

#include <cf/geometry.hpp>
#include <cf/motion.hpp>
#include <cf/params.hpp>

#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>

namespace cf::gen {

using namespace internal;

namespace {

// The distance of a pair of faces from the edge-face distances verify measured before it.
// face_face (cf/geometry.hpp) is the least distance of an edge of either face to the other
// face. NearPairs lists every such edge-face pair within its reach, as e-f or f-e and before
// the pair of faces, so the least of those measured is face_face's value, computed by the
// same arithmetic; none measured proves the faces farther apart than the reach, where verify
// only needs to know that. Saves the face pairs' point locations: most of a check's time.
class FaceDistances {
 public:
  void clear() {
    a_edges_.clear();
    b_edges_.clear();
  }
  // d: the distance between edge e of A and face f of B (a_edge), or face f of A and edge e
  // of B (b_edge).
  void a_edge(int e, int f, double d) { a_edges_.push_back({e, f, d}); }
  void b_edge(int f, int e, double d) { b_edges_.push_back({e, f, d}); }
  // Face fa of A and face fb of B: their distance, or infinity when beyond the reach.
  double faces(const Polyhedron& A, const Polyhedron& B, int fa, int fb) const {
    double d = std::numeric_limits<double>::infinity();
    for (const Measured& m : a_edges_)
      if (m.face == fb && bounds(A.edges()[static_cast<std::size_t>(m.edge)], fa))
        d = std::min(d, m.d);
    for (const Measured& m : b_edges_)
      if (m.face == fa && bounds(B.edges()[static_cast<std::size_t>(m.edge)], fb))
        d = std::min(d, m.d);
    return d;
  }

 private:
  struct Measured {
    int edge, face;
    double d;
  };
  static bool bounds(const Edge& e, int f) { return e.left.value() == f || e.right.value() == f; }
  std::vector<Measured> a_edges_, b_edges_;
};

// An upper bound of an e-e's local margin (the sine of the angle between the edges, and how
// far the plane holding both is from cutting either wedge) over the rotations `turn`
// allows: the edges' cross product c moves by at most d = turn(edge of A), its direction N by
// at most 2 d / |c| (|u/|u| - v/|v|| <= 2 |u - v| / |v|).
double ee_margin_bound(const ModelInfo& A_, const ModelInfo& B_, const Pc& pc, const Mat3& R,
                       const TurnBound& turn) {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  if (!A.edges()[pc.a].convex || !B.edges()[pc.b].convex) return -1;
  const EdgeWedge& wa = A_.wedges[pc.a];
  const EdgeWedge& wb = B_.wedges[pc.b];
  const double d = turn.of(A.edges()[pc.a].dir);
  Vec3 N = (R * A.edges()[pc.a].dir).cross(B.edges()[pc.b].dir);
  const double sin_cross = N.norm();
  if (d == 0 && sin_cross < 1e-9) return -1;
  if (sin_cross <= d) return sin_cross + d;  // N may point anywhere
  N /= sin_cross;
  const double dN = 2 * d / sin_cross;
  auto side = [&](const Vec3& n) {
    return std::min({-wb.into_left.dot(n) + dN, -wb.into_right.dot(n) + dN,
                     (R * wa.into_left).dot(n) + turn.of(wa.into_left) + dN,
                     (R * wa.into_right).dot(n) + turn.of(wa.into_right) + dN});
  };
  return std::min(sin_cross + d, std::max(side(N), side(-N)));
}

using Vec2 = Eigen::Vector2d;

// The largest value, over the unit vectors n of the plane allowed by `in`, of the least of
// the terms p_i . n + c_i (sinusoids in n's angle): attained at an end of an allowed arc
// (`ends`), at the maximum of one term, or where two terms are equal.
template <class In>
double max_of_least(const std::array<Vec2, 4>& p, const std::array<double, 4>& c,
                    const std::array<Vec2, 4>& ends, int n_ends, const In& in) {
  auto least = [&](const Vec2& n) {
    double m = HUGE_VAL;
    for (std::size_t i = 0; i < p.size(); ++i) m = std::min(m, p[i].dot(n) + c[i]);
    return m;
  };
  double best = -HUGE_VAL;
  for (int k = 0; k < n_ends; ++k) best = std::max(best, least(ends[static_cast<std::size_t>(k)]));
  auto take = [&](const Vec2& n) {
    if (in(n)) best = std::max(best, least(n));
  };
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (const double r = p[i].norm(); r > 0) take(p[i] / r);
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const Vec2 q = p[i] - p[j];  // terms i and j equal: q . n = c_j - c_i
      const double r = q.norm(), x = (c[j] - c[i]) / r;
      if (!(std::abs(x) <= 1)) continue;
      const Vec2 u = q / r, v(-u.y(), u.x());
      const double y = std::sqrt(1 - x * x);
      take(x * u + y * v);
      take(x * u - y * v);
    }
  }
  return best;
}

// A second upper bound of an e-e's local margin over the rotations `turn` allows, one that
// does not divide by the sine between the edges (docs/certificates.md, "The local margin").
// The contact normal n is a unit vector perpendicular to B's edge b and to A's turned edge,
// so |n . (R_c e_A)| <= d = turn(e_A): the whole circle perpendicular to b when the edges
// may turn parallel, else two arcs about the normals at R_c. Each wedge term is bounded at
// every such n, A's by how far the turn moves its into-face vector: near parallel edges the
// wedges still have to face each other.
double ee_margin_arc_bound(const ModelInfo& A_, const ModelInfo& B_, const Pc& pc, const Mat3& R,
                           const TurnBound& turn) {
  // Rounded up by far more than its own rounding, and far less than any slack: a checker that
  // guards its own rounding more widely (tests/oracle) still finds the leaf below the slack.
  constexpr double kRounding = 1e-7;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  const EdgeWedge& wa = A_.wedges[pc.a];
  const EdgeWedge& wb = B_.wedges[pc.b];
  const Vec3& b = B.edges()[pc.b].dir;
  const Vec3 e1 = b.unitOrthogonal(), e2 = b.cross(e1);
  auto plane = [&](const Vec3& v) { return Vec2(v.dot(e1), v.dot(e2)); };
  const Vec3& ea = A.edges()[pc.a].dir;
  const double d = turn.of(ea);
  const std::array<Vec2, 4> p{-plane(wb.into_left), -plane(wb.into_right), plane(R * wa.into_left),
                              plane(R * wa.into_right)};
  const std::array<double, 4> c{0, 0, turn.of(wa.into_left), turn.of(wa.into_right)};
  const Vec2 r = plane(R * ea);  // n . (R_c e_A) = r . n, and |r| = s_c, the edges' sine
  const double s = r.norm();
  const double cap = s + d + kRounding;  // the sine's own bound, as ee_margin_bound has it
  if (s <= d) {
    const double best = max_of_least(p, c, {}, 0, [](const Vec2&) { return true; });
    return std::min(cap, best + kRounding);
  }
  // The arcs |r . n| <= d about m and -m, m the normal at R_c: n . m >= sqrt(1 - (d/s)^2).
  const Vec2 m = Vec2(-r.y(), r.x()) / s, side = r / s;
  const double sin_half = std::min(1.0, d / s), cos_half = std::sqrt(1 - sin_half * sin_half);
  const std::array<Vec2, 4> ends{cos_half * m + sin_half * side, cos_half * m - sin_half * side,
                                 -cos_half * m + sin_half * side, -cos_half * m - sin_half * side};
  const double best = max_of_least(p, c, ends, 4, [&](const Vec2& n) {
    return std::abs(n.dot(m)) >= cos_half - kRounding;  // admits a little more: stays a bound
  });
  return std::min(cap, best + kRounding);
}

// Whether ee_margin_arc_bound can be much tighter than ee_margin_bound: where the turn moves
// the contact normal's direction (2 d / |c|) by more than a few hundredths, e.g. near
// parallel edges. Elsewhere the two differ little and the first is cheaper.
bool arc_bound_helps(const ModelInfo& A_, const ModelInfo& B_, const Pc& pc, const Mat3& R,
                     const TurnBound& turn) {
  constexpr double kNormalTurn = 0.05;
  const Vec3& ea = A_.model->edges()[pc.a].dir;
  const double d = turn.of(ea);
  return d > 0 && 2 * d > kNormalTurn * (R * ea).cross(B_.model->edges()[pc.b].dir).norm();
}

}  // namespace

Verifier::Verifier(const ModelInfo& a, const ModelInfo& b, const SearchParams& p)
    : A_(a),
      B_(b),
      p_(p),
      scale_(std::max(a.model->size(), b.model->size())),
      direction_tol_(direction_tol(a, b)) {}

double Verifier::verified_local_slack() const { return 0.5 * std::sin(p_.angle_margin); }

double local_margin_bound(const ModelInfo& A_, const ModelInfo& B_, const PcSet& pcs, const Mat3& R,
                          const TurnBound& turn, int* which, EeBound ee) {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  double m = 1.0;
  if (which) *which = -1;
  // Each term is a dot product of two unit vectors, one of them turned: over the rotations
  // it exceeds its value at R by at most how far `turn` lets that one move.
  auto cone_term = [&](const auto& rays, const Vec3& n, bool rays_turn, double dn) {
    double t = 1.0;
    for (const Vec3& r : rays) t = std::min(t, r.dot(n) + (rays_turn ? turn.of(r) : dn));
    return t;
  };
  for (int k = 0; k < pcs.size(); ++k) {
    const Pc& pc = pcs[k];
    double t = 1.0;
    switch (pc.type) {
      case PcType::kFF: {
        const Vec3& na = A.faces()[pc.a].normal;
        t = 1.0 - (R * na + B.faces()[pc.b].normal).norm() + turn.of(na);
        break;
      }
      case PcType::kVF:
        t = !A_.cones[pc.a].pointed
                ? -1
                : cone_term(A_.cones[pc.a].rays, R.transpose() * B.faces()[pc.b].normal, true, 0);
        break;
      case PcType::kFV: {
        const Vec3& na = A.faces()[pc.a].normal;
        t = !B_.cones[pc.b].pointed ? -1
                                    : cone_term(B_.cones[pc.b].rays, R * na, false, turn.of(na));
        break;
      }
      case PcType::kEF: {
        const EdgeWedge& w = A_.wedges[pc.a];
        t = !A.edges()[pc.a].convex ? -1
                                    : cone_term(std::array<Vec3, 2>{w.into_left, w.into_right},
                                                R.transpose() * B.faces()[pc.b].normal, true, 0);
        break;
      }
      case PcType::kFE: {
        const Vec3& na = A.faces()[pc.a].normal;
        const EdgeWedge& w = B_.wedges[pc.b];
        t = !B.edges()[pc.b].convex ? -1
                                    : cone_term(std::array<Vec3, 2>{w.into_left, w.into_right},
                                                R * na, false, turn.of(na));
        break;
      }
      case PcType::kEE:
        t = ee_margin_bound(A_, B_, pc, R, turn);
        if (ee == EeBound::kTightest && t > -1 && arc_bound_helps(A_, B_, pc, R, turn))
          t = std::min(t, ee_margin_arc_bound(A_, B_, pc, R, turn));
        break;
    }
    if (t < m) {
      m = t;
      if (which) *which = k;
    }
  }
  return m;
}

double Verifier::local_margin(const PcSet& pcs, const Mat3& R) const {
  return local_margin_bound(A_, B_, pcs, R, TurnBound{});
}

std::pair<Vec3, double> Verifier::contact_plane(const Pc& pc, const Pose& pose) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  switch (pc.type) {
    case PcType::kFF:
    case PcType::kEF:
    case PcType::kVF: {
      const Face& fb = B.faces()[pc.b];
      return {fb.normal, fb.offset};
    }
    case PcType::kFE:
    case PcType::kFV: {
      const Face& fa = A.faces()[pc.a];
      const Vec3 n = -(pose.R_BA * fa.normal);
      return {n, n.dot(pose.apply(fa.centroid))};
    }
    case PcType::kEE: {
      const Edge& ea = A.edges()[pc.a];
      const Edge& eb = B.edges()[pc.b];
      Vec3 n = (pose.R_BA * ea.dir).cross(eb.dir).normalized();
      if (B_.wedges[pc.b].bisector.dot(n) < 0) n = -n;  // into A, away from B
      return {n, n.dot(B.vertices()[eb.v0.index()].p)};
    }
  }
  return {Vec3::UnitY(), 0.0};
}

std::string kind_name(ElementKind k) {
  return k == ElementKind::kVertex ? "v" : k == ElementKind::kEdge ? "e" : "f";
}

namespace {

Pc pc_of(const PcSet& pcs, ElementKind ka, int a, ElementKind kb, int b) {
  for (const Pc& pc : pcs)
    if (a_kind(pc.type) == ka && b_kind(pc.type) == kb && pc.a == a && pc.b == b) return pc;
  return {};
}

}  // namespace

bool Verifier::cones_disjoint(const Pose& pose, ElementKind ka, int a, ElementKind kb,
                              int b) const {
  using K = ElementKind;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  const double tol = direction_tol_;  // on unit directions
  const Mat3& R = pose.R_BA;
  // A point on the open touching set, and a short probe length that stays near it.
  const ClosestPoints cp = element_distance(A, pose, ka, a, B, kb, b);
  const Vec3 x = cp.p_b;
  double h = scale_;
  auto shorten = [&](const Polyhedron& m, ElementKind k, int i) {
    if (k == K::kVertex)
      for (EdgeId e : m.vertices()[i].edges) h = std::min(h, m.edge(e).length);
    else if (k == K::kEdge)
      h = std::min(h, m.edges()[i].length);
  };
  shorten(A, ka, a);
  shorten(B, kb, b);
  h *= 1e-4;
  auto inside_a = [&](const Vec3& p_B) {
    return point_inside(A, pose.inverse_apply(p_B), 1e-3 * h);
  };
  auto inside_b = [&](const Vec3& p_B) { return point_inside(B, p_B, 1e-3 * h); };
  // B's wedge at a convex edge lies in A's closed outer half-space {y : n . y >= 0}.
  auto wedge_b_outside = [&](int e, const Vec3& n) {
    return B.edges()[e].convex && B_.wedges[e].into_left.dot(n) >= -tol &&
           B_.wedges[e].into_right.dot(n) >= -tol;
  };
  auto wedge_a_outside = [&](int e, const Vec3& n) {  // n in B's frame, outward of B
    return A.edges()[e].convex && (R * A_.wedges[e].into_left).dot(n) >= -tol &&
           (R * A_.wedges[e].into_right).dot(n) >= -tol;
  };
  if (ka == K::kFace && kb == K::kFace)
    return (R * A.faces()[a].normal).dot(B.faces()[b].normal) < -1 + tol;
  if (ka == K::kFace && kb == K::kEdge) return wedge_b_outside(b, R * A.faces()[a].normal);
  if (ka == K::kEdge && kb == K::kFace) return wedge_a_outside(a, B.faces()[b].normal);
  if (ka == K::kVertex && kb == K::kFace) {
    const Vec3& n = B.faces()[b].normal;
    for (const Vec3& r : A_.cones[a].rays)
      if ((R * r).dot(n) < -tol) return false;
    return A_.cones[a].pointed || !inside_a(x - h * n);
  }
  if (ka == K::kFace && kb == K::kVertex) {
    const Vec3 n = R * A.faces()[a].normal;
    for (const Vec3& r : B_.cones[b].rays)
      if (r.dot(n) < -tol) return false;
    return B_.cones[b].pointed || !inside_b(x - h * n);
  }
  if (ka == K::kEdge && kb == K::kEdge) {
    const Vec3 da = R * A.edges()[a].dir;
    const Vec3& db = B.edges()[b].dir;
    Vec3 N = da.cross(db);
    if (N.norm() > tol) {  // edges parallel to the models' precision are collinear
      // Crossing edges: the only plane that can separate the wedges holds both edges. An
      // edge tilted by tol (models known to a precision) turns that plane by tol over the
      // sine between the edges.
      if (!A.edges()[a].convex || !B.edges()[b].convex) return false;
      const double side_tol = tol > 1e-9 ? tol / N.norm() : tol;
      N.normalize();
      auto side = [&](const Vec3& n) {
        return std::min({B_.wedges[b].into_left.dot(n), B_.wedges[b].into_right.dot(n),
                         -(R * A_.wedges[a].into_left).dot(n),
                         -(R * A_.wedges[a].into_right).dot(n)});
      };
      return std::max(side(N), side(-N)) >= -side_tol;
    }
    // Collinear edges: the two wedges' angular sectors about the common line must not overlap.
    const Vec3 u = B_.wedges[b].into_left, w = db.cross(u);
    auto angle = [&](const Vec3& v) {
      const double t = std::atan2(v.dot(w), v.dot(u));
      return t < 0 ? t + 2 * M_PI : t;
    };
    // Each sector as [start, start + width] going round +db from into_right to into_left
    // (or the reverse), the width being the interior dihedral angle.
    auto sector = [&](const Vec3& from, const Vec3& to, double width) {
      double s0 = angle(from), s1 = angle(to);
      double ccw = s1 - s0;
      if (ccw < 0) ccw += 2 * M_PI;
      // The sector runs ccw from `from` when that sweep equals the width, else ccw from `to`.
      if (std::abs(ccw - width) < 1e-6) return std::pair{s0, width};
      return std::pair{s1, width};
    };
    const auto sb = sector(B_.wedges[b].into_right, B_.wedges[b].into_left, B.edges()[b].dihedral);
    const auto sa =
        sector(R * A_.wedges[a].into_right, R * A_.wedges[a].into_left, A.edges()[a].dihedral);
    auto overlap = [&](std::pair<double, double> p, std::pair<double, double> q) {
      double off = q.first - p.first;
      off = std::fmod(off + 4 * M_PI, 2 * M_PI);  // q starts this far ccw from p
      if (off < p.second - 1e-6) return true;     // q starts inside p
      return off + q.second > 2 * M_PI + 1e-6;    // q wraps round into p's start
    };
    return !overlap(sa, sb) && !overlap(sb, sa);
  }
  // A vertex against an edge or a vertex: probe into each solid's cone along its inward
  // axis and check that the point is outside the other solid.
  auto inward_b = [&]() -> Vec3 {
    if (kb == K::kEdge) return -B_.wedges[b].bisector;
    return B_.cones[b].pointed ? Vec3(B_.cones[b].center) : Vec3::Zero();
  };
  auto inward_a = [&]() -> Vec3 {
    if (ka == K::kEdge) return -(R * A_.wedges[a].bisector);
    return A_.cones[a].pointed ? Vec3(R * A_.cones[a].center) : Vec3::Zero();
  };
  const Vec3 ib = inward_b(), ia = inward_a();
  if (ib.norm() > 0.5 && inside_a(x + h * ib)) return false;
  if (ia.norm() > 0.5 && inside_b(x + h * ia)) return false;
  return true;
}

double Verifier::verify(const PcSet& pcs, const Pose& pose, std::string* why) const {
  return verify(pcs, pose, why, nullptr);
}

namespace {

// mm: tilt_allowance of each PC of a set.
using PcTilts = std::array<double, PcSet::kMaxPcs>;
PcTilts pc_tilts(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs) {
  PcTilts t{};
  for (int i = 0; i < pcs.size(); ++i) t[i] = tilt_allowance(a, b, pcs[i]);
  return t;
}

// Whether the closures of elements x and y of m share a vertex.
bool closures_meet(const Polyhedron& m, ElementKind kx, int x, ElementKind ky, int y) {
  auto in_y = [&](VertexId v) { return in_closure(m, ElementKind::kVertex, v.value(), ky, y); };
  if (kx == ElementKind::kFace) {
    const auto& vs = m.faces()[x].vertices;
    return std::any_of(vs.begin(), vs.end(), in_y);
  }
  if (kx == ElementKind::kEdge) return in_y(m.edges()[x].v0) || in_y(m.edges()[x].v1);
  return in_y(VertexId(x));
}

// Whether elements a of A and b of B, d apart (mm), touch in open points within tol (mm).
bool touching(const Polyhedron& A, const Pose& pose, ElementKind ka, int a, const Polyhedron& B,
              ElementKind kb, int b, double d, double tol) {
  return d <= tol && open_touch(A, pose, ka, a, B, kb, b, tol);
}

// mm: how close elements a of A and b of B must be to touch: touch_tol, and where both meet
// a line or plane PC's elements (share a vertex with them) that lie along each other only to
// the PC's tilt (tilt_allowance), that tilt more: the faces beside a face-edge PC that meet
// along its edge are that far apart, not touching.
double touch_along(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs, const PcTilts& tilt,
                   double touch_tol, ElementKind ka, int a, ElementKind kb, int b) {
  double along = touch_tol;
  for (int i = 0; i < pcs.size(); ++i)
    if (tilt[i] > 0 && closures_meet(A, ka, a, a_kind(pcs[i].type), pcs[i].a) &&
        closures_meet(B, kb, b, b_kind(pcs[i].type), pcs[i].b))
      along = std::max(along, touch_tol + tilt[i]);
  return along;
}

}  // namespace

bool covered_by(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs, ElementKind ka, int a,
                ElementKind kb, int b) {
  for (const Pc& pc : pcs)
    if (in_closure(A, ka, a, a_kind(pc.type), pc.a) && in_closure(B, kb, b, b_kind(pc.type), pc.b))
      return true;
  return false;
}

bool Verifier::still_blocked(const PcSet& pcs, const Pose& pose, const Obstacle& o) const {
  if (!o.set) return false;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  if (covered_by(A, B, pcs, o.ka, o.a, o.kb, o.b)) return false;  // verify judges those otherwise
  const double d = element_distance(A, pose, o.ka, o.a, B, o.kb, o.b).distance;
  if (d >= p_.min_clearance) return false;
  return d > p_.touch_tol || touching(A, pose, o.ka, o.a, B, o.kb, o.b, d, p_.touch_tol);
}

bool Verifier::obstacle_touches(const Pose& pose, const Obstacle& o) const {
  if (!o.set) return false;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  return touching(A, pose, o.ka, o.a, B, o.kb, o.b,
                  element_distance(A, pose, o.ka, o.a, B, o.kb, o.b).distance, p_.touch_tol);
}

bool Verifier::still_fails(const PcSet& pcs, const Pose& pose, const FailedPair& f) const {
  if (f.kind == FailedPair::Kind::kObstacle) return still_blocked(pcs, pose, f.obstacle());
  if (f.kind != FailedPair::Kind::kOverlap) return false;
  // verify's overlap test, for a pair that is a PC or covered by one (as recorded).
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  return overlap_at(
      pose, f.ka, f.a, f.kb, f.b, element_distance(A, pose, f.ka, f.a, B, f.kb, f.b).distance,
      touch_along(A, B, pcs, pc_tilts(A_, B_, pcs), p_.touch_tol, f.ka, f.a, f.kb, f.b));
}

bool Verifier::overlap_at(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b, double d,
                          double tol) const {
  return touching(*A_.model, pose, ka, a, *B_.model, kb, b, d, tol) &&
         !cones_disjoint(pose, ka, a, kb, b);
}

double Verifier::verify(const PcSet& pcs, const Pose& pose, std::string* why,
                        FailedPair* failed) const {
  // The reason is written only when asked for: verify runs millions of times a run, most of
  // them to reject, and a message built each time would be a heap allocation or five.
  auto reject = [&](const char* reason) {
    if (why) *why = reason;
    return -1.0;
  };
  auto reject_with = [&](const auto& reason) {
    if (why) *why = reason();
    return -1.0;
  };
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  if (local_margin(pcs, pose.R_BA) < verified_local_slack()) return reject("locally penetrating");
  // Line and plane PCs need their rotational conditions (a rotation found by a motion may
  // only nearly satisfy them).
  {
    const RotConstraints c = rotation_constraints(pcs, A_, B_);
    if (!satisfies(c, pose.R_BA)) return reject("a line or plane PC is not parallel to its face");
  }
  // Pairwise distinct contact planes.
  for (int i = 0; i < pcs.size(); ++i)
    for (int j = i + 1; j < pcs.size(); ++j) {
      const auto [ni, di] = contact_plane(pcs[i], pose);
      const auto [nj, dj] = contact_plane(pcs[j], pose);
      const double c = ni.dot(nj);
      if (std::abs(c) > 1 - 1e-9 && std::abs(di - (c > 0 ? dj : -dj)) < 1e-6 * scale_)
        return reject("two PCs share a contact plane");
    }
  double clearance = std::numeric_limits<double>::infinity();
  // Per thread, reused (verify runs hundreds of thousands of times a run).
  thread_local std::vector<double> a_vertex_gap, b_vertex_gap;
  a_vertex_gap.assign(A.num_vertices(), clearance);
  b_vertex_gap.assign(B.num_vertices(), clearance);
  int touching_pcs = 0;
  const PcTilts tilt = pc_tilts(A_, B_, pcs);
  // Pairs proven farther apart than good_clearance can neither touch nor lower the clearance
  // below what counts as good: not measured.
  NearPairs near(A_, B_, pose, p_.good_clearance);
  thread_local FaceDistances face_pairs;
  face_pairs.clear();
  for (ElementPair e; near.next(e);) {
    const ElementKind ka = e.ka, kb = e.kb;
    const int a = e.a, b = e.b;
    using K = ElementKind;
    const double d = ka == K::kFace && kb == K::kFace
                         ? face_pairs.faces(A, B, a, b)
                         : element_distance(A, pose, ka, a, B, kb, b).distance;
    if (ka == K::kEdge && kb == K::kFace) face_pairs.a_edge(a, b, d);
    if (ka == K::kFace && kb == K::kEdge) face_pairs.b_edge(a, b, d);
    if (ka == ElementKind::kVertex) a_vertex_gap[a] = std::min(a_vertex_gap[a], d);
    if (kb == ElementKind::kVertex) b_vertex_gap[b] = std::min(b_vertex_gap[b], d);
    bool is_pc = false;
    for (const Pc& pc : pcs)
      if (a_kind(pc.type) == ka && b_kind(pc.type) == kb && pc.a == a && pc.b == b) is_pc = true;
    const bool covered = covered_by(A, B, pcs, ka, a, kb, b);
    const double along = touch_along(A, B, pcs, tilt, p_.touch_tol, ka, a, kb, b);
    if (is_pc) {
      if (d > along)
        return reject_with([&] {
          return "PC " + to_string(pc_of(pcs, ka, a, kb, b)) + " apart by " + std::to_string(d);
        });
      // The open elements must touch: a face meeting an edge only at its own boundary
      // realises an edge-edge PC, not face-edge.
      if (!open_touch(A, pose, ka, a, B, kb, b, along))
        return reject_with([&] {
          return "PC " + to_string(pc_of(pcs, ka, a, kb, b)) + " touches only on its boundary";
        });
      ++touching_pcs;
    }
    // Where two elements share open points, A's and B's tangent cones there must have
    // disjoint interiors; pairs that touch only through their boundaries are judged
    // as those boundary pairs. This catches a face of A running through a reflex edge
    // of B, which no pair reports as crossing.
    if ((is_pc || covered) && overlap_at(pose, ka, a, kb, b, d, along)) {
      if (failed) *failed = FailedPair{FailedPair::Kind::kOverlap, ka, kb, a, b};
      return reject_with([&] {
        return "A and B overlap where " + kind_name(ka) + std::to_string(a) + " touches " +
               kind_name(kb) + std::to_string(b);
      });
    }
    if (!is_pc && !covered) {
      // Closed elements that meet only on their boundaries do not touch: their boundary
      // elements do, and those pairs are judged on their own.
      if (d <= along && !open_touch(A, pose, ka, a, B, kb, b, along)) continue;
      if (d < p_.min_clearance) {
        if (failed) *failed = FailedPair{FailedPair::Kind::kObstacle, ka, kb, a, b};
        return reject_with([&] {
          return "extra contact " + kind_name(ka) + std::to_string(a) + "-" + kind_name(kb) +
                 std::to_string(b) + " at " + std::to_string(d);
        });
      }
      clearance = std::min(clearance, d);
    }
  }
  if (touching_pcs != pcs.size()) return reject("a PC is not touching");
  // Neither solid inside the other: test the vertex of each farthest from the other solid.
  const auto ia = std::max_element(a_vertex_gap.begin(), a_vertex_gap.end()) - a_vertex_gap.begin();
  const auto ib = std::max_element(b_vertex_gap.begin(), b_vertex_gap.end()) - b_vertex_gap.begin();
  if (a_vertex_gap[ia] > p_.touch_tol &&
      point_inside(B, pose.apply(A.vertices()[ia].p), p_.touch_tol))
    return reject("A inside B");
  if (b_vertex_gap[ib] > p_.touch_tol &&
      point_inside(A, pose.inverse_apply(B.vertices()[ib].p), p_.touch_tol))
    return reject("B inside A");
  // Pairs beyond good_clearance are not listed (which of them are depends on the listing's
  // bounds), so a clearance beyond it is reported as good_clearance: always finite.
  return std::min(clearance, p_.good_clearance);
}

bool Verifier::contacts_at(const Pose& pose, PcSet& out, std::string* why) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  using K = ElementKind;
  // Pairs within touch_tol (closed elements), and those touching in their open interiors.
  thread_local std::vector<ElementPair> close, touching;  // reused, as verify's
  close.clear();
  touching.clear();
  // near_pairs lists pairs in ascending kinds, so the pairs of an element pair's boundary
  // elements come before it. Where one of those is within touch_tol, so is the pair (closed
  // elements). Otherwise an edge and a face, or two faces, are farther apart unless the edge
  // crosses the face's plane: the distance between two planar regions, or between a segment
  // and a region it does not cross, is reached on a boundary. near_pairs' plane bound has
  // already dropped the edges that do not cross, so the costly face-face distance is never
  // measured here, and the edge-face one only for an edge crossing the face's plane.
  auto bounded_by_close = [&](const ElementPair& e) {
    for (const ElementPair& c : close)
      if (in_closure(A, c.ka, c.a, e.ka, e.a) && in_closure(B, c.kb, c.b, e.kb, e.b)) return true;
    return false;
  };
  NearPairs near(A_, B_, pose, p_.touch_tol);
  for (ElementPair e; near.next(e);) {
    if (!bounded_by_close(e)) {
      if (e.ka == K::kFace && e.kb == K::kFace) continue;
      if (element_distance(A, pose, e.ka, e.a, B, e.kb, e.b).distance > p_.touch_tol) continue;
    }
    close.push_back(e);
    if (!open_touch(A, pose, e.ka, e.a, B, e.kb, e.b, p_.touch_tol)) continue;
    touching.push_back(e);
  }
  out = PcSet();
  for (std::size_t i = 0; i < touching.size(); ++i) {
    const ElementPair& x = touching[i];
    bool dominated = false;
    for (std::size_t j = 0; j < touching.size() && !dominated; ++j) {
      const ElementPair& y = touching[j];
      dominated =
          j != i && in_closure(A, x.ka, x.a, y.ka, y.a) && in_closure(B, x.kb, x.b, y.kb, y.b);
    }
    if (dominated) continue;
    // The reason is built only when asked for: contacts_at runs at every step of the motions.
    auto fail = [&](const char* reason, const char* detail = "") {
      if (why)
        *why = reason + kind_name(x.ka) + std::to_string(x.a) + "-" + kind_name(x.kb) +
               std::to_string(x.b) + detail;
      return false;
    };
    if (x.ka == K::kVertex && x.kb != K::kFace) return fail("degenerate touch ");
    if (x.kb == K::kVertex && x.ka != K::kFace) return fail("degenerate touch ");
    if (x.ka == K::kEdge && x.kb == K::kEdge &&
        (pose.R_BA * A.edges()[x.a].dir).cross(B.edges()[x.b].dir).norm() < 1e-9)
      return fail("degenerate touch ", " (parallel edges)");
    PcType t = PcType::kFF;
    if (x.ka == K::kFace)
      t = x.kb == K::kFace ? PcType::kFF : x.kb == K::kEdge ? PcType::kFE : PcType::kFV;
    else if (x.ka == K::kEdge)
      t = x.kb == K::kFace ? PcType::kEF : PcType::kEE;
    else
      t = PcType::kVF;
    if (!out.insert(Pc{t, x.a, x.b})) return fail("more than three PCs, the fourth ");
  }
  return true;
}

double Verifier::contact_margin(const PcSet& pcs, const Pose& pose) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  double m = std::numeric_limits<double>::infinity();
  // How far a point of an edge lies inside the open edge and inside the face (B's frame).
  auto edge_in_face = [&](const Vec3& p0, const Vec3& p1, const Polyhedron& fm, FaceId f,
                          bool face_on_a) {
    double best = 0;
    const double len = (p1 - p0).norm();
    for (int k = 1; k < 64; ++k) {
      const double s = k / 64.0;
      const Vec3 x = p0 + s * (p1 - p0);
      const double in_face = fm.face_inset(f, face_on_a ? pose.inverse_apply(x) : x);
      best = std::max(best, std::min({in_face, s * len, (1 - s) * len}));
    }
    return best;
  };
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kVF:
        m = std::min(m, B.face_inset(FaceId(pc.b), pose.apply(A.vertices()[pc.a].p)));
        break;
      case PcType::kFV:
        m = std::min(m, A.face_inset(FaceId(pc.a), pose.inverse_apply(B.vertices()[pc.b].p)));
        break;
      case PcType::kEF:
        m = std::min(
            m, edge_in_face(pose.apply(A.edge_point(EdgeId(pc.a), 0)),
                            pose.apply(A.edge_point(EdgeId(pc.a), 1)), B, FaceId(pc.b), false));
        break;
      case PcType::kFE:
        m = std::min(m, edge_in_face(B.edge_point(EdgeId(pc.b), 0), B.edge_point(EdgeId(pc.b), 1),
                                     A, FaceId(pc.a), true));
        break;
      case PcType::kEE: {
        const Vec3 p0 = pose.apply(A.edge_point(EdgeId(pc.a), 0)),
                   p1 = pose.apply(A.edge_point(EdgeId(pc.a), 1));
        const Vec3& q0 = B.edge_point(EdgeId(pc.b), 0);
        const Vec3& q1 = B.edge_point(EdgeId(pc.b), 1);
        const ClosestPoints cp = segment_segment(p0, p1, q0, q1);
        m = std::min({m, (cp.p_a - p0).norm(), (cp.p_a - p1).norm(), (cp.p_b - q0).norm(),
                      (cp.p_b - q1).norm()});
        break;
      }
      case PcType::kFF: {
        // At the centroid of the largest piece of the overlap region.
        const std::optional<Vec3> x = face_overlap_centroid(A, pose, pc.a, B, pc.b);
        m = std::min(m,
                     x ? std::max(0.0, std::min(B.face_inset(FaceId(pc.b), *x),
                                                A.face_inset(FaceId(pc.a), pose.inverse_apply(*x))))
                       : 0.0);
        break;
      }
    }
  }
  return m;
}

void Verifier::freedoms(const PcSet& pcs, const Pose& pose, CfRecord& out) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  // The run time's constraint points (cf::compute_freedoms): the contact point of a point
  // PC, two points of a contact line, three of a contact plane, all with the contact normal.
  const double L = std::max(A.size(), 1e-9);
  ConstraintPoint pts[Freedoms::kMaxRows];
  int n = 0;
  auto add = [&](const Vec3& p, const Vec3& nrm) {
    if (n < Freedoms::kMaxRows) pts[n++] = {p, nrm};
  };
  for (const Pc& pc : pcs) {
    const Vec3 nrm = contact_plane(pc, pose).first;
    switch (pc.type) {
      case PcType::kVF:
        add(pose.apply(A.vertices()[pc.a].p), nrm);
        break;
      case PcType::kFV:
        add(B.vertices()[pc.b].p, nrm);
        break;
      case PcType::kEF:
        add(pose.apply(A.edge_point(EdgeId(pc.a), 0)), nrm);
        add(pose.apply(A.edge_point(EdgeId(pc.a), 1)), nrm);
        break;
      case PcType::kFE:
        add(B.edge_point(EdgeId(pc.b), 0), nrm);
        add(B.edge_point(EdgeId(pc.b), 1), nrm);
        break;
      case PcType::kFF: {
        const Face& fa = A.faces()[pc.a];
        add(pose.apply(fa.centroid), nrm);
        add(pose.apply(fa.centroid + L * fa.u), nrm);
        add(pose.apply(fa.centroid + L * fa.v), nrm);
        break;
      }
      case PcType::kEE:
        add(element_distance(A, pose, ElementKind::kEdge, pc.a, B, ElementKind::kEdge, pc.b).p_b,
            nrm);
        break;
    }
  }
  const Freedoms f = freedoms_from_points(pts, n, pose.t_BA, L, Params{});
  out.dof = f.dof;
  out.translation_dof = f.translation_dof;
  out.pure_rotation = f.pure_rotation;
}

}  // namespace cf::gen
