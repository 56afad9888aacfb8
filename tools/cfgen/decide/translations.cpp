// The linear programs of the witness search (witness.hpp): translations that place the
// contacts inside their elements with the largest margin, and the climb past obstacles
// (separating cuts, and the turn that the program linearised in it says gains most).

#include "cfgen/decide/rotation_family.hpp"
#include "cfgen/decide/witness.hpp"

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
using Rel = LinearProgram::Rel;

namespace {

// Affine point P(x) = p0 + sum_j coef_j x_j (3D), constrained to a convex face piece given in
// the (u, v) frame: every side with margin s (variable s_var) when it is real boundary.
struct AffinePoint {
  Vec3 p0 = Vec3::Zero();
  // (variable, coefficient) pairs: t (3) and up to two parameters; inline, no allocation.
  struct Coefs {
    std::array<std::pair<int, Vec3>, 6> v;
    std::size_t n = 0;
    Coefs() { v.fill({0, Vec3::Zero()}); }
    void push_back(const std::pair<int, Vec3>& x) {
      if (n == v.size()) throw std::length_error("AffinePoint with more than 6 coefficients");
      v[n++] = x;
    }
    const std::pair<int, Vec3>* begin() const { return v.data(); }
    const std::pair<int, Vec3>* end() const { return v.data() + n; }
  } coef;
};

void add_piece_rows(LinearProgram& lp, const ConvexPiece& piece, const Vec3& u, const Vec3& v,
                    const AffinePoint& P, int s_var) {
  const std::size_t n = piece.points.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Vector2d& a = piece.points[k];
    const Eigen::Vector2d& b = piece.points[(k + 1) % n];
    Eigen::Vector2d g(-(b - a).y(), (b - a).x());
    const double len = g.norm();
    if (len < 1e-12) continue;
    g /= len;
    LinearProgram::Coefs row;
    for (const auto& [j, cvec] : P.coef)
      row.push_back({j, g.x() * u.dot(cvec) + g.y() * v.dot(cvec)});
    if (piece.boundary[k]) row.push_back({s_var, -1.0});
    lp.add(row, Rel::kGreaterEq, g.dot(a) - (g.x() * u.dot(P.p0) + g.y() * v.dot(P.p0)));
  }
}

void add_eq(LinearProgram& lp, const Vec3& n, const AffinePoint& P, double rhs) {
  LinearProgram::Coefs row;
  for (const auto& [j, cvec] : P.coef) row.push_back({j, n.dot(cvec)});
  lp.add(row, Rel::kEq, rhs - n.dot(P.p0));
}

AffinePoint plus_t(Vec3 p0, double sign = 1.0) {
  AffinePoint P;
  P.p0 = p0;
  for (int i = 0; i < 3; ++i) P.coef.push_back({i, sign * Vec3::Unit(i)});
  return P;
}

}  // namespace

