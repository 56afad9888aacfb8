// The rotations the witness search tries (witness.hpp): seeds projected onto the PCs'
// conditions, each PC's preferred family, a spread over SO(3), and rotations anchored at
// sample points of two point contacts.

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

std::vector<Mat3> WitnessSearch::family_samples(const PcSet& pcs, const std::vector<Mat3>& seeds,
                                                int samples) const {
  const RotConstraints c = rotation_constraints(pcs, A_, B_);
  std::vector<Mat3> rots;
  if (!c.align.empty()) {
    rots = align_family(c, seeds, samples);
  } else if (!c.perp.empty()) {
    for (Mat3 R : seeds)
      if (project_perp(c, R)) add_unique(rots, R);
    // Three conditions leave finitely many rotations: all of them, whatever the seeds reach.
    if (const auto roots = perp_roots(c))
      for (const Mat3& R : *roots) add_unique(rots, R);
  } else {
    for (const Mat3& R : seeds) add_unique(rots, R);
  }
  return rots;
}

std::vector<Mat3> WitnessSearch::spread_rotations(const PcSet& pcs,
                                                  const std::vector<Mat3>& seeds) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  // Each PC's preferred one-parameter family: its local conditions hold with most slack.
  std::vector<Mat3> prefs;
  const int n = std::max(4, p_.theta_samples / std::max(1, pcs.size()));
  for (const Pc& pc : pcs) {
    Vec3 x = Vec3::Zero(), y = Vec3::Zero();  // align A-frame x to world y, spin about y
    switch (pc.type) {
      case PcType::kFF:
        x = A.faces()[pc.a].normal;
        y = -B.faces()[pc.b].normal;
        break;
      case PcType::kVF:
        x = A_.cones[pc.a].center;
        y = B.faces()[pc.b].normal;
        break;
      case PcType::kFV:
        x = A.faces()[pc.a].normal;
        y = B_.cones[pc.b].center;
        break;
      case PcType::kEF:
        x = A_.wedges[pc.a].bisector;
        y = -B.faces()[pc.b].normal;
        break;
      case PcType::kFE:
        x = A.faces()[pc.a].normal;
        y = -B_.wedges[pc.b].bisector;
        break;
      case PcType::kEE:
        x = A_.wedges[pc.a].bisector;
        y = -B_.wedges[pc.b].bisector;
        break;
    }
    if (x.norm() < 0.5 || y.norm() < 0.5) continue;
    const Mat3 R0 = align(x, y);
    for (int k = 0; k < n; ++k) prefs.push_back(axis_angle(y, 0.05 + 2 * M_PI * k / n) * R0);
  }
  std::vector<Mat3> all_seeds = seeds;
  all_seeds.insert(all_seeds.end(), prefs.begin(), prefs.end());
  // Spread-out seeds so that constrained families are covered beyond the preferred ones:
  // the 24 rotations of the cube's symmetry group, each tilted twice by fixed generic
  // rotations so that none sits exactly on a special alignment.
  static const std::vector<Mat3> kSpread = [] {
    std::vector<Mat3> out;
    // Two tilts: a large one, and a small one for narrow places (a vertex or an edge of A
    // just lowest while A still fits a slot barely wider than itself).
    for (const Mat3& tilt :
         {axis_angle(Vec3(0.3, 0.5, 0.8), 0.37), axis_angle(Vec3(0.7, -0.2, 0.4), 0.09)})
      for (int perm = 0; perm < 6; ++perm)
        for (int signs = 0; signs < 8; ++signs) {
          static const int P[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2},
                                      {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
          Mat3 M = Mat3::Zero();
          for (int r = 0; r < 3; ++r) M(r, P[perm][r]) = (signs >> r & 1) ? -1.0 : 1.0;
          if (M.determinant() > 0) out.push_back(tilt * M);
        }
    return out;
  }();
  all_seeds.insert(all_seeds.end(), kSpread.begin(), kSpread.end());
  return all_seeds;
}

