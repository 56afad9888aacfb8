#include "cfgen/decide/cell_relaxation.hpp"

#include "cfgen/decide/first_order.hpp"
#include "cfgen/verify/rotation_conditions.hpp"
#include "cfgen/verify/verifier.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cf::gen {
namespace {

using Rel = LinearProgram::Rel;

// Parameters a PC's contact point takes on each side: a point of A's edge (1) or face (2),
// of B's edge (1); B's faces are met by rows on the image point, vertices are fixed.
int params_of(PcType type) {
  int n = 0;
  if (a_kind(type) == ElementKind::kEdge) n += 1;
  if (a_kind(type) == ElementKind::kFace) n += 2;
  if (b_kind(type) == ElementKind::kEdge) n += 1;
  return n;
}

int num_vars(const PcSet& pcs) {
  int n = 3;
  for (const Pc& pc : pcs) n += params_of(pc.type);
  return n;
}

// Unit outward normal (2D) of side k of a counter-clockwise convex piece, and its offset:
// the piece is { q : o . q <= o . P_k } over its sides.
std::pair<Eigen::Vector2d, double> side_row(const ConvexPiece& piece, std::size_t k) {
  const Eigen::Vector2d& p = piece.points[k];
  const Eigen::Vector2d& q = piece.points[(k + 1) % piece.points.size()];
  Eigen::Vector2d o(q.y() - p.y(), p.x() - q.x());
  o.normalize();
  return {o, o.dot(p)};
}

// How much of the margin a witness keeps from a boundary side's line soundly carries over
// (docs/certificates.md, "The programs"): a contact point at least m from the face's
// boundary is at least m from the side's line where it projects inside the side; past an end
// where the piece turns by phi < pi / 2 onto a diagonal (the face goes on) or onto a
// boundary side shorter than m / sin(phi), the piece's wedge there keeps it only
// m sin(phi) from the line.
double side_margin_factor(const ConvexPiece& piece, std::size_t k, double margin) {
  const std::size_t n = piece.points.size();
  auto dir = [&](std::size_t j) {
    return Eigen::Vector2d(piece.points[(j + 1) % n] - piece.points[j]).normalized();
  };
  auto end_factor = [&](std::size_t next, double cross, double dot) {
    const double phi = std::atan2(cross, dot);  // the turn onto the next side
    if (phi >= M_PI / 2) return 1.0;
    if (phi <= 0) return 0.0;
    const double s = std::sin(phi);
    const double length = (piece.points[(next + 1) % n] - piece.points[next]).norm();
    return piece.boundary[next] && length >= margin / s ? 1.0 : s;
  };
  const Eigen::Vector2d e = dir(k), after = dir((k + 1) % n), before = dir((k + n - 1) % n);
  const double forward =
      end_factor((k + 1) % n, e.x() * after.y() - e.y() * after.x(), e.dot(after));
  const double back =
      end_factor((k + n - 1) % n, before.x() * e.y() - before.y() * e.x(), before.dot(e));
  return std::min(forward, back);
}

Vec3 face_point(const Face& f, const Eigen::Vector2d& q) {
  return f.offset * f.normal + q.x() * f.u + q.y() * f.v;
}

// The point A turns about: the one vertex in the closure of every element of A the set uses
// when there is exactly one (the corner two contact edges share), where the programs' rows
// widen least, down to nothing (add_contact), so that contacts that can only meet there are
// refuted at any cell size; else the mean of the elements' closure points `pts`.
Vec3 pivot_of(const Polyhedron& A, const PcSet& pcs, const std::vector<Vec3>& pts) {
  std::vector<Vec3> common = closure_points(A, a_kind(pcs[0].type), pcs[0].a);
  for (int k = 1; k < pcs.size(); ++k) {
    const std::vector<Vec3> c = closure_points(A, a_kind(pcs[k].type), pcs[k].a);
    common.erase(
        std::remove_if(common.begin(), common.end(),
                       [&](const Vec3& p) { return std::find(c.begin(), c.end(), p) == c.end(); }),
        common.end());
  }
  if (common.size() == 1) return common[0];
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : pts) mean += p;
  return mean / static_cast<double>(pts.size());
}