LinearProgram WitnessSearch::build_lp(const PcSet& pcs, const Mat3& R,
                                      const std::vector<int>& pieces, int extra_vars) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  int nv = 4;  // t (0..2), s (3), then per-PC auxiliaries
  for (const Pc& pc : pcs)
    nv += pc.type == PcType::kEF || pc.type == PcType::kFE   ? 1
          : pc.type == PcType::kFF || pc.type == PcType::kEE ? 2
                                                             : 0;
  LinearProgram lp(nv + extra_vars);
  lp.rows.reserve(64);  // a few dozen rows and the cuts translations() adds: no regrowth
  const int S = 3;
  lp.lower[S] = {true, 0.0};
  lp.upper[S] = {true, scale_};
  lp.c[S] = -1.0;
  int aux = 4;
  std::size_t slot = 0;
  auto bounded_param = [&](int var, double len) {
    lp.add({{var, 1.0}, {S, -1.0}}, Rel::kGreaterEq, 0.0);
    lp.add({{var, 1.0}, {S, 1.0}}, Rel::kLessEq, len);
  };
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kVF: {
        const Face& fb = B.faces()[pc.b];
        const AffinePoint P = plus_t(R * A.vertices()[pc.a].p);
        add_eq(lp, fb.normal, P, fb.offset);
        add_piece_rows(lp, B_.pieces[pc.b][pieces[slot++]], fb.u, fb.v, P, S);
        break;
      }
      case PcType::kFV: {
        const Face& fa = A.faces()[pc.a];
        const AffinePoint P = plus_t(B.vertices()[pc.b].p, -1.0);  // vb - t, in A's rotated frame
        add_eq(lp, R * fa.normal, P, fa.offset);
        add_piece_rows(lp, A_.pieces[pc.a][pieces[slot++]], R * fa.u, R * fa.v, P, S);
        break;
      }
      case PcType::kEF: {
        const Face& fb = B.faces()[pc.b];
        const Edge& ea = A.edges()[pc.a];
        AffinePoint P = plus_t(R * A.vertices()[ea.v0.index()].p);
        P.coef.push_back({aux, R * ea.dir});
        add_eq(lp, fb.normal, P, fb.offset);
        add_piece_rows(lp, B_.pieces[pc.b][pieces[slot++]], fb.u, fb.v, P, S);
        bounded_param(aux++, ea.length);
        break;
      }
      case PcType::kFE: {
        const Face& fa = A.faces()[pc.a];
        const Edge& eb = B.edges()[pc.b];
        AffinePoint P = plus_t(B.vertices()[eb.v0.index()].p, -1.0);
        P.coef.push_back({aux, eb.dir});
        add_eq(lp, R * fa.normal, P, fa.offset);
        add_piece_rows(lp, A_.pieces[pc.a][pieces[slot++]], R * fa.u, R * fa.v, P, S);
        bounded_param(aux++, eb.length);
        break;
      }
      case PcType::kFF: {
        const Face& fa = A.faces()[pc.a];
        const Face& fb = B.faces()[pc.b];
        add_eq(lp, fb.normal, plus_t(R * fa.centroid), fb.offset);
        AffinePoint Q;  // a common point q on B's face plane
        Q.p0 = fb.offset * fb.normal;
        Q.coef.push_back({aux, fb.u});
        Q.coef.push_back({aux + 1, fb.v});
        add_piece_rows(lp, B_.pieces[pc.b][pieces[slot++]], fb.u, fb.v, Q, S);
        AffinePoint QA = Q;  // q - t, read in A's rotated face frame
        for (int i = 0; i < 3; ++i) QA.coef.push_back({i, -Vec3::Unit(i)});
        add_piece_rows(lp, A_.pieces[pc.a][pieces[slot++]], R * fa.u, R * fa.v, QA, S);
        aux += 2;
        break;
      }
      case PcType::kEE: {
        const Edge& ea = A.edges()[pc.a];
        const Edge& eb = B.edges()[pc.b];
        const Vec3 pa = R * A.vertices()[ea.v0.index()].p;
        const Vec3 da = R * ea.dir;
        const Vec3& pb = B.vertices()[eb.v0.index()].p;
        for (int i = 0; i < 3; ++i)
          lp.add({{i, 1.0}, {aux, da[i]}, {aux + 1, -eb.dir[i]}}, Rel::kEq, pb[i] - pa[i]);
        bounded_param(aux, ea.length);
        bounded_param(aux + 1, eb.length);
        aux += 2;
        break;
      }
    }
  }
  return lp;
}

double WitnessSearch::signed_margin(const PcSet& pcs, const Mat3& R,
                                    const std::vector<int>& pieces) const {
  LinearProgram lp = build_lp(pcs, R, pieces);
  lp.lower[3] = {true, -scale_};
  const LpResult r = solve(lp);
  return r.status == LpResult::Status::kOptimal ? r.x[3] : -std::numeric_limits<double>::infinity();
}