namespace {

bool point_pc(PcType t) { return t == PcType::kVF || t == PcType::kFV || t == PcType::kEE; }

// Sample points of an element's interior: a vertex itself; an edge at its eighths and 1% from
// each end; a face at its centroid and toward the corners and sides of its outer loop (kept
// when inside). Points near the ends matter: a CF whose contact sits within a few tenths of a
// millimetre of a corner (a box's edge crossing a nosing just past the box's corner) holds
// only at rotations close to the ones they anchor.
std::vector<Vec3> interior_samples(const Polyhedron& m, ElementKind k, int i) {
  std::vector<Vec3> out;
  if (k == ElementKind::kVertex) {
    out.push_back(m.vertices()[i].p);
  } else if (k == ElementKind::kEdge) {
    const Vec3 &a = m.edge_point(EdgeId(i), 0), &b = m.edge_point(EdgeId(i), 1);
    for (double f : {0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875, 0.01, 0.99})
      out.push_back(a + f * (b - a));
  } else {
    // Toward each corner and each side's midpoint, 50%, 90% and 98% of the way: contacts
    // near a face's boundary matter (a peg's corner just inside a hole's rim).
    const Face& F = m.faces()[i];
    std::vector<Vec3> targets;
    for (std::size_t j = 0; j < F.loops.front().size(); ++j) {
      const Vec3& a = m.vertices()[F.loops.front()[j].index()].p;
      const Vec3& b = m.vertices()[F.loops.front()[(j + 1) % F.loops.front().size()].index()].p;
      targets.push_back(a);
      targets.push_back(0.5 * (a + b));
    }
    if (m.face_inset(FaceId(i), F.centroid) > 0) out.push_back(F.centroid);
    for (double f : {0.5, 0.9, 0.98})
      for (const Vec3& c : targets) {
        const Vec3 q = F.centroid + f * (c - F.centroid);
        if (m.face_inset(FaceId(i), q) > 0) out.push_back(q);
      }
  }
  return out;
}

// Angles (rad, ascending, in (-pi, pi]) at which the circle of radius r about c (the face's
// (u, v) frame) crosses the boundary of face F.
std::vector<double> circle_crossings(const Face& F, const Eigen::Vector2d& c, double r) {
  std::vector<double> out;
  for (const std::vector<Eigen::Vector2d>& loop : F.loops_2d)
    for (std::size_t j = 0; j < loop.size(); ++j) {
      const Eigen::Vector2d a = loop[j] - c, d = loop[(j + 1) % loop.size()] - loop[j];
      // |a + s d|^2 = r^2: quadratic in s.
      const double qa = d.squaredNorm(), qb = 2 * d.dot(a), qc = a.squaredNorm() - r * r;
      const double disc = qb * qb - 4 * qa * qc;
      if (qa <= 0 || disc < 0) continue;
      for (double sg : {-1.0, 1.0}) {
        const double s = (-qb + sg * std::sqrt(disc)) / (2 * qa);
        if (s < 0 || s > 1) continue;
        const Eigen::Vector2d x = a + s * d;
        out.push_back(std::atan2(x.y(), x.x()));
      }
    }
  std::sort(out.begin(), out.end());
  return out;
}

// Points x inside element i (an edge or a face) with |x - c| = L.
std::vector<Vec3> at_distance(const Polyhedron& m, ElementKind k, int i, const Vec3& c, double L) {
  std::vector<Vec3> out;
  if (k == ElementKind::kEdge) {
    const Vec3 a = m.edge_point(EdgeId(i), 0), d = m.edge_point(EdgeId(i), 1) - a;
    // |a + u d - c|^2 = L^2: quadratic in u.
    const double qa = d.squaredNorm(), qb = 2 * d.dot(a - c), qc = (a - c).squaredNorm() - L * L;
    const double disc = qb * qb - 4 * qa * qc;
    if (qa <= 0 || disc < 0) return out;
    for (double sg : {-1.0, 1.0}) {
      const double u = (-qb + sg * std::sqrt(disc)) / (2 * qa);
      if (u > 0.005 && u < 0.995) out.push_back(a + u * d);  // inside, as the samples' ends
    }
  } else if (k == ElementKind::kFace) {
    // The circle where the sphere meets the face's plane, cut into arcs where it crosses the
    // face's boundary: each arc inside the face gets points spread along it, at least one,
    // so that a narrow face (a riser, a rim) that the circle only grazes is still reached.
    const Face& F = m.faces()[i];
    const double h = F.normal.dot(c) - F.offset;
    const double r2 = L * L - h * h;
    if (r2 <= 0) return out;
    const double r = std::sqrt(r2);
    const Vec3 c0 = c - h * F.normal;
    constexpr double kSpacing = 2 * M_PI / 16;  // rad: the most between two points of an arc
    std::vector<double> cuts = circle_crossings(F, {F.u.dot(c0), F.v.dot(c0)}, r);
    if (cuts.empty()) cuts.push_back(0);
    for (std::size_t j = 0; j < cuts.size(); ++j) {
      const double lo = cuts[j], hi = j + 1 < cuts.size() ? cuts[j + 1] : cuts[0] + 2 * M_PI;
      const int n = std::max(1, static_cast<int>(std::ceil((hi - lo) / kSpacing)));
      for (int q = 0; q < n; ++q) {
        const double th = lo + (hi - lo) * (q + 0.5) / n;
        const Vec3 x = c0 + r * (std::cos(th) * F.u + std::sin(th) * F.v);
        if (m.face_inset(FaceId(i), x) > 0) out.push_back(x);
      }
    }
  }
  return out;
}

// The rotations rots[order[i].second] in that order, at most `limit`; with `spread`, each at
// least kMinSeparation from those taken, so that the budget covers different orientations
// rather than one well-liked family.
std::vector<Mat3> take_spread(const std::vector<Mat3>& rots,
                              const std::vector<std::pair<double, std::size_t>>& order, int limit,
                              bool spread) {
  constexpr double kMinSeparation = 0.15;  // rad between two rotations tried
  const double min_trace = 1 + 2 * std::cos(kMinSeparation);
  std::vector<Mat3> out;
  for (std::size_t i = 0; i < order.size() && static_cast<int>(out.size()) < limit; ++i) {
    const Mat3& R = rots[order[i].second];
    bool distinct = true;
    for (const Mat3& Q : out)
      if (spread && (Q.transpose() * R).trace() > min_trace) {
        distinct = false;
        break;
      }
    if (distinct) out.push_back(R);
  }
  return out;
}

// Signed distance between the elements of point PC z (their lines or planes) at pose (R, t);
// NaN for an e-e whose lines are parallel.
double third_residual(const Polyhedron& A, const Polyhedron& B, const Pc& z, const Mat3& R,
                      const Vec3& t, double scale) {
  switch (z.type) {
    case PcType::kVF: {
      const Face& F = B.faces()[z.b];
      return F.normal.dot(R * A.vertices()[z.a].p + t) - F.offset;
    }
    case PcType::kFV: {
      const Face& F = A.faces()[z.a];
      return (R * F.normal).dot(B.vertices()[z.b].p - t) - F.offset;
    }
    default: {  // e-e
      const Vec3 a0 = R * A.edge_point(EdgeId(z.a), 0) + t;
      const Vec3 da = R * (A.edge_point(EdgeId(z.a), 1) - A.edge_point(EdgeId(z.a), 0));
      const Vec3 b0 = B.edge_point(EdgeId(z.b), 0);
      const Vec3 n = da.cross(B.edge_point(EdgeId(z.b), 1) - b0);
      const double len = n.norm();
      if (len < 1e-12 * scale * scale) return std::numeric_limits<double>::quiet_NaN();
      return (a0 - b0).dot(n) / len;
    }
  }
}

// Roots phi in [0, 2 pi) of f: sign changes between 96 equal steps of the turn, refined by
// bisection; a sign change across a jump of f (an e-e's lines turning parallel), where |f|
// stays above `small`, is no root.
template <class F>
std::vector<double> turn_roots(const F& f, double small) {
  constexpr int kSpinSamples = 96;
  std::vector<double> out;
  double f0 = f(0);
  for (int k = 1; k <= kSpinSamples; ++k) {
    double lo = 2 * M_PI * (k - 1) / kSpinSamples, hi = 2 * M_PI * k / kSpinSamples;
    const double f1 = f(hi);
    if (std::isfinite(f0) && std::isfinite(f1) && (f0 < 0) != (f1 < 0)) {
      double flo = f0;
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi), fm = f(mid);
        if (!std::isfinite(fm)) break;
        if ((fm < 0) == (flo < 0))
          lo = mid, flo = fm;
        else
          hi = mid;
      }
      if (std::abs(f(0.5 * (lo + hi))) < small) out.push_back(0.5 * (lo + hi));
    }
    f0 = f1;
  }
  return out;
}

}  // namespace

