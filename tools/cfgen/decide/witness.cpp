#include "cfgen/decide/witness.hpp"

#include "cfgen/decide/mirror_corners.hpp"
#include "cfgen/decide/rotation_family.hpp"
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

WitnessSearch::WitnessSearch(const ModelInfo& a, const ModelInfo& b, const SearchParams& p)
    : Verifier(a, b, p), debug_(std::getenv("CFGEN_DEBUG") != nullptr) {}

const char* rule_name(Rule rule) {
  switch (rule) {
    case Rule::kNone:
      return "";
    case Rule::kVertexInTwoPcs:
      return "vertex-in-two-pcs";
    case Rule::kDominatedPc:
      return "dominated-pc";
    case Rule::kOneContactPlane:
      return "one-contact-plane";
    case Rule::kHeightsOverFf:
      return "heights-over-ff";
    case Rule::kRotationalConditions:
      return "rotational-conditions";
    case Rule::kFiniteRotations:
      return "finite-rotations";
    case Rule::kMirrorCorners:
      return "mirror-corners";
  }
  return "";
}

RuleVerdict WitnessSearch::implausible_by(const PcSet& pcs) const {
  // A point lies in at most one open element: one vertex cannot make two PCs.
  for (int i = 0; i < pcs.size(); ++i)
    for (int j = i + 1; j < pcs.size(); ++j) {
      const Pc& x = pcs[i];
      const Pc& y = pcs[j];
      if (a_kind(x.type) == ElementKind::kVertex && a_kind(y.type) == ElementKind::kVertex &&
          x.a == y.a)
        return {Rule::kVertexInTwoPcs, i, j};
      if (b_kind(x.type) == ElementKind::kVertex && b_kind(y.type) == ElementKind::kVertex &&
          x.b == y.b)
        return {Rule::kVertexInTwoPcs, i, j};
      // A PC whose two elements lie in the closures of another's is dominated by it, not
      // principal.
      const Polyhedron& A = *A_.model;
      const Polyhedron& B = *B_.model;
      if ((in_closure(A, a_kind(x.type), x.a, a_kind(y.type), y.a) &&
           in_closure(B, b_kind(x.type), x.b, b_kind(y.type), y.b)) ||
          (in_closure(A, a_kind(y.type), y.a, a_kind(x.type), x.a) &&
           in_closure(B, b_kind(y.type), y.b, b_kind(x.type), x.b)))
        return {Rule::kDominatedPc, i, j};
      // Two PCs on one plane of B, or one plane of A, share their contact plane.
      const bool xb = b_kind(x.type) == ElementKind::kFace,
                 yb = b_kind(y.type) == ElementKind::kFace;
      if (xb && yb && B_.face_plane[x.b] == B_.face_plane[y.b])
        return {Rule::kOneContactPlane, i, j};
      const bool xa = a_kind(x.type) == ElementKind::kFace,
                 ya = a_kind(y.type) == ElementKind::kFace;
      if (xa && ya && A_.face_plane[x.a] == A_.face_plane[y.a])
        return {Rule::kOneContactPlane, i, j};
    }
  // Heights over a face-face contact: while faces a and b lie against each other, a point's
  // depth below A's face plane (along A's normal, into A) is its height over B's face plane
  // (along B's normal), whatever the spin and the slide in the plane. So every other PC's
  // contact point, a common point of its two elements, needs the two elements' height
  // ranges over that plane to meet.
  // A witness meets the f-f's alignment to its tolerance, which tilts heights by that much
  // per mm of A; both contacts touch within touch_tol.
  const Polyhedron& mA = *A_.model;
  for (int f = 0; f < pcs.size(); ++f) {
    const Pc& ff = pcs[f];
    if (ff.type != PcType::kFF) continue;
    const double tol = condition_tol(A_, ElementKind::kFace, ff.a, B_, ElementKind::kFace, ff.b) *
                           (mA.bbox_max() - mA.bbox_min()).norm() +
                       2 * p_.touch_tol;
    const Face& fa = A_.model->faces()[ff.a];
    const Face& fb = B_.model->faces()[ff.b];
    for (int k = 0; k < pcs.size(); ++k) {
      const Pc& pc = pcs[k];
      if (k == f) continue;
      double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo, b_lo = a_lo,
             b_hi = -a_lo;
      for (const Vec3& p : closure_points(*A_.model, a_kind(pc.type), pc.a)) {
        const double h = fa.offset - fa.normal.dot(p);
        a_lo = std::min(a_lo, h);
        a_hi = std::max(a_hi, h);
      }
      for (const Vec3& q : closure_points(*B_.model, b_kind(pc.type), pc.b)) {
        const double h = fb.normal.dot(q) - fb.offset;
        b_lo = std::min(b_lo, h);
        b_hi = std::max(b_hi, h);
      }
      // An element's open points span the open interval (lo, hi), or the one height of an
      // element parallel to the plane.
      const bool a_flat = a_hi - a_lo <= tol, b_flat = b_hi - b_lo <= tol;
      bool meet;
      if (a_flat && b_flat)
        meet = std::abs(a_lo - b_lo) <= 2 * tol;
      else if (a_flat)
        meet = a_lo > b_lo + tol && a_lo < b_hi - tol;
      else if (b_flat)
        meet = b_lo > a_lo + tol && b_lo < a_hi - tol;
      else
        meet = std::max(a_lo, b_lo) < std::min(a_hi, b_hi) - tol;
      if (!meet) return {Rule::kHeightsOverFf, f, k};
    }
  }
  return {};
}
Witness WitnessSearch::refine(const PcSet& pcs, const Pose& pose) const {
  Witness out;
  const std::vector<int> slot_sizes = piece_slots(pcs);
  auto accept = [&](const Pose& q) {
    const double c = verify(pcs, q);
    if (c < p_.min_clearance || contact_margin(pcs, q) < p_.min_margin) return false;
    out.found = true;
    out.pose = q;
    out.clearance = c;
    return true;
  };
  // The translations that keep the contacts inside their elements form a convex set that
  // holds the given pose: move from it towards that set's centre, most central first.
  std::vector<int> choice(slot_sizes.size(), 0);
  for (int combo = 0; combo < p_.max_piece_combinations; ++combo) {
    double margin = 0;
    const std::vector<Vec3> ts = translations(pcs, pose.R_BA, choice, margin, false);
    if (!ts.empty())
      for (double lambda : {0.5, 0.25, 0.1, 0.03}) {
        Pose q = pose;
        q.t_BA = pose.t_BA + lambda * (ts.front() - pose.t_BA);
        if (accept(q)) return out;
      }
    std::size_t i = 0;
    while (i < choice.size() && ++choice[i] == slot_sizes[i]) choice[i++] = 0;
    if (i == choice.size()) break;
  }
  accept(pose);
  return out;
}