std::vector<Vec3> WitnessSearch::translations(const PcSet& pcs, const Mat3& R,
                                              const std::vector<int>& pieces, double& margin,
                                              bool near_boundary,
                                              const std::vector<LinearProgram::Row>& cuts,
                                              TranslationMemo* memo) const {
  LinearProgram lp = build_lp(pcs, R, pieces);
  lp.rows.insert(lp.rows.end(), cuts.begin(), cuts.end());
  const bool memo_set = memo && memo->set;
  const LpResult best = memo_set ? memo->best : solve(lp);
  margin = best.status == LpResult::Status::kOptimal ? best.x[3] : 0.0;
  if (best.status != LpResult::Status::kOptimal || margin < p_.min_margin) return {};
  // The largest margin is reached on a whole face of the feasible polytope and the solver
  // returns one of its corners, where A tends to graze other features. Keep half the margin
  // and move to the mean of the extreme translations along +-x, +-y, +-z: a point well inside
  // the region of translations that keep the contacts.
  lp.c[3] = 0.0;
  auto extremes_at = [&](double floor) {
    lp.lower[3] = {true, floor};
    std::vector<LpVector> ext;
    for (int axis = 0; axis < 3; ++axis)
      for (double sign : {1.0, -1.0}) {
        lp.c[axis] = sign;
        const LpResult r = solve(lp);
        lp.c[axis] = 0.0;
        if (r.status == LpResult::Status::kOptimal) ext.push_back(r.x);
      }
    return ext;
  };
  const std::vector<LpVector> extremes = memo_set ? memo->half : extremes_at(0.5 * margin);
  if (memo && !memo_set) *memo = TranslationMemo{true, best, extremes};
  if (extremes.empty()) return {best.x.head<3>()};
  if (near_boundary) {
    // Near a wall the contact may have to sit close to its element's boundary: extremes that
    // keep only 5% of the margin (still at least min_margin), pulled a little towards the
    // centre of the first set.
    LpVector c0 = LpVector::Zero(best.x.size());
    for (const auto& x : extremes) c0 += x;
    c0 /= static_cast<double>(extremes.size());
    std::vector<Vec3> out;
    for (const auto& x : extremes_at(std::max(p_.min_margin, 0.05 * margin)))
      out.push_back((0.9 * x + 0.1 * c0).head<3>());
    return out;
  }
  LpVector center = LpVector::Zero(best.x.size());
  for (const auto& x : extremes) center += x;
  center /= static_cast<double>(extremes.size());
  std::vector<Vec3> out{center.head<3>()};
  // Midway between the two extremes along each axis: centred along that axis, and feasible
  // (the region is convex), where the mean of all six may sit off-centre in a narrow place.
  if (extremes.size() == 6)
    for (int axis = 0; axis < 3; ++axis)
      out.push_back((0.5 * (extremes[2 * axis] + extremes[2 * axis + 1])).head<3>());
  for (const auto& x : extremes) out.push_back((0.5 * (center + x)).head<3>());
  out.push_back(best.x.head<3>());
  return out;
}

namespace {

// A convex part of an element: its points and its edges' directions (A's turned by R), and
// the face's normal (zero for an edge or a vertex).
struct ConvexPart {
  std::vector<Vec3> points, dirs;
  Vec3 normal = Vec3::Zero();
};

// The closure of element i of kind k of m, turned by R, as one part.
ConvexPart closure_part(const Polyhedron& m, ElementKind k, int i, const Mat3& R) {
  ConvexPart c;
  c.points = closure_points(m, k, i);
  c.dirs = closure_directions(m, k, i);
  for (Vec3& p : c.points) p = R * p;
  for (Vec3& d : c.dirs) d = R * d;
  if (k == ElementKind::kFace) c.normal = R * m.faces()[i].normal;
  return c;
}

// The convex parts of an element: a face's convex pieces where it has more than one (a face
// with a hole or a reflex corner, whose hull would cover the hole), else its closure.
std::vector<ConvexPart> convex_parts(const ModelInfo& mi, ElementKind k, int i, const Mat3& R) {
  const Polyhedron& m = *mi.model;
  if (k != ElementKind::kFace || mi.pieces[i].size() <= 1) return {closure_part(m, k, i, R)};
  const Face& f = m.faces()[i];
  std::vector<ConvexPart> out;
  for (const ConvexPiece& piece : mi.pieces[i]) {
    ConvexPart c;
    c.normal = R * f.normal;
    const std::size_t n = piece.points.size();
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector2d& a = piece.points[j];
      c.points.push_back(R * (a.x() * f.u + a.y() * f.v + f.offset * f.normal));
      const Eigen::Vector2d d = piece.points[(j + 1) % n] - a;
      if (d.norm() > 0) c.dirs.push_back(R * (d.x() * f.u + d.y() * f.v).normalized());
    }
    out.push_back(std::move(c));
  }
  return out;
}