std::vector<Mat3> WitnessSearch::anchored_rotations(const PcSet& pcs,
                                                    std::optional<Mat3>* near_miss) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  std::vector<Pc> pts;
  for (const Pc& pc : pcs)
    if (point_pc(pc.type)) pts.push_back(pc);
  // Only the locally admissible candidates are kept (most are not, and there are thousands),
  // each with its rank: most slack first, those where all three point contacts hold before all.
  std::vector<Mat3> cands;
  std::vector<std::pair<double, std::size_t>> order;
  if (pts.size() < 2) return cands;
  const double min_local = std::sin(p_.angle_margin);
  // The anchors place the point contacts only; the set's other PCs (an e-f beside an e-e and
  // a v-f) still ask their rotational conditions, so each rotation is projected onto them.
  // Unprojected, a rotation whose contacts the program places would count as near a witness
  // and keep the search from the stages meant for sets whose planes never meet.
  const RotConstraints conditions = rotation_constraints(pcs, A_, B_);
  const bool conditioned = !conditions.align.empty() || !conditions.perp.empty();
  auto keep = [&](const Mat3& R, bool exact) {
    const double m = local_margin(pcs, R);
    if (m <= min_local) return;
    order.push_back({exact ? -2.0 - m : -m, cands.size()});
    cands.push_back(R);
  };
  auto consider = [&](const Mat3& R0, bool exact) {
    if (!conditioned) return keep(R0, exact);
    for (const Mat3& R : project_onto(conditions, R0)) keep(R, exact);
  };
  // The anchored rotation with the largest local margin short of min_local: the contacts
  // placed, some PC locally penetrating by a little.
  std::pair<double, Mat3> miss{-std::numeric_limits<double>::infinity(), Mat3::Identity()};
  const Pc& x = pts[0];
  const Pc& y = pts[1];
  const Pc* third = pts.size() >= 3 ? &pts[2] : nullptr;
  // Solve for the free point on the side where y's element is not a vertex.
  const bool solve_on_b = b_kind(y.type) != ElementKind::kVertex;
  const std::vector<Vec3> fixed = solve_on_b ? interior_samples(A, a_kind(y.type), y.a)
                                             : interior_samples(B, b_kind(y.type), y.b);
  const std::vector<Vec3> on_b = interior_samples(B, b_kind(x.type), x.b);
  for (const Vec3& pa : interior_samples(A, a_kind(x.type), x.a))
    for (const Vec3& qb : on_b) {
      for (const Vec3& f : fixed) {
        const double L = (f - (solve_on_b ? pa : qb)).norm();
        if (L < 1e-9 * scale_) continue;
        for (const Vec3& g : solve_on_b ? at_distance(B, b_kind(y.type), y.b, qb, L)
                                        : at_distance(A, a_kind(y.type), y.a, pa, L)) {
          const Vec3 dA = ((solve_on_b ? f : g) - pa).normalized();
          const Vec3 dB = ((solve_on_b ? g : f) - qb).normalized();
          const Mat3 R0 = align(dA, dB);
          auto spun = [&](double phi) { return Mat3(axis_angle(dB, phi) * R0); };
          std::pair<double, double> best;
          for (double phi :
               admissible_spins(A_, B_, pcs, dA, R0, p_.theta_samples, min_local, &best))
            consider(spun(phi), false);
          if (best.second <= min_local && best.second > miss.first)
            miss = {best.second, spun(best.first)};
          if (!third) continue;
          // A third point PC: also the spins where its contact holds, the first contact held
          // at (pa, qb); tried first.
          auto residual = [&](double phi) {
            const Mat3 R = spun(phi);
            return third_residual(A, B, *third, R, qb - R * pa, scale_);
          };
          for (double phi : turn_roots(residual, 1e-6 * scale_)) consider(spun(phi), true);
        }
      }
    }
  // Spread apart, at most max_rotations.
  std::stable_sort(order.begin(), order.end());
  if (debug_)
    std::cerr << "  anchored: " << order.size() << " locally admissible rotations, nearest miss "
              << miss.first << "\n";
  if (near_miss && order.empty() && std::isfinite(miss.first)) *near_miss = miss.second;
  return take_spread(cands, order, p_.max_rotations, true);
}