Witness WitnessSearch::image_witness(const PcSet& pcs, const Pose& image) const {
  Witness w;
  w.pose = image;
  w.clearance = verify(pcs, image);
  w.found = w.clearance >= p_.min_clearance;
  if (w.found) return w;
  const RotConstraints c = rotation_constraints(pcs, A_, B_);
  for (const Mat3& R : project_onto(c, image.R_BA)) {
    Pose q = image;
    q.R_BA = R;
    const Witness r = refine(pcs, q);
    if (r.found) return r;
  }
  return w;
}

std::vector<int> WitnessSearch::piece_slots(const PcSet& pcs) const {
  std::vector<int> slot_sizes;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kVF:
      case PcType::kEF:
        slot_sizes.push_back(int(B_.pieces[pc.b].size()));
        break;
      case PcType::kFV:
      case PcType::kFE:
        slot_sizes.push_back(int(A_.pieces[pc.a].size()));
        break;
      case PcType::kFF:
        slot_sizes.push_back(int(B_.pieces[pc.b].size()));
        slot_sizes.push_back(int(A_.pieces[pc.a].size()));
        break;
      case PcType::kEE:
        break;
    }
  }
  return slot_sizes;
}

std::optional<std::vector<Mat3>> WitnessSearch::finite_rotations(const PcSet& pcs) const {
  const RotConstraints c = rotation_constraints(pcs, A_, B_);
  if (c.align.empty()) return perp_roots(c);
  bool finite = false;
  std::vector<Mat3> rots = align_family(c, {}, 0, &finite);
  if (!finite && !rots.empty()) return std::nullopt;
  // No other condition fixed the spin: the family is continuous unless a condition failed,
  // and align_family returns nothing either way. Tell them apart with one sample.
  if (!finite && !align_family(c, {}, 1).empty()) return std::nullopt;
  return rots;
}

RuleVerdict WitnessSearch::refuted_by(const PcSet& pcs) const {
  if (const RuleVerdict v = implausible_by(pcs); v.rule != Rule::kNone) return v;
  for (int i = 0; i < pcs.size(); ++i)
    for (int j = i + 1; j < pcs.size(); ++j)
      if (mirror_corners(*A_.model, *B_.model, pcs[i], pcs[j], verified_local_slack()))
        return {Rule::kMirrorCorners, i, j};
  const std::optional<std::vector<Mat3>> finite = finite_rotations(pcs);
  if (!finite) return {};  // a continuous family of rotations: not decided here
  const std::vector<Mat3>& rots = *finite;
  std::size_t combos = 1;
  const std::vector<int> slot_sizes = piece_slots(pcs);
  for (int n : slot_sizes) combos *= static_cast<std::size_t>(n);
  if (combos > 4096) return {};
  // Without an f-f, the checker cannot recheck that no rotation exists (docs/certificates.md):
  // the finite-rotations rule, evidence only, stands for that case too.
  const bool ff =
      std::any_of(pcs.begin(), pcs.end(), [](const Pc& pc) { return pc.type == PcType::kFF; });
  if (rots.empty()) return {ff ? Rule::kRotationalConditions : Rule::kFiniteRotations};
  // Finitely many rotations: each must be locally penetrating or leave no room to place the
  // contacts inside their elements (the LP over every combination of convex pieces).
  for (const Mat3& R : rots) {
    if (local_margin(pcs, R) < verified_local_slack()) continue;
    std::vector<int> choice(slot_sizes.size(), 0);
    for (std::size_t k = 0; k < combos; ++k) {
      const LpResult r = solve(build_lp(pcs, R, choice));
      if (r.status == LpResult::Status::kOptimal && r.x[3] >= thin_params(p_).min_margin) return {};
      for (std::size_t i = 0; i < choice.size() && ++choice[i] == slot_sizes[i]; ++i) choice[i] = 0;
    }
  }
  return {Rule::kFiniteRotations};
}

}  // namespace cf::gen