// The next choice of convex pieces (an index per face slot, the first slot counting fastest).
void next_choice(std::vector<int>& choice, const std::vector<int>& slot_sizes) {
  for (std::size_t k = 0; k < choice.size() && ++choice[k] == slot_sizes[k]; ++k) choice[k] = 0;
}

}  // namespace

std::size_t CellRelaxation::choices() const {
  std::size_t n = 1;
  for (int s : slot_sizes_) n *= static_cast<std::size_t>(std::max(s, 1));
  return n;
}

std::vector<std::vector<int>> CellRelaxation::choice_list() const {
  std::vector<std::vector<int>> out;
  std::vector<int> choice(slot_sizes_.size(), 0);
  for (std::size_t c = 0; c < choices(); ++c) {
    out.push_back(choice);
    next_choice(choice, slot_sizes_);
  }
  return out;
}

CellRelaxation::CellRelaxation(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                               double touch_tol, double margin, double local_slack, double rot_tol)
    : A_(a),
      B_(b),
      pcs_(pcs),
      touch_tol_(touch_tol),
      margin_(margin),
      local_slack_(local_slack),
      rot_tol_(rot_tol) {
  if (pcs.empty() || num_vars(pcs) > LinearProgram::kMaxVars)
    throw std::invalid_argument("CellRelaxation: a set of 1 to 3 PCs");
  const Polyhedron& mA = *A_.model;
  const Polyhedron& mB = *B_.model;
  size_ = std::max((mA.bbox_max() - mA.bbox_min()).norm(), (mB.bbox_max() - mB.bbox_min()).norm());
  std::vector<Vec3> pts;
  for (const Pc& pc : pcs) {
    const std::vector<Vec3> p = closure_points(mA, a_kind(pc.type), pc.a);
    pts.insert(pts.end(), p.begin(), p.end());
    if (a_kind(pc.type) == ElementKind::kFace)
      slot_sizes_.push_back(static_cast<int>(A_.pieces[static_cast<std::size_t>(pc.a)].size()));
    if (b_kind(pc.type) == ElementKind::kFace)
      slot_sizes_.push_back(static_cast<int>(B_.pieces[static_cast<std::size_t>(pc.b)].size()));
  }
  pivot_ = pivot_of(mA, pcs, pts);
  // The translation t puts the pivot at t: a contact point x of A goes to R (x - pivot) + t,
  // which must be a point y of B's element, so t = y - R (x - pivot) lies in the box of B's
  // element grown by the largest |x - pivot|.
  t_lo_ = Vec3::Constant(-HUGE_VAL);
  t_hi_ = Vec3::Constant(HUGE_VAL);
  for (const Pc& pc : pcs) {
    double reach = 0;
    for (const Vec3& x : closure_points(mA, a_kind(pc.type), pc.a))
      reach = std::max(reach, (x - pivot_).norm());
    Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
    for (const Vec3& y : closure_points(mB, b_kind(pc.type), pc.b)) {
      lo = lo.cwiseMin(y);
      hi = hi.cwiseMax(y);
    }
    // Touching within touch_tol, and the rounding of the points' coordinates.
    const double slack = reach + touch_tol_ + 1e-12 * size_;
    t_lo_ = t_lo_.cwiseMax(lo - Vec3::Constant(slack));
    t_hi_ = t_hi_.cwiseMin(hi + Vec3::Constant(slack));
  }
  for (int k = 0; k < 3; ++k) empty_ = empty_ || t_lo_[k] > t_hi_[k];
  // An edge shorter than twice the margin has no point that far from both ends.
  for (const Pc& pc : pcs) {
    if (a_kind(pc.type) == ElementKind::kEdge)
      empty_ = empty_ || mA.edge(EdgeId(pc.a)).length < 2 * margin_;
    if (b_kind(pc.type) == ElementKind::kEdge)
      empty_ = empty_ || mB.edge(EdgeId(pc.b)).length < 2 * margin_;
  }
}