// The cut (a row n.t >= h on the translation) in which parts a (A's, before translation by t)
// and b are at least `gap` apart along a separating axis of their hulls: face normals, edge
// cross products, and for the lower-dimensional pairs the directions between an edge or a
// point and a point, none within 1e-9 of a direction in `avoid`; of these the one that needs
// the smallest move from t. Each axis is tried both ways, in this order (the first of equal
// moves is kept); hundreds for two faces, so each axis is taken as it comes, and its opposite
// from the same extents (the negated products are exact). False when no axis separates them.
bool best_cut(const ConvexPart& a, const ConvexPart& b, const Vec3& t, double gap, double scale,
              const std::vector<Vec3>& avoid, LinearProgram::Row& cut) {
  double best_move = std::numeric_limits<double>::infinity();
  auto try_axis = [&](Vec3 n) {
    const double len = n.norm();
    if (len < 1e-9 * scale) return;
    n /= len;
    for (const Vec3& d : avoid)
      if (std::abs(n.dot(d)) > 1 - 1e-9) return;
    double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo, b_lo = a_lo, b_hi = -a_lo;
    for (const Vec3& p : a.points) {
      const double x = n.dot(p);
      a_lo = std::min(a_lo, x);
      a_hi = std::max(a_hi, x);
    }
    for (const Vec3& q : b.points) {
      const double x = n.dot(q);
      b_lo = std::min(b_lo, x);
      b_hi = std::max(b_hi, x);
    }
    const double n_t = n.dot(t);
    // A on m's side: min over A of m.(p + t) >= max over B of m.q + gap.
    auto side = [&](const Vec3& m, double a_min, double b_max, double m_t) {
      const double rhs = b_max - a_min + gap;
      const double move = rhs - m_t;
      if (move < best_move) {
        best_move = move;
        cut = {{{0, m.x()}, {1, m.y()}, {2, m.z()}}, LinearProgram::Rel::kGreaterEq, rhs};
      }
    };
    side(n, a_lo, b_hi, n_t);
    side(-n, -a_hi, -b_lo, -n_t);
  };
  if (a.normal != Vec3::Zero()) try_axis(a.normal);
  if (b.normal != Vec3::Zero()) try_axis(b.normal);
  for (const Vec3& x : a.dirs)
    for (const Vec3& y : b.dirs) try_axis(x.cross(y));
  for (const Vec3& p : a.points)
    for (const Vec3& q : b.points) {
      const Vec3 w = q - (p + t);
      try_axis(w);
      for (const Vec3& x : a.dirs) try_axis(w - w.dot(x) * x);
      for (const Vec3& y : b.dirs) try_axis(w - w.dot(y) * y);
    }
  return best_move < std::numeric_limits<double>::infinity();
}

}  // namespace

bool WitnessSearch::separating_cut(const Mat3& R, const Vec3& t, const Obstacle& o,
                                   LinearProgram::Row& cut) const {
  return best_cut(closure_part(*A_.model, o.ka, o.a, R),
                  closure_part(*B_.model, o.kb, o.b, Mat3::Identity()), t, 2 * p_.min_clearance,
                  scale_, {}, cut);
}

double WitnessSearch::obstacle_margin(const PcSet& pcs, const Mat3& R,
                                      const std::vector<int>& pieces,
                                      const std::vector<Obstacle>& obstacles, const Vec3& t_axes,
                                      LpVector& x, std::vector<LinearProgram::Row>& cuts,
                                      std::vector<std::vector<Vec3>>& cut_points) const {
  constexpr double kNone = -std::numeric_limits<double>::infinity();
  cuts.clear();
  cut_points.clear();
  LinearProgram lp = build_lp(pcs, R, pieces);
  lp.lower[3] = {true, -scale_};
  std::vector<Vec3> normals;
  Pose at;
  at.R_BA = R;
  at.t_BA = t_axes;
  for (const Pc& pc : pcs) normals.push_back(contact_plane(pc, at).first);
  for (const Obstacle& o : obstacles) {
    const std::vector<ConvexPart> pa = convex_parts(A_, o.ka, o.a, Mat3::Identity());
    const std::vector<ConvexPart> pb = convex_parts(B_, o.kb, o.b, Mat3::Identity());
    for (const ConvexPart& a : pa) {
      ConvexPart turned = a;
      for (Vec3& p : turned.points) p = R * p;
      for (Vec3& d : turned.dirs) d = R * d;
      turned.normal = R * a.normal;
      for (const ConvexPart& b : pb) {
        LinearProgram::Row cut;
        if (!best_cut(turned, b, t_axes, 2 * p_.min_clearance, scale_, normals, cut)) return kNone;
        cuts.push_back(cut);
        cut_points.push_back(a.points);
        // m.t >= rhs becomes m.t - s >= rhs - min_margin: the gap beyond the cut is the margin.
        cut.a.push_back({3, -1.0});
        cut.b -= p_.min_margin;
        lp.rows.push_back(cut);
      }
    }
  }
  const LpResult r = solve(lp);
  if (r.status != LpResult::Status::kOptimal) return kNone;
  x = r.x;
  return r.x[3];
}