std::vector<Mat3> WitnessSearch::rotation_candidates(const PcSet& pcs,
                                                     const std::vector<Mat3>& seeds,
                                                     bool generic_seeds) const {
  const std::vector<Mat3> rots =
      family_samples(pcs, generic_seeds ? spread_rotations(pcs, seeds) : seeds,
                     generic_seeds ? p_.theta_samples : 0);
  // Drop rotations that are locally penetrating; try the sub-sets' witnesses first, then the
  // rest by decreasing local slack, skipping near-duplicates so that the budget of
  // max_rotations covers different orientations rather than one well-liked family.
  const std::size_t n_subset = std::min(seeds.size(), rots.size());
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < rots.size(); ++i) {
    const double m = local_margin(pcs, rots[i]);
    if (m > std::sin(p_.angle_margin))
      order.push_back({i < n_subset && generic_seeds ? -2.0 : -m, i});
  }
  std::stable_sort(order.begin(), order.end());
  return take_spread(rots, order, p_.max_rotations, generic_seeds);
}

std::vector<Mat3> WitnessSearch::rotation_steps(const PcSet& pcs, const Mat3& R, double h) const {
  const RotConstraints c = rotation_constraints(pcs, A_, B_);
  std::vector<Mat3> out;
  if (c.align.size() >= 2) return out;  // the rotation is fixed
  if (c.align.size() == 1) {
    // The spin about the aligned normal is free; perp conditions, if any, fix it.
    if (!c.perp.empty()) return out;
    for (double sg : {1.0, -1.0}) out.push_back(axis_angle(c.align[0].second, sg * h) * R);
    return out;
  }
  for (int ax = 0; ax < 3; ++ax)
    for (double sg : {1.0, -1.0}) {
      Mat3 Q = axis_angle(sg * Vec3::Unit(ax), h) * R;
      if (c.perp.empty() || project_perp(c, Q)) out.push_back(Q);
    }
  return out;
}

}  // namespace cf::gen