CellRelaxation::Verdict CellRelaxation::rotation_test(const Mat3& R_c, const TurnBound& turn,
                                                      int& pc, Vec3& direction,
                                                      double* slack_bound) const {
  const Polyhedron& mA = *A_.model;
  const Polyhedron& mB = *B_.model;
  for (pc = 0; pc < pcs_.size(); ++pc) {
    const Pc& x = pcs_[pc];
    const ElementKind ka = a_kind(x.type), kb = b_kind(x.type);
    // Opposite normals (f-f), an edge parallel to the face (e-f, f-e): A's vector moves by at
    // most turn(vector) over the cell.
    // A pose meets each condition to rot_tol_, not exactly.
    if (x.type == PcType::kFF) {
      const Vec3& na = mA.face(FaceId(x.a)).normal;
      if ((R_c * na + mB.face(FaceId(x.b)).normal).norm() > turn.of(na) + rot_tol_)
        return Verdict::kRotation;
    }
    if (x.type == PcType::kEF) {
      const Vec3& ea = mA.edge(EdgeId(x.a)).dir;
      if (std::abs((R_c * ea).dot(mB.face(FaceId(x.b)).normal)) > turn.of(ea) + rot_tol_)
        return Verdict::kRotation;
    }
    if (x.type == PcType::kFE) {
      const Vec3& na = mA.face(FaceId(x.a)).normal;
      if (std::abs((R_c * na).dot(mB.edge(EdgeId(x.b)).dir)) > turn.of(na) + rot_tol_)
        return Verdict::kRotation;
    }
    // Local non-penetration against a face: the other solid's tangent directions at the
    // contact (a vertex's edge rays, an edge's wedge sides) lie on the face's outer side.
    // Whether pred holds for one of the solid's tangent directions at element i, read in
    // place; that direction goes to `direction`.
    auto any_tangent = [&direction](const ModelInfo& m, ElementKind k, int i, const auto& pred) {
      auto hit = [&](const Vec3& d) {
        if (!pred(d)) return false;
        direction = d;
        return true;
      };
      if (k == ElementKind::kVertex) {
        const auto& rays = m.cones[static_cast<std::size_t>(i)].rays;
        return std::any_of(rays.begin(), rays.end(), hit);
      }
      const EdgeWedge& w = m.wedges[static_cast<std::size_t>(i)];
      return hit(w.into_left) || hit(w.into_right);
    };
    // d . n < 0 for every rotation of the cell, `moved` the most the rotation changes it.
    if (kb == ElementKind::kFace && ka != ElementKind::kFace) {
      const Vec3& nb = mB.face(FaceId(x.b)).normal;
      if (any_tangent(A_, ka, x.a, [&](const Vec3& d) { return (R_c * d).dot(nb) < -turn.of(d); }))
        return Verdict::kCone;
    }
    if (ka == ElementKind::kFace && kb != ElementKind::kFace) {
      const Vec3 na = R_c * mA.face(FaceId(x.a)).normal;
      const double moved = turn.of(mA.face(FaceId(x.a)).normal);
      if (any_tangent(B_, kb, x.b, [&](const Vec3& d) { return d.dot(na) < -moved; }))
        return Verdict::kCone;
    }
  }
  // The slack a witness keeps at every contact: an e-e whose edges turn parallel, or a
  // tangent direction lying in the face, is degenerate there, and the cells near such a
  // limit pose are refuted once they are small against the slack.
  if (local_slack_ > 0) {
    const double bound = local_margin_bound(A_, B_, pcs_, R_c, turn, &pc);
    if (slack_bound) *slack_bound = bound;
    if (bound < local_slack_) return Verdict::kSlack;
  }
  pc = -1;
  return Verdict::kOpen;
}

