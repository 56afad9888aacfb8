// Certificate checker: a set's `cells` (docs/certificates.md, "Cells"). The tree must tile the
// domain (every rotation, every translation the set's PCs allow), checked with exact
// comparisons; every leaf's claim is rechecked with the checker's own turn bound and
// geometry. A gap the children's rounded centres leave is measured exactly and carried down
// as a growth `g` of the rotations every leaf below must refute.

#include "certificate_internal.hpp"

#include <algorithm>
#include <cmath>
#include <set>

namespace oracle::cert {

Rational pi_upper() {
#ifdef CF_ORACLE_CERT_GMP
  Rational q("314159265358979323847/100000000000000000000");
  q.canonicalize();
  return q;
#else
  using boost::multiprecision::cpp_int;
  return Rational(cpp_int("314159265358979323847"), cpp_int("100000000000000000000"));
#endif
}

Mat3 rot_about(const Vec3& k, double theta) {
  Mat3 K;
  K << 0, -k.z(), k.y(), k.z(), 0, -k.x(), -k.y(), k.x(), 0;
  return Mat3::Identity() + std::sin(theta) * K + (1 - std::cos(theta)) * K * K;
}

Mat3 rodrigues(const Vec3& r) {
  const double th = r.norm();
  if (th < 1e-8) {  // series: the next term is th^3 / 6 < 2e-25
    Mat3 K;
    K << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
    return Mat3::Identity() + K + 0.5 * K * K;
  }
  return rot_about(r / th, th);
}

// The turn bound (docs/certificates.md): a cube moves x by at most min(sqrt(3) h, 2)|x|
// (Hartley and Kahl 2009, lemma 1: the angle between R_r x and R_c x is at most |r - c|, and
// the chord is shorter than the angle); an arc's rotations R = Q R0' Rot(axis, theta), Q a
// turn of at most off_circle_rad (checked per set), move x by at most
// off |x| + |R0| 2 sin(|theta - c| / 2) |x x axis| <= off |x| + (1 + eta) h |x x axis|.
// kRcErr covers the checker's computed M against the exact central rotation.
double Turn::beta(const Vec3& x) const {
  const double r = x.norm();
  if (!arc) return (std::min(std::sqrt(3.0) * h, 2.0) + kRcErr) * r;
  return (off + kRcErr) * r + (1 + eta) * h * x.cross(axis).norm();
}

double Turn::unit() const {
  if (!arc) return std::min(std::sqrt(3.0) * h, 2.0) + kRcErr;
  return off + kRcErr + (1 + eta) * h;
}

namespace {

struct CNode {
  int id = 0, parent = -1;
  int pidx = -1;
  Vec3 c = Vec3::Zero();  // cube centre, or the arc's centre in c.x()
  double h = 0;
  Vec3 lo, hi;
  std::string kind;
  const json* j = nullptr;
  std::vector<int> kids;
  double g = 0;  // growth of the rotations (rad): the gaps left above this node
};

struct Circle {
  int pc = -1;
  Mat3 R0;
  Vec3 axis;
  double eta = 0;
};

struct Tree {
  const Ctx& ctx;
  const std::vector<SetPc>& pcs;
  bool arc = false;
  Circle circ;
  Vec3 pivot;
  std::vector<CNode> nodes;
  CertSetResult& out;