bool WitnessSearch::obstacle_step(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces,
                                  const LpVector& x, const std::vector<LinearProgram::Row>& cuts,
                                  const std::vector<std::vector<Vec3>>& cut_points, double turn,
                                  Mat3& next) const {
  const RotConstraints c = rotation_constraints(pcs, A_, B_);
  if (c.align.size() >= 2 || (c.align.size() == 1 && !c.perp.empty())) return false;  // fixed
  // The contact rows at R and at R turned by h about each axis: the rows keep their order and
  // their variables, so the difference of each coefficient and right side, over h, is its
  // derivative along that turn (the rows are linear in R). A row a(R).x REL b(R) becomes, to
  // first order in the turn w, a.x + sum_k w_k (da_k.x0 - db_k) REL b, with x0 the solution
  // at R.
  constexpr double kH = 1e-6;  // rad
  LinearProgram lp = build_lp(pcs, R, pieces, 3);
  const int W = lp.num_vars - 3;
  const std::size_t contact_rows = lp.rows.size();
  auto value = [&](const LinearProgram::Coefs& a) {
    double v = 0;
    for (const auto& [j, cj] : a) v += cj * x[j];
    return v;
  };
  std::vector<std::array<double, 3>> dw(contact_rows);  // d(row)/dw, zero-initialised
  for (int k = 0; k < 3; ++k) {
    const LinearProgram turned = build_lp(pcs, axis_angle(Vec3::Unit(k), kH) * R, pieces);
    if (turned.rows.size() != contact_rows) return false;
    for (std::size_t i = 0; i < contact_rows; ++i)
      dw[i][static_cast<std::size_t>(k)] =
          ((value(turned.rows[i].a) - value(lp.rows[i].a)) - (turned.rows[i].b - lp.rows[i].b)) /
          kH;
  }
  for (std::size_t i = 0; i < contact_rows; ++i)
    for (int k = 0; k < 3; ++k)
      if (dw[i][static_cast<std::size_t>(k)] != 0.0)
        lp.rows[i].a.push_back({W + k, dw[i][static_cast<std::size_t>(k)]});
  // Obstacles: each cut's axis m kept fixed in the world (a fixed axis still proves the
  // elements apart at any pose); every point p of A's element, turned with A, stays beyond B's
  // extent on it: m.(R p + w x R p + t) - s >= max_B m.q + 2 min_clearance - min_margin.
  for (std::size_t i = 0; i < cuts.size() && i < cut_points.size(); ++i) {
    Vec3 m = Vec3::Zero();
    for (const auto& [j, cj] : cuts[i].a) m[j] = cj;
    double a_min = std::numeric_limits<double>::infinity();
    for (const Vec3& p : cut_points[i]) a_min = std::min(a_min, m.dot(R * p));
    const double b_max = cuts[i].b - 2 * p_.min_clearance + a_min;
    for (const Vec3& p : cut_points[i]) {
      const Vec3 Rp = R * p;
      const Vec3 g = Rp.cross(m);
      LinearProgram::Coefs row{{0, m.x()}, {1, m.y()}, {2, m.z()}, {3, -1.0}};
      for (int k = 0; k < 3; ++k) row.push_back({W + k, g[k]});
      lp.add(row, Rel::kGreaterEq, b_max + 2 * p_.min_clearance - p_.min_margin - m.dot(Rp));
    }
  }
  // The rotational conditions, to first order: an aligned normal b allows turns about b only;
  // (R u).w == 0 becomes w.((R u) x w) == -(R u).w.
  for (const auto& [a, b] : c.align) {
    Vec3 e1 = b.unitOrthogonal(), e2 = b.cross(e1).normalized();
    lp.add({{W, e1.x()}, {W + 1, e1.y()}, {W + 2, e1.z()}}, Rel::kEq, 0.0);
    lp.add({{W, e2.x()}, {W + 1, e2.y()}, {W + 2, e2.z()}}, Rel::kEq, 0.0);
  }
  for (const auto& [u, w] : c.perp) {
    const Vec3 Ru = R * u;
    const Vec3 g = Ru.cross(w);
    lp.add({{W, g.x()}, {W + 1, g.y()}, {W + 2, g.z()}}, Rel::kEq, -Ru.dot(w));
  }
  lp.lower[3] = {true, -scale_};
  for (int k = 0; k < 3; ++k) {
    lp.lower[static_cast<std::size_t>(W + k)] = {true, -turn};
    lp.upper[static_cast<std::size_t>(W + k)] = {true, turn};
  }
  const LpResult r = solve(lp);
  if (r.status != LpResult::Status::kOptimal) return false;
  const Vec3 w(r.x[W], r.x[W + 1], r.x[W + 2]);
  const double ang = w.norm();
  if (!(ang > 0)) return false;
  if (c.align.size() == 1) {
    // Only turns about the aligned normal keep the alignment; the program meets its rows to
    // its tolerance, so take w's component along it exactly.
    const Vec3& b = c.align[0].second;
    next = axis_angle(b, w.dot(b)) * R;
    return true;
  }
  next = axis_angle(w / ang, ang) * R;
  if (!c.perp.empty() && !project_perp(c, next)) return false;
  return true;
}

}  // namespace cf::gen