void CellRelaxation::add_contact(LinearProgram& lp, int i, const Mat3& R_c, const TurnBound& turn,
                                 int& slot, const std::vector<int>& choice) const {
  const Pc& pc = pcs_[i];
  const Polyhedron& mA = *A_.model;
  const Polyhedron& mB = *B_.model;
  int var = 3;
  for (int k = 0; k < i; ++k) var += params_of(pcs_[k].type);
  // A's contact point x(s) = x0 + g0 s0 + g1 s1 (A's frame) and the points it ranges over.
  Vec3 x0;
  std::vector<Vec3> g, pts;
  if (a_kind(pc.type) == ElementKind::kVertex) {
    x0 = mA.vertex(VertexId(pc.a)).p;
    pts = {x0};
  } else if (a_kind(pc.type) == ElementKind::kEdge) {
    x0 = mA.edge_point(EdgeId(pc.a), 0);
    g = {mA.edge_point(EdgeId(pc.a), 1) - x0};
    pts = {x0, x0 + g[0]};
    const double inset = margin_ / g[0].norm();
    lp.lower[var] = {true, inset};
    lp.upper[var] = {true, 1.0 - inset};
  } else {
    const Face& f = mA.face(FaceId(pc.a));
    const ConvexPiece& piece =
        A_.pieces[static_cast<std::size_t>(pc.a)]
                 [static_cast<std::size_t>(choice[static_cast<std::size_t>(slot++)])];
    x0 = f.offset * f.normal;
    g = {f.u, f.v};
    Eigen::Vector2d lo = piece.points[0], hi = piece.points[0];
    for (std::size_t k = 0; k < piece.points.size(); ++k) {
      lo = lo.cwiseMin(piece.points[k]);
      hi = hi.cwiseMax(piece.points[k]);
      pts.push_back(face_point(f, piece.points[k]));
      const auto [o, off] = side_row(piece, k);
      // A side on the face's boundary keeps the point the margin inside; a diagonal of the
      // partition does not bound the face.
      lp.add({{var, o.x()}, {var + 1, o.y()}}, Rel::kLessEq,
             piece.boundary[k] ? off - margin_ * side_margin_factor(piece, k, margin_) : off);
    }
    for (int k = 0; k < 2; ++k) {
      lp.lower[var + k] = {true, lo[k]};
      lp.upper[var + k] = {true, hi[k]};
    }
  }
  // How far the cell's rotations move the image of A's contact point from where R_c puts
  // it: at most turn(x - pivot), a convex function of x. On an edge it is bounded by its
  // chord between the ends, widen + chord s, which vanishes towards an end at the pivot;
  // on a face piece, by its largest value at the corners.
  double moved = 0, chord = 0;
  if (a_kind(pc.type) == ElementKind::kEdge) {
    moved = turn.of(pts[0] - pivot_);
    chord = turn.of(pts[1] - pivot_) - moved;
  } else {
    for (const Vec3& x : pts) moved = std::max(moved, turn.of(x - pivot_));
  }
  const double widen = moved + touch_tol_ + 1e-12 * size_;
  const Vec3 p0 = R_c * (x0 - pivot_);
  std::vector<Vec3> Rg;
  for (const Vec3& d : g) Rg.push_back(R_c * d);
  // a . (image of x(s)) <= b, the image R (x(s) - pivot) + t known within `widen` (+ `chord`
  // s) of R_c (x(s) - pivot) + t; `extra`: one more term (a B edge's parameter).
  auto row = [&](const Vec3& a, double b, int extra_var = -1, double extra = 0) {
    LinearProgram::Coefs c;
    for (int j = 0; j < 3; ++j) c.push_back({j, a[j]});
    for (std::size_t k = 0; k < Rg.size(); ++k)
      c.push_back({var + int(k), a.dot(Rg[k]) - (k == 0 ? a.norm() * chord : 0.0)});
    if (extra_var >= 0) c.push_back({extra_var, extra});
    lp.add(c, Rel::kLessEq, b + a.norm() * widen - a.dot(p0));
  };
  const int b_var = var + static_cast<int>(g.size());
  if (b_kind(pc.type) == ElementKind::kVertex) {
    const Vec3 w = mB.vertex(VertexId(pc.b)).p;
    for (int j = 0; j < 3; ++j) {
      row(Vec3::Unit(j), w[j]);
      row(-Vec3::Unit(j), -w[j]);
    }
  } else if (b_kind(pc.type) == ElementKind::kEdge) {
    const Vec3 b0 = mB.edge_point(EdgeId(pc.b), 0);
    const Vec3 d = mB.edge_point(EdgeId(pc.b), 1) - b0;
    const double inset = margin_ / d.norm();
    lp.lower[b_var] = {true, inset};
    lp.upper[b_var] = {true, 1.0 - inset};
    for (int j = 0; j < 3; ++j) {
      row(Vec3::Unit(j), b0[j], b_var, -d[j]);
      row(-Vec3::Unit(j), -b0[j], b_var, d[j]);
    }
  } else {
    const Face& f = mB.face(FaceId(pc.b));
    const ConvexPiece& piece =
        B_.pieces[static_cast<std::size_t>(pc.b)]
                 [static_cast<std::size_t>(choice[static_cast<std::size_t>(slot++)])];
    row(f.normal, f.offset);
    row(-f.normal, -f.offset);
    for (std::size_t k = 0; k < piece.points.size(); ++k) {
      const auto [o, off] = side_row(piece, k);
      row(o.x() * f.u + o.y() * f.v,
          piece.boundary[k] ? off - margin_ * side_margin_factor(piece, k, margin_) : off);
    }
  }
}