  void fail(int id, const std::string& why) { out.node_fails.push_back({id, why}); }
  Turn turn(const CNode& n) const;
  bool same_rot(const CNode& a, const CNode& b) const { return a.c == b.c && a.h == b.h; }
};

bool parse_node(Tree& T, const json& j, CNode& n, std::string* why) {
  n.id = j.at("id").get<int>();
  n.parent = j.at("parent").get<int>();
  const json& rot = j.at("rot");
  if (T.arc) {
    if (!rot.contains("arc")) return *why = "rot has no arc in a circle domain", false;
    const json& a = rot.at("arc");
    if (!a.is_array() || a.size() != 2) return *why = "arc is not [c, h]", false;
    n.c = Vec3(a[0].get<double>(), 0, 0);
    n.h = a[1].get<double>();
  } else {
    if (!rot.contains("centre")) return *why = "rot has no centre in a ball domain", false;
    n.c = get_vec3(rot, "centre");
    n.h = rot.at("half").get<double>();
  }
  if (!(n.h > 0)) return *why = "rotation half-width " + fmt(n.h) + " is not positive", false;
  n.lo = get_vec3(j, "t_lo");
  n.hi = get_vec3(j, "t_hi");
  n.kind = j.at("kind").get<std::string>();
  n.j = &j;
  return true;
}

Turn Tree::turn(const CNode& n) const {
  Turn t;
  t.arc = arc;
  t.h = n.h + n.g;
  if (arc) {
    t.off = ctx.tol.off_circle;
    t.axis = circ.axis;
    t.eta = circ.eta;
    t.M = circ.R0 * rot_about(circ.axis, n.c.x());
  } else {
    t.M = rodrigues(n.c);
  }
  return t;
}

// The circle: R0 must turn n_A onto -n_B and axis be n_A, closely enough that off_circle_rad
// covers every rotation the f-f allows. A rotation R with |R n_A + n_B| <= rot_tol_rad is
// R0' P Rot(a, theta) with R0' the rotation nearest R0 (|R0 - R0'| <= eta) and P the least
// turn taking a to R0'^T R a, whose chord is at most
// |R n_A + n_B| + |R0 n_A + n_B| + eta + 2 |a - n_A|; the node's bound then needs
// off >= rot_tol_rad + |R0 n_A + n_B| + 2 eta + 2 |a - n_A| (plus rounding).
std::string parse_circle(Tree& T, const json& cj) {
  Circle& c = T.circ;
  c.pc = cj.at("pc").get<int>();
  if (c.pc < 0 || c.pc >= static_cast<int>(T.pcs.size()) || T.pcs[c.pc].type != PcType::FF)
    return "circle.pc " + std::to_string(c.pc) + " is not an f-f PC of the set";
  const json& r = cj.at("R0");
  if (!r.is_array() || r.size() != 9) return "circle.R0 is not 9 numbers";
  for (int i = 0; i < 9; ++i) c.R0(i / 3, i % 3) = r[i].get<double>();
  // The nearest rotation R0' (polar factor) is within eta of R0 only when det R0 > 0; a
  // reflection could still turn n_A onto -n_B.
  if (!(c.R0.determinant() > 0)) return "circle.R0 is not a rotation (det <= 0)";
  const Vec3 ax = get_vec3(cj, "axis");
  if (!(ax.norm() > 0)) return "circle.axis is zero";
  c.axis = ax.normalized();
  const Vec3 nA = T.ctx.g.A.F[T.pcs[c.pc].a].n, nB = T.ctx.g.B.F[T.pcs[c.pc].b].n;
  c.eta = (c.R0.transpose() * c.R0 - Mat3::Identity()).norm() + 1e-15;
  const double e0 = (c.R0 * nA + nB).norm(), da = (c.axis - nA).norm();
  const double need = T.ctx.tol.rot + e0 + 2 * c.eta + 2 * da + kUnitEval;
  if (T.ctx.tol.off_circle < need)
    return "off_circle_rad " + fmt(T.ctx.tol.off_circle) +
           " does not cover the f-f's circle: " + "needs " + fmt(need) + " (rot_tol_rad " +
           fmt(T.ctx.tol.rot) + ", |R0 n_A + n_B| " + fmt(e0) + ", R0's defect " + fmt(c.eta) +
           ", |axis - n_A| " + fmt(da) + ")";
  return "";
}

// The translations any pose of the set can give the pivot: per PC, B's element's box grown by
// the pivot's largest distance to a closure vertex of A's element plus the touch tolerance
// (the contact point of A is in the hull of those vertices and within touch_tol of B's
// element). No rounding allowance: `err` bounds the checker's own rounding here.
Box3 my_root_box(const Tree& T, double* err) {
  const Poly &A = T.ctx.g.A, &B = T.ctx.g.B;
  Box3 out;
  out.lo = Vec3::Constant(-kInf);
  out.hi = Vec3::Constant(kInf);
  double mag = 0;
  for (const SetPc& pc : T.pcs) {
    double r = 0;
    for (int v : closure_vertices(A, kind_a(pc.type), pc.a))
      r = std::max(r, (A.V[v].p - T.pivot).norm());
    Box3 b;
    for (int v : closure_vertices(B, kind_b(pc.type), pc.b)) b.add(B.V[v].p);
    const double grow = r * (1 + 1e-15) + T.ctx.tol.touch;
    out.lo = out.lo.cwiseMax(b.lo - Vec3::Constant(grow));
    out.hi = out.hi.cwiseMin(b.hi + Vec3::Constant(grow));
    mag = std::max({mag, b.lo.cwiseAbs().maxCoeff(), b.hi.cwiseAbs().maxCoeff(), grow});
  }
  *err = 2e-15 * 2 * mag;  // two roundings (the sum, the difference) of that magnitude, x4
  return out;
}

// ---- structure ----

bool build(Tree& T, const json& nodes) {
  if (!nodes.is_array() || nodes.empty()) return T.fail(-1, "no nodes"), false;
  std::map<int, int> index;
  for (const auto& j : nodes) {
    CNode n;
    std::string why;
    try {
      if (!parse_node(T, j, n, &why)) return T.fail(-1, "malformed node: " + why), false;
    } catch (const std::exception& e) {
      return T.fail(-1, std::string("malformed node: ") + e.what()), false;
    }
    if (index.count(n.id)) return T.fail(n.id, "node id repeated"), false;
    const int me = static_cast<int>(T.nodes.size());
    if (me == 0) {
      if (n.parent != -1) return T.fail(n.id, "the first node is not the root"), false;
    } else {
      auto it = index.find(n.parent);
      if (it == index.end())
        return T.fail(n.id, "parent " + std::to_string(n.parent) + " is not an earlier node"),
               false;
      n.pidx = it->second;
      T.nodes[it->second].kids.push_back(me);
    }
    index[n.id] = me;
    T.nodes.push_back(n);
  }
  return true;
}

// Split-rotation: the children are the dyadic halves. Per axis, the children on each side
// share an interval (their intersection); the parent's interval less their union is measured
// exactly and every child inherits it as growth.
std::string split_rotation(Tree& T, CNode& P) {
  const int dims = T.arc ? 1 : 3;
  const std::size_t want = T.arc ? 2 : 8;
  if (P.kids.size() != want)
    return std::to_string(P.kids.size()) + " children, a split-rotation has " +
           std::to_string(want);
  std::set<int> combos;
  for (int k : P.kids) {
    const CNode& K = T.nodes[k];
    if (K.h != P.h / 2) return "child " + std::to_string(K.id) + " is not half as wide";
    if (K.lo != P.lo || K.hi != P.hi) return "child " + std::to_string(K.id) + " has another box";
    int combo = 0;
    for (int a = 0; a < dims; ++a) {
      const bool up = K.c[a] > P.c[a];
      const double want_c = P.c[a] + (up ? P.h / 2 : -P.h / 2);
      // A rounded dyadic centre is within a few ulps; the exact cover below decides the rest.
      if (std::abs(K.c[a] - want_c) > 1e-12 * (std::abs(P.c[a]) + P.h))
        return "child " + std::to_string(K.id) + " is not a dyadic half (centre " + fmt(K.c[a]) +
               ", expected " + fmt(want_c) + ")";
      combo |= (up ? 1 : 0) << a;
    }
    combos.insert(combo);
  }
  if (combos.size() != want) return "two children are the same half";
  Rational miss(0);
  for (int a = 0; a < dims; ++a) {
    Rational Llo(-1e300), Lhi(1e300), Hlo(-1e300), Hhi(1e300);
    for (int k : P.kids) {
      const CNode& K = T.nodes[k];
      const Rational lo = Rational(K.c[a]) - Rational(K.h), hi = Rational(K.c[a]) + Rational(K.h);
      Rational& l = K.c[a] > P.c[a] ? Hlo : Llo;
      Rational& h = K.c[a] > P.c[a] ? Hhi : Lhi;
      if (lo > l) l = lo;
      if (hi < h) h = hi;
    }
    const Rational plo = Rational(P.c[a]) - Rational(P.h), phi = Rational(P.c[a]) + Rational(P.h);
    for (const Rational& m : {Rational(Llo - plo), Rational(Hlo - Lhi), Rational(phi - Hhi)})
      if (m > miss) miss = m;
  }
  double g = to_double(miss);
  // Rounded centres leave gaps of ulps (~1e-16 rad); one this large is a wrong tree.
  if (g > 1e-12) return "the children leave a gap of " + fmt(g) + " rad";
  if (Rational(g) < miss) g = std::nextafter(g, kInf);
  for (int k : P.kids) T.nodes[k].g = P.g + g;
  return "";
}

std::string split_translation(Tree& T, const CNode& P) {
  if (P.kids.size() != 2) return std::to_string(P.kids.size()) + " children, expected 2";
  const int axis = P.j->at("axis").get<int>();
  const double at = P.j->at("at").get<double>();
  if (axis < 0 || axis > 2) return "axis " + std::to_string(axis) + " is not 0, 1 or 2";
  if (!(P.lo[axis] <= at && at <= P.hi[axis])) return "at " + fmt(at) + " is outside the box";
  const CNode *a = &T.nodes[P.kids[0]], *b = &T.nodes[P.kids[1]];
  if (a->lo[axis] != P.lo[axis]) std::swap(a, b);
  Vec3 ahi = P.hi, blo = P.lo;
  ahi[axis] = at;
  blo[axis] = at;
  if (!T.same_rot(*a, P) || !T.same_rot(*b, P)) return "a child has other rotations";
  if (a->lo != P.lo || a->hi != ahi || b->lo != blo || b->hi != P.hi)
    return "the children are not the box cut at " + fmt(at) + " across axis " +
           std::to_string(axis);
  for (int k : P.kids) T.nodes[k].g = P.g;
  return "";
}

// Narrow: the child and the program slabs, each inside the parent's box, cover it: every cell
// of the grid of their distinct coordinates lies in one of them (comparisons only).
std::string narrow(Tree& T, const CNode& P) {
  if (P.kids.empty() || P.kids.size() > 7)
    return std::to_string(P.kids.size()) + " children, a narrow has 1 to 7";
  for (int k : P.kids) {
    const CNode& K = T.nodes[k];
    if (!T.same_rot(K, P)) return "child " + std::to_string(K.id) + " has other rotations";
    for (int a = 0; a < 3; ++a)
      if (K.lo[a] <= K.hi[a] && (K.lo[a] < P.lo[a] || K.hi[a] > P.hi[a]))
        return "child " + std::to_string(K.id) + "'s box is not inside the parent's";
    T.nodes[k].g = P.g;
  }
  for (int a = 0; a < 3; ++a)
    if (P.lo[a] > P.hi[a]) return "";  // an empty box: nothing to cover
  std::array<std::vector<double>, 3> grid;
  for (int a = 0; a < 3; ++a) {
    grid[a] = {P.lo[a], P.hi[a]};
    for (int k : P.kids)
      for (double x : {T.nodes[k].lo[a], T.nodes[k].hi[a]})
        if (x > P.lo[a] && x < P.hi[a]) grid[a].push_back(x);
    std::sort(grid[a].begin(), grid[a].end());
    grid[a].erase(std::unique(grid[a].begin(), grid[a].end()), grid[a].end());
    if (grid[a].size() == 1) grid[a].push_back(grid[a][0]);  // a flat box: one degenerate cell
  }
  for (std::size_t i = 0; i + 1 < grid[0].size(); ++i)
    for (std::size_t j = 0; j + 1 < grid[1].size(); ++j)
      for (std::size_t k = 0; k + 1 < grid[2].size(); ++k) {
        const Vec3 clo(grid[0][i], grid[1][j], grid[2][k]);
        const Vec3 chi(grid[0][i + 1], grid[1][j + 1], grid[2][k + 1]);
        bool covered = false;
        for (int q : P.kids) {
          const CNode& K = T.nodes[q];
          covered = covered ||
                    ((K.lo.array() <= clo.array()).all() && (chi.array() <= K.hi.array()).all());
        }
        if (!covered)
          return "the children do not cover the box: [" + fmt(clo.x()) + "," + fmt(chi.x()) +
                 "]x[" + fmt(clo.y()) + "," + fmt(chi.y()) + "]x[" + fmt(clo.z()) + "," +
                 fmt(chi.z()) + "] is left out";
      }
  return "";
}

// The root: the whole domain (grown by kPiGap it covers [-pi, pi]^3, or an arc of length 2 pi)
// and a box holding every translation the set's PCs allow.
std::string root_checks(Tree& T, CNode& R) {
  R.g = kPiGap;
  const Rational pi = pi_upper(), hg = Rational(R.h) + Rational(R.g);
  if (T.arc) {
    if (hg < pi) return "the root arc's half-width " + fmt(R.h) + " does not cover the circle";
  } else {
    for (int a = 0; a < 3; ++a)
      if (Rational(R.c[a]) - hg > -pi || Rational(R.c[a]) + hg < pi)
        return "the root cube (centre " + fmt(R.c[a]) + ", half " + fmt(R.h) +
               ") does not hold the ball |r| <= pi";
  }
  double err = 0;
  const Box3 mine = my_root_box(T, &err);
  for (int a = 0; a < 3; ++a)
    if (mine.lo[a] - mine.hi[a] > 2 * err) return "";  // no pose at all: nothing to hold
  for (int a = 0; a < 3; ++a)
    if (R.lo[a] > mine.lo[a] - err || R.hi[a] < mine.hi[a] + err)
      return "the root box [" + fmt(R.lo[a]) + ", " + fmt(R.hi[a]) + "] on axis " +
             std::to_string(a) + " does not hold the pivot's reachable translations [" +
             fmt(mine.lo[a]) + ", " + fmt(mine.hi[a]) + "]";
  return "";
}

// ---- leaves ----

std::vector<Vec3> tangent_dirs(const Poly& P, int kind, int idx) {
  std::vector<Vec3> d;
  if (kind == 0)
    for (int e : P.V[idx].edges) {
      const int o = P.E[e].v0 == idx ? P.E[e].v1 : P.E[e].v0;
      d.push_back((P.V[o].p - P.V[idx].p).normalized());
    }
  if (kind == 1) d = {P.E[idx].m[0], P.E[idx].m[1]};
  return d;
}

// An edge clearly reflex (its local margin is -1 by definition): m[0] against the other
// face's normal above rounding, i.e. the dihedral angle beyond pi by more than 1e-6 rad.
bool clearly_reflex(const Poly& P, int e) { return P.E[e].m[0].dot(P.F[P.E[e].face[1]].n) > 1e-6; }

int leaf_pc(const Tree& T, const CNode& n) {
  const int k = n.j->at("pc").get<int>();
  if (k < 0 || k >= static_cast<int>(T.pcs.size()))
    throw std::runtime_error("pc " + std::to_string(k) + " is not a PC of the set");
  return k;
}

std::string pc_label(const Tree& T, int k) {
  return "PC " + std::to_string(k) + " (" + pc_text(T.pcs[k]) + ")";
}

// A rotational condition fails at every rotation of the node by more than the alignment a
// witness is allowed (rot_tol_rad: a witness meets the conditions to it, not exactly).
std::string rotation_leaf(const Tree& T, const CNode& n, const Turn& tu) {
  const int k = leaf_pc(T, n);
  const SetPc& pc = T.pcs[k];
  const Poly &A = T.ctx.g.A, &B = T.ctx.g.B;
  double v = 0, need = 0;
  if (pc.type == PcType::FF) {
    v = (tu.M * A.F[pc.a].n + B.F[pc.b].n).norm();
    need = tu.beta(A.F[pc.a].n);
  } else if (pc.type == PcType::EF) {
    v = std::abs((tu.M * A.E[pc.a].dir).dot(B.F[pc.b].n));
    need = tu.beta(A.E[pc.a].dir);
  } else if (pc.type == PcType::FE) {
    v = std::abs((tu.M * A.F[pc.a].n).dot(B.E[pc.b].dir));
    need = tu.beta(A.F[pc.a].n);
  } else {
    return pc_label(T, k) + " has no rotational condition";
  }
  need += T.ctx.tol.rot + kUnitEval;
  if (v > need) return "";
  return pc_label(T, k) + ": the condition's value " + fmt(v) + " at the centre is not above " +
         fmt(need) + " (turn bound + rot_tol_rad " + fmt(T.ctx.tol.rot) + ")";
}

std::string cone_leaf(const Tree& T, const CNode& n, const Turn& tu) {
  const int k = leaf_pc(T, n);
  const SetPc& pc = T.pcs[k];
  const Poly &A = T.ctx.g.A, &B = T.ctx.g.B;
  const Vec3 d = get_vec3(*n.j, "direction");
  const bool a_side = pc.type == PcType::VF || pc.type == PcType::EF;
  if (!a_side && pc.type != PcType::FV && pc.type != PcType::FE)
    return pc_label(T, k) + " has no vertex or edge against a face";
  const auto dirs =
      a_side ? tangent_dirs(A, kind_a(pc.type), pc.a) : tangent_dirs(B, kind_b(pc.type), pc.b);
  constexpr double kDirMatch = 1e-9;  // the file's direction is the element's to rounding
  const Vec3* mine = nullptr;
  for (const auto& t : dirs)
    if ((t - d).norm() <= kDirMatch) mine = &t;
  if (!mine)
    return pc_label(T, k) + ": direction " + fmt(d.x()) + "," + fmt(d.y()) + "," + fmt(d.z()) +
           " is not a tangent direction of its element";
  double v, need;
  if (a_side) {
    v = (tu.M * *mine).dot(B.F[pc.b].n);
    need = -tu.beta(*mine) - kUnitEval;
  } else {
    v = mine->dot(tu.M * A.F[pc.a].n);
    need = -tu.beta(A.F[pc.a].n) - kUnitEval;
  }
  if (v < need) return "";
  return pc_label(T, k) + ": the direction's height " + fmt(v) + " is not below " + fmt(need);
}

}  // namespace

// ---- the e-e margin by the range of its normal ----
// At every R of the node the e-e's normal n is a unit vector perpendicular to e_B with
// |n . M e_A| <= beta(e_A) (n is perpendicular to R e_A); with n = cos(phi) u1 + sin(phi) u2
// each term of the margin, widened by the turn bound, is a sinusoid of phi. The largest of
// their least over the allowed arcs of phi is at an arc's end, a term's maximum or a crossing
// of two terms. Each candidate angle is computed with an error d, so the value taken there is
// a bound of the least over [phi - d, phi + d], which holds the exact candidate.

namespace {

/// Error of an angle the checker computes (atan2, asin, acos and a sum of two: a few ulps of
/// 2 pi, ~2e-15), taken ~5 times larger.
constexpr double kAngle = 1e-14;

// f(phi) = p . (cos phi, sin phi) + c.
struct Sinusoid {
  Vec2 p;
  double c = 0;
  double at(double phi) const { return p.x() * std::cos(phi) + p.y() * std::sin(phi) + c; }
  double slope(double phi) const { return -p.x() * std::sin(phi) + p.y() * std::cos(phi); }
};

// An upper bound of the least of the terms over [phi - d, phi + d]: each term is at most its
// value plus |slope| d plus |p| d^2 / 2 there (its second derivative is at most |p|).
double least_near(const std::vector<Sinusoid>& f, double phi, double d) {
  double m = kInf;
  for (const Sinusoid& t : f)
    m = std::min(m, t.at(phi) + std::abs(t.slope(phi)) * d + t.p.norm() * d * d / 2);
  return m;
}

bool in_arc(double phi, double centre, double half, double tol) {
  return std::abs(std::remainder(phi - centre, 2 * kPi)) <= half + tol;
}

// The angles where terms i and j are equal: (p_i - p_j) . (cos, sin) = c_j - c_i, i.e.
// phi = atan2(B, A) +- acos(x), x = (c_j - c_i) / r. x carries ~5 ulps of relative error ex
// (the differences, the hypot, the quotient); acos moves by at most ex / sqrt(1 - x^2), and by
// at most acos(1 - ex) <= 1.01 sqrt(2 ex) wherever x lies. Appends {phi, error} pairs.
void crossings(const Sinusoid& fi, const Sinusoid& fj,
               std::vector<std::pair<double, double>>* out) {
  const double A = fi.p.x() - fj.p.x(), B = fi.p.y() - fj.p.y();
  const double r = std::hypot(A, B);
  if (!(r > 0)) return;  // the terms differ by a constant: they cross nowhere or everywhere
  const double x = (fj.c - fi.c) / r, ex = 1e-15 * std::abs(x);
  if (std::abs(x) > 1 + ex) return;
  const double xc = std::clamp(x, -1.0, 1.0), xm = std::min(1.0, std::abs(xc) + ex);
  double d = 1.01 * std::sqrt(2 * ex);
  if (xm < 1) d = std::min(d, ex / std::sqrt(1 - xm * xm));
  const double base = std::atan2(B, A), t = std::acos(xc);
  out->push_back({base + t, d + kAngle});
  out->push_back({base - t, d + kAngle});
}

}  // namespace

// The allowed n: |k cos(phi - psi)| <= beta(e_A) (k cos(phi - psi) = n . M e_A, k = s_c), the
// whole circle when k is at most that, else two arcs centred on psi +- pi/2 of half-width
// asin(beta(e_A) / k). The tolerance kUnitEval covers the rounding of the basis and the dot
// products (the circle of computed n(phi) is within a few ulps of the true one), and asin's
// argument is taken upwards, asin being increasing.
double ee_normal_bound(const EeNode& g) {
  const Vec3 a = g.M * g.eA;
  const double sc = a.cross(g.eB).norm();
  const Vec3 u1 = g.eB.unitOrthogonal(), u2 = g.eB.cross(u1);
  std::vector<Sinusoid> f;
  for (const Vec3& w : g.wB) f.push_back({Vec2(-w.dot(u1), -w.dot(u2)), 0.0});
  for (int k = 0; k < 2; ++k) {
    const Vec3 w = g.M * g.wA[k];
    f.push_back({Vec2(w.dot(u1), w.dot(u2)), g.beta_w[k]});
  }
  const double k1 = a.dot(u1), k2 = a.dot(u2), k = std::hypot(k1, k2);
  const double b = g.beta_e + kUnitEval;
  std::vector<std::pair<double, double>> arcs;  // {centre, half-width}
  if (k <= b) {
    arcs.push_back({0.0, kPi});
  } else {
    const double psi = std::atan2(k2, k1);
    const double half = std::asin(std::min(1.0, b / k * (1 + 1e-15))) + 2 * kAngle;
    arcs = {{psi + kPi / 2, half}, {psi - kPi / 2, half}};
  }
  std::vector<std::pair<double, double>> cand;  // {angle, error}
  for (const Sinusoid& t : f)
    if (t.p.norm() > 0) cand.push_back({std::atan2(t.p.y(), t.p.x()), kAngle});
  for (std::size_t i = 0; i < f.size(); ++i)
    for (std::size_t j = i + 1; j < f.size(); ++j) crossings(f[i], f[j], &cand);
  double G = -kInf;
  for (const auto& [c, h] : arcs) {
    G = std::max(G, least_near(f, c, kAngle));  // a point of the arc: G is never left -inf
    if (h < kPi)
      for (double e : {c - h, c + h}) G = std::max(G, least_near(f, e, kAngle));
    for (const auto& [phi, d] : cand)
      if (in_arc(phi, c, h, d + kAngle)) G = std::max(G, least_near(f, phi, d));
  }
  return std::min(sc + g.beta_e, G);
}

namespace {

// The checker's upper bound of the local margin over the node (docs: "The local margin"),
// each term widened by how far the node turns its vector.
double margin_bound(const Tree& T, const SetPc& pc, const Turn& tu) {
  const Poly &A = T.ctx.g.A, &B = T.ctx.g.B;
  const int ka = kind_a(pc.type), kb = kind_b(pc.type);
  double u = 1;
  switch (pc.type) {
    case PcType::FF:
      u = 1 - std::max(0.0, (tu.M * A.F[pc.a].n + B.F[pc.b].n).norm() - tu.beta(A.F[pc.a].n));
      break;
    case PcType::VF:
    case PcType::EF:
      if (ka == 1 && clearly_reflex(A, pc.a)) return -1;
      for (const auto& d : tangent_dirs(A, ka, pc.a))
        u = std::min(u, (tu.M * d).dot(B.F[pc.b].n) + tu.beta(d));
      break;
    case PcType::FV:
    case PcType::FE:
      if (kb == 1 && clearly_reflex(B, pc.b)) return -1;
      for (const auto& d : tangent_dirs(B, kb, pc.b))
        u = std::min(u, d.dot(tu.M * A.F[pc.a].n) + tu.beta(A.F[pc.a].n));
      break;
    case PcType::EE: {
      if (clearly_reflex(A, pc.a) || clearly_reflex(B, pc.b)) return -1;
      const Edge &ea = A.E[pc.a], &eb = B.E[pc.b];
      const Vec3 N = (tu.M * ea.dir).cross(eb.dir);
      const double s = N.norm(), dN = tu.beta(ea.dir);
      if (s + dN < 1e-9) return -1;
      // |N/|N| - N_c/|N_c|| <= 2 |N - N_c| / |N_c|.
      const double dn = s > 0 ? std::min(2.0, 2 * dN / s) : 2.0;
      const Vec3 nu = s > 0 ? Vec3(N / s) : Vec3::Zero();
      double best = -kInf;
      for (double sg : {1.0, -1.0}) {
        double m = kInf;
        for (const Vec3& w : {eb.m[0], eb.m[1]}) m = std::min(m, -w.dot(sg * nu) + dn);
        for (const Vec3& w : {ea.m[0], ea.m[1]})
          m = std::min(m, (tu.M * w).dot(sg * nu) + tu.beta(w) + dn * (1 + 1e-12));
        best = std::max(best, m);
      }
      // The first bound widens the normal by 2 beta / s, without limit as the edges turn
      // parallel; the second bounds the normal's range instead, and holds there.
      EeNode g;
      g.M = tu.M;
      g.eA = ea.dir;
      g.eB = eb.dir;
      for (int i = 0; i < 2; ++i) {
        g.wA[i] = ea.m[i];
        g.wB[i] = eb.m[i];
        g.beta_w[i] = tu.beta(ea.m[i]);
      }
      g.beta_e = dN;
      u = std::min(std::min(s + dN, best), ee_normal_bound(g));
      break;
    }
    default:
      break;
  }
  return u + kUnitEval;
}

std::string slack_leaf(const Tree& T, const CNode& n, const Turn& tu) {
  const int k = leaf_pc(T, n);
  const double u = margin_bound(T, T.pcs[k], tu);
  if (u < T.ctx.tol.slack) return "";
  return pc_label(T, k) + ": the checker's bound of the local margin over the node, " + fmt(u) +
         ", is not below local_slack " + fmt(T.ctx.tol.slack) +
         " (the checker's bound may be looser than the generator's)";
}

std::string bounds_leaf(const Tree& T, const CNode& n) {
  double err = 0;
  const Box3 mine = my_root_box(T, &err);
  for (int a = 0; a < 3; ++a)
    if (mine.lo[a] - mine.hi[a] > 2 * err || n.lo[a] > n.hi[a]) return "";
  for (const SetPc& pc : T.pcs) {
    if (kind_a(pc.type) == 1 && T.ctx.g.A.E[pc.a].len < 2 * T.ctx.tol.margin * (1 - 1e-12))
      return "";
    if (kind_b(pc.type) == 1 && T.ctx.g.B.E[pc.b].len < 2 * T.ctx.tol.margin * (1 - 1e-12))
      return "";
  }
  return "the root box is not empty and no edge of the set is shorter than 2 min_margin_mm";
}

// No point of the cube (grown by g) lies in the ball |r| <= pi: exactly.
std::string outside_ball_leaf(const CNode& n) {
  Rational d2(0);
  for (int a = 0; a < 3; ++a) {
    const Rational m = Rational(std::abs(n.c[a])) - Rational(n.h) - Rational(n.g);
    if (m > 0) d2 += m * m;
  }
  const Rational pi = pi_upper();
  if (d2 > pi * pi) return "";
  return "the cube (grown by " + fmt(n.g) + ") reaches the ball |r| <= pi";
}

// ---- deep points ----

double dist_to_surface(const Poly& P, const Vec3& x) {
  double d = kInf;
  for (const auto& f : P.F) d = std::min(d, point_face_dist(P, f, x));
  return d;
}

// Parity of a ray's crossings, over fixed directions until one meets no face ambiguously (its
// hit point within eps of a face's boundary, or the ray in a face's plane): 1 inside, 0
// outside, -1 undecided.
int inside_solid(const Poly& P, const Vec3& x, double eps) {
  static const Vec3 dirs[] = {Vec3(0.5773, 0.6123, 0.5401), Vec3(-0.3119, 0.8412, -0.4417),
                              Vec3(0.7071, -0.1234, 0.6962), Vec3(-0.6012, -0.5523, 0.5775),
                              Vec3(0.2231, -0.9117, -0.3450)};
  for (const Vec3& d0 : dirs) {
    const Vec3 d = d0.normalized();
    bool ambiguous = false;
    int count = 0;
    for (const auto& f : P.F) {
      const double den = f.n.dot(d), h = f.n.dot(x) - f.d;
      if (std::abs(den) < 1e-12) {  // the ray runs along the plane: ambiguous only if in it
        ambiguous = ambiguous || std::abs(h) < eps;
        continue;
      }
      const double lam = -h / den;
      const Vec2 q = f.to2(x + lam * d);
      const double edge = dist_to_loops(f.loops2, q);
      if (edge < eps || (std::abs(lam) < eps && inside_loops(f.loops2, q))) ambiguous = true;
      if (lam > 0 && inside_loops(f.loops2, q)) ++count;
    }
    if (!ambiguous) return count % 2;
  }
  return -1;
}

std::string deep_leaf(const Tree& T, const CNode& n, const Turn& tu) {
  const std::string of = n.j->at("of").get<std::string>();
  if (of != "A" && of != "B") return "of is \"" + of + "\", expected \"A\" or \"B\"";
  const Vec3 pt = get_vec3(*n.j, "point");
  const Poly& own = of == "A" ? T.ctx.g.A : T.ctx.g.B;
  const Poly& other = of == "A" ? T.ctx.g.B : T.ctx.g.A;
  const double scale = T.ctx.tol.scale;
  // The point must be on its solid's boundary (to rounding); its nearest boundary point is
  // then delta away, and the requirement grows by what delta can add.
  const double delta = dist_to_surface(own, pt);
  if (delta > kGross * scale)
    return "the point is " + fmt(delta) + " mm from " + of + "'s boundary";
  if (!(n.lo.array() <= n.hi.array()).all()) return "";  // an empty box holds no pose
  const Vec3 tc = (n.lo + n.hi) / 2;
  const double spread = (n.hi - n.lo).norm() / 2, bu = tu.unit();
  const double err = kRelRound * 4 * scale;
  Vec3 img;
  double need;
  if (of == "A") {
    img = tu.M * (pt - T.pivot) + tc;
    need = bu * ((pt - T.pivot).norm() + delta) + spread + delta + err;
  } else {
    img = tu.M.transpose() * (pt - tc) + T.pivot;
    need = bu * ((pt - tc).norm() + spread + delta) + spread * (1 + tu.eta + 1e-12) + delta + err;
  }
  // deep_extra_mm: a tree that also refutes its set's images needs the point deeper by how far
  // the symmetries miss (docs/certificates.md, "Images").
  need += T.ctx.tol.deep_extra;
  const double depth = dist_to_surface(other, img);
  if (depth <= need)
    return "the point's image is " + fmt(depth) + " mm from " + (of == "A" ? "B" : "A") +
           "'s boundary, not more than " + fmt(need);
  const int in = inside_solid(other, img, kGross * scale);
  if (in == 1) return "";
  return in == 0 ? "the point's image is outside " + std::string(of == "A" ? "B" : "A")
                 : "could not decide whether the point's image is inside";
}

std::string leaf_claim(const Tree& T, const CNode& n) {
  if (!n.kids.empty()) return "a " + n.kind + " leaf has children";
  const Turn tu = T.turn(n);
  if (n.kind == "outside-ball")
    return T.arc ? "outside-ball in a circle domain" : outside_ball_leaf(n);
  if (n.kind == "bounds") return bounds_leaf(T, n);
  if (n.kind == "rotation") return rotation_leaf(T, n, tu);
  if (n.kind == "cone") return cone_leaf(T, n, tu);
  if (n.kind == "local-slack") return slack_leaf(T, n, tu);
  if (n.kind == "deep") return deep_leaf(T, n, tu);
  if (n.kind == "first-order")
    return T.arc ? "a first-order leaf needs a cube of rotations (domain \"ball\"), not an arc"
                 : check_first_order(T.ctx, T.pcs, tu, n.j->at("farkas"));
  if (n.kind == "program")
    return check_program(T.ctx, T.pcs, T.pivot, tu, n.lo, n.hi, n.j->at("farkas"));
  return "unknown kind \"" + n.kind + "\"";
}

}  // namespace

void check_cells(const Ctx& ctx, const std::vector<SetPc>& pcs, const json& cells,
                 CertSetResult& out) {
  Tree T{ctx, pcs, false, {}, Vec3::Zero(), {}, out};
  try {
    T.pivot = get_vec3(cells, "pivot");
    const std::string domain = cells.at("domain").get<std::string>();
    if (domain != "ball" && domain != "circle")
      return T.fail(-1, "domain \"" + domain + "\" is not ball or circle");
    T.arc = domain == "circle";
    if (T.arc) {
      const std::string why = parse_circle(T, cells.at("circle"));
      if (!why.empty()) return T.fail(-1, why);
    }
  } catch (const std::exception& e) {
    return T.fail(-1, std::string("malformed cells: ") + e.what());
  }
  if (!build(T, cells.at("nodes"))) return;
  std::string why = root_checks(T, T.nodes[0]);
  if (!why.empty()) T.fail(T.nodes[0].id, why);
  for (CNode& n : T.nodes) {  // parents before children: g flows down
    try {
      if (n.kind == "split-rotation")
        why = split_rotation(T, n);
      else if (n.kind == "split-translation")
        why = split_translation(T, n);
      else if (n.kind == "narrow")
        why = narrow(T, n);
      else {
        why = leaf_claim(T, n);
        out.leaves[n.kind][why.empty() ? 0 : 1]++;
      }
    } catch (const std::exception& e) {
      why = std::string("malformed node: ") + e.what();
    }
    if (!why.empty()) T.fail(n.id, n.kind + ": " + why);
  }
}

}  // namespace oracle::cert