LinearProgram CellRelaxation::program(const Mat3& R_c, const TurnBound& turn,
                                      const std::vector<int>& choice, const Vec3& t_lo,
                                      const Vec3& t_hi) const {
  LinearProgram lp(num_vars(pcs_));
  for (int j = 0; j < 3; ++j) {
    lp.lower[j] = {true, t_lo[j]};
    lp.upper[j] = {true, std::max(t_lo[j], t_hi[j])};
  }
  int slot = 0;
  for (int i = 0; i < pcs_.size(); ++i) add_contact(lp, i, R_c, turn, slot, choice);
  return lp;
}

CellRelaxation::Refutation CellRelaxation::refute(const RotationCell& cell, Vec3& t_lo, Vec3& t_hi,
                                                  bool with_certificates,
                                                  std::size_t max_choices) const {
  return refute(rotation_at(cell.centre), TurnBound{turn_bound(cell)}, t_lo, t_hi,
                with_certificates, max_choices);
}

CellRelaxation::Refutation CellRelaxation::refute(const Mat3& R_c, const TurnBound& turn,
                                                  Vec3& t_lo, Vec3& t_hi, bool with_certificates,
                                                  std::size_t max_choices,
                                                  bool may_keep_box) const {
  Refutation out;
  if (empty_) {
    out.verdict = Verdict::kBounds;
    return out;
  }
  double bound = HUGE_VAL;
  out.verdict = rotation_test(R_c, turn, out.pc, out.direction, &bound);
  if (out.verdict != Verdict::kOpen) return out;
  if (may_keep_box && local_slack_ > 0) {
    const double centre = local_margin_bound(A_, B_, pcs_, R_c, TurnBound{});
    out.unsettled = centre - (bound - centre) < local_slack_;
  }
  // A cube of rotations (no arc): its turn bound is an angle.
  if (local_slack_ > 0 && turn.about == 0 && turn.any > 0 &&
      first_order_refutes(A_, B_, pcs_, R_c, turn.any, local_slack_, rot_tol_,
                          with_certificates ? &out.certificates : nullptr)) {
    out.verdict = Verdict::kFirstOrder;
    return out;
  }
  const std::size_t choices = this->choices();
  if (choices > max_choices) return out;
  std::vector<int> choice(slot_sizes_.size(), 0);
  Vec3 lo = Vec3::Constant(HUGE_VAL), hi = Vec3::Constant(-HUGE_VAL);
  bool open = false;
  for (std::size_t c = 0; c < choices; ++c) {
    LinearProgram lp = program(R_c, turn, choice, t_lo, t_hi);
    if (solve(lp).status == LpResult::Status::kOptimal) {
      open = true;
      if (out.unsettled) {  // kOpen, the box as given
        out.certificates.clear();
        return out;
      }
      // The translations this choice allows: each coordinate's least and greatest value.
      for (int j = 0; j < 3; ++j)
        for (double sign : {1.0, -1.0}) {
          std::fill(lp.c.begin(), lp.c.end(), 0.0);
          lp.c[static_cast<std::size_t>(j)] = sign;
          const LpResult r = solve(lp);
          // Unsolved: keep the bound given.
          const double v = r.status == LpResult::Status::kOptimal ? r.x[j]
                           : sign > 0                             ? t_lo[j]
                                                                  : t_hi[j];
          if (sign > 0)
            lo[j] = std::min(lo[j], v);
          else
            hi[j] = std::max(hi[j], v);
        }
    } else {
      std::optional<FarkasCertificate> proof = farkas(lp);
      if (!proof) return out;  // not solved, and not proven infeasible either
      if (with_certificates) out.certificates.push_back(std::move(*proof));
    }
    next_choice(choice, slot_sizes_);
  }
  if (!open) {
    out.verdict = Verdict::kProgram;
    return out;
  }
  // The programs' optima are within the solver's tolerances (reduced costs 1e-9, rows 1e-7
  // (1 + |b|)) of the true ones: grow the range by more than those.
  const Vec3 slack = Vec3::Constant(1e-7 * (1 + size_));
  out.certificates.clear();
  std::vector<Slab> cut = narrow(R_c, turn, t_lo, t_hi, lo - slack, hi + slack);
  if (with_certificates) out.slabs = std::move(cut);
  return out;
}

// Narrows [t_lo, t_hi] towards [lo, hi] one side after the other, cutting off a slab only
// where the Farkas proofs of its programs (every choice of pieces) are found: the bounds come
// from the programs' optima, which are not proofs. The slabs cut off, with their proofs.
std::vector<CellRelaxation::Slab> CellRelaxation::narrow(const Mat3& R_c, const TurnBound& turn,
                                                         Vec3& t_lo, Vec3& t_hi, const Vec3& lo,
                                                         const Vec3& hi) const {
  std::vector<Slab> out;
  auto cut = [&](int j, bool low) {
    Slab slab{t_lo, t_hi, {}};
    (low ? slab.hi : slab.lo)[j] = low ? lo[j] : hi[j];
    std::vector<int> choice(slot_sizes_.size(), 0);
    for (std::size_t c = 0; c < choices(); ++c) {
      std::optional<FarkasCertificate> proof = farkas(program(R_c, turn, choice, slab.lo, slab.hi));
      if (!proof) return;  // not proven: this side stays
      slab.proofs.push_back(std::move(*proof));
      next_choice(choice, slot_sizes_);
    }
    (low ? t_lo : t_hi)[j] = low ? lo[j] : hi[j];
    out.push_back(std::move(slab));
  };
  for (int j = 0; j < 3; ++j) {
    if (lo[j] > t_lo[j]) cut(j, true);
    if (hi[j] < t_hi[j]) cut(j, false);
  }
  return out;
}

bool CellRelaxation::holds_at(const Mat3& R) const {
  int pc = -1;
  Vec3 direction;
  if (empty_ || rotation_test(R, TurnBound{rot_tol_}, pc, direction) != Verdict::kOpen)
    return false;
  std::vector<int> choice(slot_sizes_.size(), 0);
  for (std::size_t c = 0; c < choices(); ++c) {
    if (solve(program(R, TurnBound{}, choice, t_lo_, t_hi_)).status == LpResult::Status::kOptimal)
      return true;
    next_choice(choice, slot_sizes_);
  }
  return false;
}

}  // namespace cf::gen
