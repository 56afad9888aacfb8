#include "witness.hpp"

#include "touch.hpp"

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
#include <memory>
#include <stdexcept>

namespace cf::gen {
namespace {

using Rel = LinearProgram::Rel;

struct RotConstraints {
  std::vector<std::pair<Vec3, Vec3>> align;  // R a == b
  std::vector<std::pair<Vec3, Vec3>> perp;   // (R u) . w == 0
};

constexpr double kRotTol = 1e-9;  // residual accepted for rotational contact conditions

bool satisfies(const RotConstraints& c, const Mat3& R) {
  for (const auto& [a, b] : c.align)
    if ((R * a - b).norm() > 10 * kRotTol) return false;
  for (const auto& [u, w] : c.perp)
    if (std::abs((R * u).dot(w)) > 10 * kRotTol) return false;
  return true;
}

// Solutions theta of a cos(theta) + b sin(theta) == d; `all` when it holds for every theta.
bool trig_solve(double a, double b, double d, std::vector<double>& out, bool& all) {
  const double r = std::hypot(a, b);
  all = false;
  if (r < 1e-12) {
    all = std::abs(d) < kRotTol;
    return all;
  }
  double c = d / r;
  if (std::abs(c) > 1 + 1e-9) return false;
  c = std::clamp(c, -1.0, 1.0);
  const double phi = std::atan2(b, a);
  const double delta = std::acos(c);
  out.push_back(phi + delta);
  if (delta > 1e-9 && delta < M_PI - 1e-9) out.push_back(phi - delta);
  return true;
}

// Each rotation turned by each angle (rad) about each coordinate axis, both ways: the
// rotations a little around given ones, in a fixed order.
std::vector<Mat3> turned_about_axes(const std::vector<Mat3>& rots,
                                    std::initializer_list<double> angles) {
  std::vector<Mat3> out;
  for (const Mat3& R : rots)
    for (double ang : angles)
      for (int ax = 0; ax < 3; ++ax)
        for (double sg : {1.0, -1.0}) out.push_back(axis_angle(sg * Vec3::Unit(ax), ang) * R);
  return out;
}

void add_unique(std::vector<Mat3>& out, const Mat3& R) {
  for (const Mat3& Q : out)
    if ((Q - R).squaredNorm() < 1e-14) return;
  out.push_back(R);
}

// theta maximising trace(S^T Rot(axis, theta) R0): the family member closest to S.
double closest_theta(const Vec3& axis, const Mat3& R0, const Mat3& S) {
  const Mat3 Q = R0 * S.transpose();
  Mat3 K;
  K << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  const double c = Q.trace() - axis.dot(Q * axis);
  const double s = (Q * K).trace();
  return std::atan2(s, c);
}

// Rotations R = Rot(axis, theta) * R0 satisfying all constraints; finitely many or samples.
std::vector<Mat3> align_family(const RotConstraints& c, const std::vector<Mat3>& seeds,
                               int samples, bool* finite_out = nullptr) {
  if (c.align.size() >= 2) {
    // Two alignments fix the rotation. Solving the second as a condition on the spin about
    // the first meets it at a double root (its dot product is at its maximum, 1), where a
    // rounding error e in the models' angles moves the answer by sqrt(e): 3e-8 rad for
    // e = 1e-15, above kRotTol. The least-squares rotation (Kabsch) errs by e itself.
    if (finite_out) *finite_out = true;
    Mat3 H = Mat3::Zero();
    for (const auto& [a, b] : c.align) H += b * a.transpose();
    Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Mat3 D = Mat3::Identity();
    D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
    const Mat3 R = svd.matrixU() * D * svd.matrixV().transpose();
    if (satisfies(c, R)) return {R};
    return {};
  }
  const Vec3 a1 = c.align[0].first, axis = c.align[0].second;
  const Mat3 R0 = align(a1, axis);
  std::vector<double> thetas;
  bool finite = false;
  auto consider = [&](const Vec3& u0, const Vec3& w, double target) {
    const Vec3 u = R0 * u0;
    const Vec3 u_par = u.dot(axis) * axis;
    const double A = (u - u_par).dot(w);
    const double B = axis.cross(u).dot(w);
    const double C = u_par.dot(w);
    std::vector<double> sol;
    bool all = false;
    if (!trig_solve(A, B, target - C, sol, all)) return false;
    if (all) return true;
    if (!finite) {
      thetas = sol;
      finite = true;
    }
    return true;
  };
  for (std::size_t i = 1; i < c.align.size(); ++i)
    if (!consider(c.align[i].first, c.align[i].second, 1.0)) return {};
  for (const auto& [u, w] : c.perp)
    if (!consider(u, w, 0.0)) return {};
  if (finite_out) *finite_out = finite;
  if (!finite) {
    for (const Mat3& S : seeds) thetas.push_back(closest_theta(axis, R0, S));
    for (int k = 0; k < samples; ++k) thetas.push_back(0.1 + 2 * M_PI * k / samples);
  }
  std::vector<Mat3> out;
  for (double th : thetas) {
    const Mat3 R = axis_angle(axis, th) * R0;
    if (satisfies(c, R)) add_unique(out, R);
  }
  return out;
}

// Gauss-Newton projection of R onto { (R u_i) . w_i == 0 }.
bool project_perp(const RotConstraints& c, Mat3& R) {
  const int k = static_cast<int>(c.perp.size());
  // At most three conditions: fixed-capacity matrices keep this hot loop off the heap.
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 3, 1>;
  using Jac = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, 3, 3>;
  for (int it = 0; it < 40; ++it) {
    Vec r(k);
    Jac J(k, 3);
    for (int i = 0; i < k; ++i) {
      const Vec3 Ru = R * c.perp[i].first;
      r[i] = Ru.dot(c.perp[i].second);
      J.row(i) = Ru.cross(c.perp[i].second).transpose();
    }
    if (r.cwiseAbs().maxCoeff() < 1e-14) return true;
    const Eigen::Vector3d d = -J.completeOrthogonalDecomposition().solve(r);
    if (!d.allFinite() || d.norm() < 1e-16) break;
    const double ang = std::min(d.norm(), 0.5);
    R = axis_angle(d.normalized(), ang) * R;
  }
  return satisfies(c, R);
}

// Walks a one-parameter family of rotations (one alignment with its spin free, or two
// perpendicularity conditions) away from R by steps of about h rad, at most n steps along
// each branch: the rotations along each branch, R excluded. Where the two conditions'
// gradients coincide (an axis-aligned pose, where branches of the family cross), each branch
// is entered by a small turn about a coordinate axis projected back onto the conditions.
// Empty for other families.
std::vector<std::vector<Mat3>> walk_family(const RotConstraints& c, const Mat3& R, double h, int n) {
  std::vector<std::vector<Mat3>> paths;
  const bool spin = c.align.size() == 1 && c.perp.empty();
  if (!spin && !(c.align.empty() && c.perp.size() == 2)) return paths;
  // The axis keeping the conditions to first order (zero where it is not unique).
  auto tangent = [&](const Mat3& Q) -> Vec3 {
    if (spin) return c.align[0].second;
    const Vec3 w = (Q * c.perp[0].first).cross(c.perp[0].second).cross((Q * c.perp[1].first).cross(c.perp[1].second));
    return w.norm() < 1e-6 ? Vec3::Zero() : Vec3(w.normalized());
  };
  auto step = [&](const Mat3& Q, const Vec3& axis, Mat3& out) {
    out = axis_angle(axis, h) * Q;
    return spin || project_perp(c, out);
  };
  std::vector<Mat3> starts;
  const Vec3 w0 = tangent(R);
  std::vector<Vec3> kicks;
  if (w0.norm() > 0) kicks = {w0, -w0};
  else
    for (int ax = 0; ax < 3; ++ax) kicks.push_back(Vec3::Unit(ax)), kicks.push_back(-Vec3::Unit(ax));
  const double min_trace = 1 + 2 * std::cos(0.5 * h);  // a start at least h/2 from R and the others
  for (const Vec3& k : kicks) {
    Mat3 Q;
    if (!step(R, k, Q) || (R.transpose() * Q).trace() > min_trace) continue;
    bool distinct = true;
    for (const Mat3& S : starts) distinct = distinct && (S.transpose() * Q).trace() <= min_trace;
    if (distinct) starts.push_back(Q);
  }
  for (const Mat3& first : starts) {
    std::vector<Mat3> path{first};
    Mat3 prev = R;
    for (int k = 1; k < n; ++k) {
      // Keep turning the way the last step turned, then back onto the conditions: this
      // follows a branch through points where gradients coincide.
      const Mat3 cur = path.back();
      const Eigen::AngleAxisd moved(Mat3(cur * prev.transpose()));  // angle in [0, pi]
      Mat3 next;
      if (!step(cur, moved.axis(), next)) break;
      prev = cur;
      path.push_back(next);
    }
    paths.push_back(std::move(path));
  }
  return paths;
}

}  // namespace

WitnessSearch::WitnessSearch(const ModelInfo& a, const ModelInfo& b, const SearchParams& p)
    : A_(a), B_(b), p_(p), scale_(std::max(a.model->size(), b.model->size())),
      debug_(std::getenv("CFGEN_DEBUG") != nullptr) {}

namespace {

RotConstraints rotation_constraints(const PcSet& pcs, const Polyhedron& A, const Polyhedron& B) {
  RotConstraints c;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kFF:
        c.align.push_back({A.faces()[pc.a].normal, -B.faces()[pc.b].normal});
        break;
      case PcType::kEF:
        c.perp.push_back({A.edges()[pc.a].dir, B.faces()[pc.b].normal});
        break;
      case PcType::kFE:
        c.perp.push_back({A.faces()[pc.a].normal, B.edges()[pc.b].dir});
        break;
      default:
        break;
    }
  }
  return c;
}

}  // namespace

std::vector<Mat3> WitnessSearch::family_samples(const PcSet& pcs, const std::vector<Mat3>& seeds,
                                               int samples) const {
  const RotConstraints c = rotation_constraints(pcs, *A_.model, *B_.model);
  std::vector<Mat3> rots;
  if (!c.align.empty()) {
    rots = align_family(c, seeds, samples);
  } else if (!c.perp.empty()) {
    for (Mat3 R : seeds)
      if (project_perp(c, R)) add_unique(rots, R);
  } else {
    for (const Mat3& R : seeds) add_unique(rots, R);
  }
  return rots;
}

std::vector<Mat3> WitnessSearch::spread_rotations(const PcSet& pcs, const std::vector<Mat3>& seeds) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  // Each PC's preferred one-parameter family: its local conditions hold with most slack.
  std::vector<Mat3> prefs;
  const int n = std::max(4, p_.theta_samples / std::max(1, pcs.size()));
  for (const Pc& pc : pcs) {
    Vec3 x, y;  // align A-frame x to world y, then spin about y
    switch (pc.type) {
      case PcType::kFF: x = A.faces()[pc.a].normal; y = -B.faces()[pc.b].normal; break;
      case PcType::kVF: x = A_.cones[pc.a].center; y = B.faces()[pc.b].normal; break;
      case PcType::kFV: x = A.faces()[pc.a].normal; y = B_.cones[pc.b].center; break;
      case PcType::kEF: x = A_.wedges[pc.a].bisector; y = -B.faces()[pc.b].normal; break;
      case PcType::kFE: x = A.faces()[pc.a].normal; y = -B_.wedges[pc.b].bisector; break;
      case PcType::kEE: x = A_.wedges[pc.a].bisector; y = -B_.wedges[pc.b].bisector; break;
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
    for (const Mat3& tilt : {axis_angle(Vec3(0.3, 0.5, 0.8), 0.37), axis_angle(Vec3(0.7, -0.2, 0.4), 0.09)})
      for (int perm = 0; perm < 6; ++perm)
        for (int signs = 0; signs < 8; ++signs) {
          static const int P[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
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

// Sample points of an element's interior: a vertex itself; an edge at its eighths; a face at its
// centroid and toward the corners and sides of its outer loop (kept when inside).
std::vector<Vec3> interior_samples(const Polyhedron& m, ElementKind k, int i) {
  std::vector<Vec3> out;
  if (k == ElementKind::kVertex) {
    out.push_back(m.vertices()[i].p);
  } else if (k == ElementKind::kEdge) {
    const Vec3 &a = m.edge_point(EdgeId(i), 0), &b = m.edge_point(EdgeId(i), 1);
    for (double f : {0.5, 0.25, 0.75, 0.125, 0.375, 0.625, 0.875}) out.push_back(a + f * (b - a));
  } else {
    // Toward each corner and each side's midpoint, halfway and nine tenths of the way:
    // contacts near a face's boundary matter (a peg's corner just inside a hole's rim).
    const Face& F = m.faces()[i];
    std::vector<Vec3> targets;
    for (std::size_t j = 0; j < F.loops.front().size(); ++j) {
      const Vec3& a = m.vertices()[F.loops.front()[j].index()].p;
      const Vec3& b = m.vertices()[F.loops.front()[(j + 1) % F.loops.front().size()].index()].p;
      targets.push_back(a);
      targets.push_back(0.5 * (a + b));
    }
    if (m.face_inset(FaceId(i), F.centroid) > 0) out.push_back(F.centroid);
    for (double f : {0.5, 0.9})
      for (const Vec3& c : targets) {
        const Vec3 q = F.centroid + f * (c - F.centroid);
        if (m.face_inset(FaceId(i), q) > 0) out.push_back(q);
      }
  }
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
      if (u > 0.02 && u < 0.98) out.push_back(a + u * d);
    }
  } else if (k == ElementKind::kFace) {
    const Face& F = m.faces()[i];
    const double h = F.normal.dot(c) - F.offset;
    const double r2 = L * L - h * h;
    if (r2 <= 0) return out;
    const Vec3 c0 = c - h * F.normal;
    constexpr int kAngles = 8;  // points on the circle where the sphere meets the face plane
    for (int j = 0; j < kAngles; ++j) {
      const double th = 2 * M_PI * (j + 0.5) / kAngles;
      const Vec3 x = c0 + std::sqrt(r2) * (std::cos(th) * F.u + std::sin(th) * F.v);
      if (m.face_inset(FaceId(i), x) > 0) out.push_back(x);
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

}  // namespace

std::vector<Mat3> WitnessSearch::anchored_rotations(const PcSet& pcs) const {
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
  auto consider = [&](const Mat3& R, bool exact) {
    const double m = local_margin(pcs, R);
    if (m <= min_local) return;
    order.push_back({exact ? -2.0 - m : -m, cands.size()});
    cands.push_back(R);
  };
  const Pc& x = pts[0];
  const Pc& y = pts[1];
  const Pc* third = pts.size() >= 3 ? &pts[2] : nullptr;
  // Signed distance between the third PC's elements (their lines or planes) at pose (R, t).
  auto third_residual = [&](const Pc& z, const Mat3& R, const Vec3& t) {
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
        if (len < 1e-12 * scale_ * scale_) return std::numeric_limits<double>::quiet_NaN();
        return (a0 - b0).dot(n) / len;
      }
    }
  };
  // Solve for the free point on the side where y's element is not a vertex.
  const bool solve_on_b = b_kind(y.type) != ElementKind::kVertex;
  for (const Vec3& pa : interior_samples(A, a_kind(x.type), x.a))
    for (const Vec3& qb : interior_samples(B, b_kind(x.type), x.b)) {
      const std::vector<Vec3> fixed = solve_on_b ? interior_samples(A, a_kind(y.type), y.a)
                                                 : interior_samples(B, b_kind(y.type), y.b);
      for (const Vec3& f : fixed) {
        const double L = (f - (solve_on_b ? pa : qb)).norm();
        if (L < 1e-9 * scale_) continue;
        for (const Vec3& g : solve_on_b ? at_distance(B, b_kind(y.type), y.b, qb, L)
                                        : at_distance(A, a_kind(y.type), y.a, pa, L)) {
          const Vec3 dA = ((solve_on_b ? f : g) - pa).normalized();
          const Vec3 dB = ((solve_on_b ? g : f) - qb).normalized();
          const Mat3 R0 = align(dA, dB);
          auto spun = [&](double phi) { return Mat3(axis_angle(dB, phi) * R0); };
          for (int k = 0; k < p_.theta_samples; ++k) consider(spun(2 * M_PI * k / p_.theta_samples), false);
          if (!third) continue;
          // A third point PC: also the spins where its contact holds, the first contact held
          // at (pa, qb); tried first.
          auto residual = [&](double phi) {
            const Mat3 R = spun(phi);
            return third_residual(*third, R, qb - R * pa);
          };
          constexpr int kSpinSamples = 96;
          double f0 = residual(0);
          for (int k = 1; k <= kSpinSamples; ++k) {
            double lo = 2 * M_PI * (k - 1) / kSpinSamples, hi = 2 * M_PI * k / kSpinSamples;
            const double f1 = residual(hi);
            if (std::isfinite(f0) && std::isfinite(f1) && (f0 < 0) != (f1 < 0)) {
              double flo = f0;
              for (int it = 0; it < 40; ++it) {
                const double mid = 0.5 * (lo + hi), fm = residual(mid);
                if (!std::isfinite(fm)) break;
                if ((fm < 0) == (flo < 0)) lo = mid, flo = fm;
                else hi = mid;
              }
              // A sign change across the e-e residual's jump (lines turning parallel) is no root.
              if (std::abs(residual(0.5 * (lo + hi))) < 1e-6 * scale_) consider(spun(0.5 * (lo + hi)), true);
            }
            f0 = f1;
          }
        }
      }
    }
  // Spread apart, at most max_rotations.
  std::stable_sort(order.begin(), order.end());
  if (debug_) std::cerr << "  anchored: " << order.size() << " locally admissible rotations\n";
  return take_spread(cands, order, p_.max_rotations, true);
}

std::vector<Mat3> WitnessSearch::rotation_candidates(const PcSet& pcs,
                                                     const std::vector<Mat3>& seeds,
                                                     bool generic_seeds) const {
  const std::vector<Mat3> rots = family_samples(pcs, generic_seeds ? spread_rotations(pcs, seeds) : seeds,
                                                generic_seeds ? p_.theta_samples : 0);
  // Drop rotations that are locally penetrating; try the sub-sets' witnesses first, then the
  // rest by decreasing local slack, skipping near-duplicates so that the budget of
  // max_rotations covers different orientations rather than one well-liked family.
  const std::size_t n_subset = std::min(seeds.size(), rots.size());
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < rots.size(); ++i) {
    const double m = local_margin(pcs, rots[i]);
    if (m > std::sin(p_.angle_margin)) order.push_back({i < n_subset && generic_seeds ? -2.0 : -m, i});
  }
  std::stable_sort(order.begin(), order.end());
  return take_spread(rots, order, p_.max_rotations, generic_seeds);
}

double WitnessSearch::verified_local_slack() const { return 0.5 * std::sin(p_.angle_margin); }

double WitnessSearch::local_margin(const PcSet& pcs, const Mat3& R) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  double m = 1.0;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kFF:
        m = std::min(m, 1.0 - (R * A.faces()[pc.a].normal + B.faces()[pc.b].normal).norm());
        break;
      case PcType::kVF: {
        const auto& cone = A_.cones[pc.a];
        if (!cone.pointed) return -1;
        const Vec3 nb = R.transpose() * B.faces()[pc.b].normal;
        for (const Vec3& r : cone.rays) m = std::min(m, r.dot(nb));
        break;
      }
      case PcType::kFV: {
        const auto& cone = B_.cones[pc.b];
        if (!cone.pointed) return -1;
        const Vec3 na = R * A.faces()[pc.a].normal;
        for (const Vec3& r : cone.rays) m = std::min(m, r.dot(na));
        break;
      }
      case PcType::kEF: {
        if (!A.edges()[pc.a].convex) return -1;
        const Vec3 nb = R.transpose() * B.faces()[pc.b].normal;
        m = std::min({m, A_.wedges[pc.a].into_left.dot(nb), A_.wedges[pc.a].into_right.dot(nb)});
        break;
      }
      case PcType::kFE: {
        if (!B.edges()[pc.b].convex) return -1;
        const Vec3 na = R * A.faces()[pc.a].normal;
        m = std::min({m, B_.wedges[pc.b].into_left.dot(na), B_.wedges[pc.b].into_right.dot(na)});
        break;
      }
      case PcType::kEE: {
        if (!A.edges()[pc.a].convex || !B.edges()[pc.b].convex) return -1;
        Vec3 N = (R * A.edges()[pc.a].dir).cross(B.edges()[pc.b].dir);
        const double sin_cross = N.norm();
        if (sin_cross < 1e-9) return -1;
        N /= sin_cross;
        auto side = [&](const Vec3& n) {
          return std::min({-B_.wedges[pc.b].into_left.dot(n), -B_.wedges[pc.b].into_right.dot(n),
                           (R * A_.wedges[pc.a].into_left).dot(n),
                           (R * A_.wedges[pc.a].into_right).dot(n)});
        };
        m = std::min({m, sin_cross, std::max(side(N), side(-N))});
        break;
      }
    }
  }
  return m;
}

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
    for (const auto& [j, cvec] : P.coef) row.push_back({j, g.x() * u.dot(cvec) + g.y() * v.dot(cvec)});
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
    nv += pc.type == PcType::kEF || pc.type == PcType::kFE ? 1
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

double WitnessSearch::signed_margin(const PcSet& pcs, const Mat3& R, const std::vector<int>& pieces) const {
  LinearProgram lp = build_lp(pcs, R, pieces);
  lp.lower[3] = {true, -scale_};
  const LpResult r = solve(lp);
  return r.status == LpResult::Status::kOptimal ? r.x[3] : -std::numeric_limits<double>::infinity();
}

std::vector<Mat3> WitnessSearch::rotation_steps(const PcSet& pcs, const Mat3& R, double h) const {
  const RotConstraints c = rotation_constraints(pcs, *A_.model, *B_.model);
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
  const RotConstraints c = rotation_constraints(pcs, *A_.model, *B_.model);
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

std::pair<Vec3, double> WitnessSearch::contact_plane(const Pc& pc, const Pose& pose) const {
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

namespace {

std::string kind_name(ElementKind k) {
  return k == ElementKind::kVertex ? "v" : k == ElementKind::kEdge ? "e" : "f";
}

Pc pc_of(const PcSet& pcs, ElementKind ka, int a, ElementKind kb, int b) {
  for (const Pc& pc : pcs)
    if (a_kind(pc.type) == ka && b_kind(pc.type) == kb && pc.a == a && pc.b == b) return pc;
  return {};
}

// Lower bounds on the distance between an element of A and an element of B at one pose,
// computed before the exact distance (which locates points in faces and clamps segments: the
// bulk of verify's and contacts_at's time). From a face's plane: when every vertex of the
// other element's closure lies on one side of it, the two are at least the nearest vertex's
// height apart. From an edge's line: a vertex or an edge is at least its distance from the
// line of the other side's edge apart (most edge pairs of two models, 95% of those near
// enough to be listed, are far from crossing). From where an edge crosses a face's plane
// outside the face (crossing_gap).
class DistanceBound {
 public:
  // a_buf, b_buf: where the posed vertices go (reused storage).
  DistanceBound(const Polyhedron& A, const Polyhedron& B, const Pose& pose, std::vector<Vec3>& a_buf,
             std::vector<Vec3>& b_buf)
      : A_(A), B_(B), a_in_b_(a_buf), b_in_a_(b_buf) {
    a_in_b_.clear();
    for (const Vertex& v : A.vertices()) a_in_b_.push_back(pose.apply(v.p));
    b_in_a_.clear();
    for (const Vertex& v : B.vertices()) b_in_a_.push_back(pose.inverse_apply(v.p));
    // The line bound is compared with distances computed from the same coordinates; its own
    // rounding (a few ulps of the coordinates) is kept off by this much.
    double extent = 1.0;
    for (const Vec3& p : a_in_b_) extent = std::max(extent, p.lpNorm<Eigen::Infinity>());
    for (const Vertex& v : B.vertices()) extent = std::max(extent, v.p.lpNorm<Eigen::Infinity>());
    line_slack_ = 1e-12 * extent;
  }
  /// The slack kept off bounds computed from the posed coordinates (mm).
  double slack() const { return line_slack_; }
  /// True when element a of A and element b of B are proven farther apart than `reach`.
  bool farther(ElementKind ka, int a, ElementKind kb, int b, double reach) const {
    using K = ElementKind;
    double lb = 0;
    if (kb == K::kFace) lb = std::max(lb, side(B_.faces()[b], A_, ka, a, a_in_b_));
    if (ka == K::kFace) lb = std::max(lb, side(A_.faces()[a], B_, kb, b, b_in_a_));
    if (kb == K::kEdge && ka != K::kFace) {
      const Edge& eb = B_.edges()[b];
      const Vec3& q = B_.vertices()[eb.v0.index()].p;
      const Vec3 *p0, *p1;
      if (ka == K::kVertex) {
        p0 = p1 = &a_in_b_[static_cast<std::size_t>(a)];
      } else {
        p0 = &a_in_b_[A_.edges()[a].v0.index()];
        p1 = &a_in_b_[A_.edges()[a].v1.index()];
      }
      lb = std::max(lb, line_gap(q, eb.dir, *p0, *p1) - line_slack_);
    } else if (ka == K::kEdge && kb == K::kVertex) {
      const Vec3& p0 = a_in_b_[A_.edges()[a].v0.index()];
      const Vec3& p1 = a_in_b_[A_.edges()[a].v1.index()];
      const Vec3 u = (p1 - p0).normalized();
      const Vec3& q = B_.vertices()[static_cast<std::size_t>(b)].p;
      lb = std::max(lb, line_gap(p0, u, q, q) - line_slack_);
    }
    if (lb > reach) return true;
    // The bounds above are 0 when an edge crosses the face's plane: then from where it
    // crosses it.
    if (lb > 0) return false;
    if (ka == K::kEdge && kb == K::kFace) {
      const Edge& e = A_.edges()[a];
      return crossing_gap(B_, b, a_in_b_[e.v0.index()], a_in_b_[e.v1.index()]) - line_slack_ >
             reach;
    }
    if (ka == K::kFace && kb == K::kEdge) {
      const Edge& e = B_.edges()[b];
      return crossing_gap(A_, a, b_in_a_[e.v0.index()], b_in_a_[e.v1.index()]) - line_slack_ >
             reach;
    }
    return false;
  }

 private:
  // Distance between the line through q along unit u and the segment [p0, p1]: the segment
  // seen along u (both ends projected onto the plane through q across u) against the point
  // the line becomes.
  static double line_gap(const Vec3& q, const Vec3& u, const Vec3& p0, const Vec3& p1) {
    Vec3 x0 = p0 - q;
    x0 -= x0.dot(u) * u;
    Vec3 x1 = p1 - q;
    x1 -= x1.dot(u) * u;
    return point_segment(Vec3::Zero(), x0, x1).distance;
  }

  // For a segment [p0, p1] crossing the plane of face f of m (same frame) outside the face:
  // a point of the segment at length l from the crossing point x lies l sin(a) above the
  // plane and at most l cos(a) from x along it (a: the angle between segment and plane), so
  // its squared distance from the face is at least (l sin a)^2 + (d - l cos a)^2 while
  // l cos a <= d, where d is x's distance from the face in its plane: at least d sin(a)
  // over all l. 0 when the segment does not cross the plane or crosses it in the face.
  // One point location where the exact distance takes three and a segment distance for
  // each of the face's edges; most edges near a face's plane cross it outside the face.
  static double crossing_gap(const Polyhedron& m, int f, const Vec3& p0, const Vec3& p1) {
    const Face& F = m.faces()[f];
    const double h0 = F.normal.dot(p0) - F.offset, h1 = F.normal.dot(p1) - F.offset;
    if (!((h0 < 0 && h1 > 0) || (h0 > 0 && h1 < 0))) return 0;
    const Vec3 x = p0 + (h0 / (h0 - h1)) * (p1 - p0);
    const FaceLocation loc = locate_in_face(m, FaceId(f), Eigen::Vector2d(F.u.dot(x), F.v.dot(x)));
    if (loc.inside) return 0;
    return loc.boundary_distance * std::abs(h1 - h0) / (p1 - p0).norm();
  }

  // Smallest height of element (k, i) of m (vertices given in f's frame) over f's plane when
  // all of them are on one side, else 0.
  static double side(const Face& f, const Polyhedron& m, ElementKind k, int i, const std::vector<Vec3>& pts) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    auto add = [&](VertexId v) {
      const double h = f.normal.dot(pts[v.index()]) - f.offset;
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    };
    if (k == ElementKind::kVertex) add(VertexId(i));
    else if (k == ElementKind::kEdge) add(m.edges()[i].v0), add(m.edges()[i].v1);
    else for (VertexId v : m.faces()[i].vertices) add(v);
    return lo > 0 ? lo : hi < 0 ? -hi : 0.0;
  }
  const Polyhedron& A_;
  const Polyhedron& B_;
  std::vector<Vec3>& a_in_b_;
  std::vector<Vec3>& b_in_a_;
  double line_slack_ = 0;  // mm
};

// The elements of A and of B that can come within `reach` of the other solid at `pose` (each
// element's bounding sphere against the other model's), ascending by kind: the pairs worth
// measuring, found in time linear in the models' size. Every pair left out is farther apart
// than `reach`.
struct NearElements {
  std::array<std::vector<int>, 3> a;
  std::vector<std::uint64_t> b_bits;  // B's, as one bitset in B.boxes' numbering
  std::array<std::vector<Vec3>, 3> a_centers;  // A's element sphere centres in B's frame
};

void near_elements(const ModelInfo& A, const ModelInfo& B, const Pose& pose, double reach, NearElements& out) {
  for (auto& a : out.a) a.clear();
  const Vec3 b_in_a = pose.inverse_apply(B.bound.first);
  const Vec3 a_in_b = pose.apply(A.bound.first);
  out.b_bits.assign(static_cast<std::size_t>(B.boxes.words()), 0);
  for (int k = 0; k < 3; ++k) {
    out.a_centers[static_cast<std::size_t>(k)].resize(A.spheres[k].size());
    for (std::size_t i = 0; i < A.spheres[k].size(); ++i)
      if ((A.spheres[k][i].first - b_in_a).norm() - A.spheres[k][i].second - B.bound.second <= reach) {
        out.a[static_cast<std::size_t>(k)].push_back(static_cast<int>(i));
        out.a_centers[static_cast<std::size_t>(k)][i] = pose.apply(A.spheres[k][i].first);
      }
    for (std::size_t i = 0; i < B.spheres[k].size(); ++i)
      if ((B.spheres[k][i].first - a_in_b).norm() - B.spheres[k][i].second - A.bound.second <= reach) {
        const std::size_t bit = static_cast<std::size_t>(B.box_offset[k]) + i;
        out.b_bits[bit / 64] |= std::uint64_t{1} << (bit % 64);
      }
  }
}

// The buffers of one pair listing, kept per thread and reused: verify and contacts_at list
// the pairs of a pose hundreds of thousands of times a run, each listing a dozen vectors.
// Leased by depth, so that a listing inside another would get its own.
struct NearScratch {
  NearElements near;
  std::vector<Vec3> a_in_b, b_in_a;
  // NearPairs: per element of A (A.boxes' numbering), the elements of B whose boxes meet its
  // box, a bitset of B.boxes.words() words, valid when its stamp is the listing's.
  std::vector<std::uint64_t> a_rows;
  std::vector<std::uint64_t> a_row_stamp;
  std::uint64_t stamp = 0;
};
class ScratchLease {
 public:
  ScratchLease() {
    Pool& p = pool();
    if (p.depth == p.items.size()) p.items.push_back(std::make_unique<NearScratch>());
    s_ = p.items[p.depth++].get();
  }
  ~ScratchLease() { --pool().depth; }
  ScratchLease(const ScratchLease&) = delete;
  ScratchLease& operator=(const ScratchLease&) = delete;
  NearScratch& get() const { return *s_; }

 private:
  struct Pool {
    std::vector<std::unique_ptr<NearScratch>> items;
    std::size_t depth = 0;
  };
  static Pool& pool() {
    thread_local Pool p;
    return p;
  }
  NearScratch* s_;
};

// The element pairs (A's kind, B's kind, A's element, B's element, in that nesting order)
// not proven farther apart than `reach` at `pose`: near the other model, then by boxes (the
// index of B's boxes), then by bounding spheres, then by a face's plane or an edge's line.
// verify and contacts_at measure only these. Produced one at a time, so that a caller that
// stops at the first obstacle (verify, on most failed poses) does not pay for the rest.
struct ElementPair {
  ElementKind ka, kb;
  int a, b;
};

class NearPairs {
 public:
  NearPairs(const ModelInfo& A, const ModelInfo& B, const Pose& pose, double reach)
      : A_(A),
        B_(B),
        reach_(reach),
        near_(lease_.get().near),
        bounds_(*A.model, *B.model, pose, lease_.get().a_in_b, lease_.get().b_in_a) {
    near_elements(A, B, pose, reach, near_);
    NearScratch& sc = lease_.get();
    ++sc.stamp;
    const auto na = static_cast<std::size_t>(A.boxes.size());
    if (sc.a_row_stamp.size() != na) sc.a_row_stamp.assign(na, 0);
    sc.a_rows.resize(na * static_cast<std::size_t>(B.boxes.words()));
  }

  /// The next pair, false when there is none.
  bool next(ElementPair& out) {
    for (; kind_ < 9; ++kind_, i_ = 0) {
      const auto ia = static_cast<std::size_t>(kind_ / 3), ib = static_cast<std::size_t>(kind_ % 3);
      const std::vector<int>& as = near_.a[ia];
      for (; i_ < as.size(); ++i_) {
        const int a = as[i_];
        const auto& sa = A_.spheres[ia][static_cast<std::size_t>(a)];
        const Vec3& ca = near_.a_centers[ia][static_cast<std::size_t>(a)];
        if (!row_built_) start_row(ia, a, ib);
        // The row's elements in ascending order, lowest bit of each word first.
        for (; word_ <= last_word_; ++word_, bits_ = word_ <= last_word_ ? row_word(word_) : 0)
          while (bits_ != 0) {
            const int b = static_cast<int>(word_ * 64) + __builtin_ctzll(bits_) - B_.box_offset[ib];
            bits_ &= bits_ - 1;
            const auto& sb = B_.spheres[ib][static_cast<std::size_t>(b)];
            if ((ca - sb.first).norm() - sa.second - sb.second > reach_) continue;
            const auto ka = static_cast<ElementKind>(ia), kb = static_cast<ElementKind>(ib);
            if (bounds_.farther(ka, a, kb, b, reach_)) continue;
            out = {ka, kb, a, b};
            return true;
          }
        row_built_ = false;
      }
    }
    return false;
  }

 private:
  ScratchLease lease_;  // first: the members below live in it
  const ModelInfo& A_;
  const ModelInfo& B_;
  double reach_;
  // Starts the row of element a of kind ia against B's elements of kind ib: those near the
  // other solid whose boxes meet a's box grown by the reach (a box apart by more along an
  // axis is farther than the reach). The box query runs once per element of A and listing.
  void start_row(std::size_t ia, int a, std::size_t ib) {
    NearScratch& sc = lease_.get();
    const auto words = static_cast<std::size_t>(B_.boxes.words());
    const auto ga = static_cast<std::size_t>(A_.box_offset[ia] + a);
    row_ = sc.a_rows.data() + ga * words;
    if (sc.a_row_stamp[ga] != sc.stamp) {
      sc.a_row_stamp[ga] = sc.stamp;
      // a's box from its vertices in B's frame (the bound's own coordinates, so that the box
      // test and the distances agree within the bound's slack).
      const std::vector<Vec3>& p = sc.a_in_b;
      const Polyhedron& m = *A_.model;
      Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      auto add = [&](VertexId v) {
        lo = lo.cwiseMin(p[v.index()]);
        hi = hi.cwiseMax(p[v.index()]);
      };
      if (ia == 0) add(VertexId(a));
      else if (ia == 1) add(m.edges()[a].v0), add(m.edges()[a].v1);
      else for (VertexId v : m.faces()[a].vertices) add(v);
      const Vec3 g = Vec3::Constant(reach_ + bounds_.slack());
      B_.boxes.query(lo - g, hi + g, row_);
      for (std::size_t i = 0; i < words; ++i) row_[i] &= near_.b_bits[i];
    }
    // B's elements of kind ib are the bits [first_, end_).
    first_ = static_cast<std::size_t>(B_.box_offset[ib]);
    end_ = first_ + B_.spheres[ib].size();
    word_ = first_ / 64;
    last_word_ = end_ == first_ ? 0 : (end_ - 1) / 64;
    bits_ = end_ == first_ ? 0 : row_word(word_);
    if (end_ == first_) word_ = 1;  // an empty range: past last_word_
    row_built_ = true;
  }
  // Word w of the row, bits outside [first_, end_) cleared.
  std::uint64_t row_word(std::size_t w) const {
    std::uint64_t x = row_[w];
    if (w == first_ / 64) x &= ~std::uint64_t{0} << (first_ % 64);
    if (w == (end_ - 1) / 64 && end_ % 64 != 0) x &= ~(~std::uint64_t{0} << (end_ % 64));
    return x;
  }

  NearElements& near_;
  std::uint64_t* row_ = nullptr;  // the current row (in the scratch's a_rows)
  DistanceBound bounds_;
  int kind_ = 0;  // A's kind * 3 + B's kind
  std::size_t i_ = 0, word_ = 0, last_word_ = 0, first_ = 0, end_ = 0;
  std::uint64_t bits_ = 0;  // the row's current word, the elements already listed cleared
  bool row_built_ = false;
};

}  // namespace

bool WitnessSearch::cones_disjoint(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b) const {
  using K = ElementKind;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  const double tol = 1e-9;  // on unit directions
  const Mat3& R = pose.R_BA;
  // A point on the open touching set, and a short probe length that stays near it.
  const ClosestPoints cp = element_distance(A, pose, ka, a, B, kb, b);
  const Vec3 x = cp.p_b;
  double h = scale_;
  auto shorten = [&](const Polyhedron& m, ElementKind k, int i) {
    if (k == K::kVertex)
      for (EdgeId e : m.vertices()[i].edges) h = std::min(h, m.edge(e).length);
    else if (k == K::kEdge) h = std::min(h, m.edges()[i].length);
  };
  shorten(A, ka, a);
  shorten(B, kb, b);
  h *= 1e-4;
  auto inside_a = [&](const Vec3& p_B) { return point_inside(A, pose.inverse_apply(p_B), 1e-3 * h); };
  auto inside_b = [&](const Vec3& p_B) { return point_inside(B, p_B, 1e-3 * h); };
  // B's wedge at a convex edge lies in A's closed outer half-space {y : n . y >= 0}.
  auto wedge_b_outside = [&](int e, const Vec3& n) {
    return B.edges()[e].convex && B_.wedges[e].into_left.dot(n) >= -tol && B_.wedges[e].into_right.dot(n) >= -tol;
  };
  auto wedge_a_outside = [&](int e, const Vec3& n) {  // n in B's frame, outward of B
    return A.edges()[e].convex && (R * A_.wedges[e].into_left).dot(n) >= -tol &&
           (R * A_.wedges[e].into_right).dot(n) >= -tol;
  };
  if (ka == K::kFace && kb == K::kFace) return (R * A.faces()[a].normal).dot(B.faces()[b].normal) < -1 + tol;
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
    if (N.norm() > 1e-9) {
      // Crossing edges: the only plane that can separate the wedges holds both edges.
      if (!A.edges()[a].convex || !B.edges()[b].convex) return false;
      N.normalize();
      auto side = [&](const Vec3& n) {
        return std::min({B_.wedges[b].into_left.dot(n), B_.wedges[b].into_right.dot(n),
                         -(R * A_.wedges[a].into_left).dot(n), -(R * A_.wedges[a].into_right).dot(n)});
      };
      return std::max(side(N), side(-N)) >= -tol;
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
    const auto sa = sector(R * A_.wedges[a].into_right, R * A_.wedges[a].into_left, A.edges()[a].dihedral);
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

double WitnessSearch::verify(const PcSet& pcs, const Pose& pose, std::string* why) const {
  return verify(pcs, pose, why, nullptr);
}

bool covered_by(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs, ElementKind ka, int a,
                ElementKind kb, int b) {
  for (const Pc& pc : pcs)
    if (in_closure(A, ka, a, a_kind(pc.type), pc.a) && in_closure(B, kb, b, b_kind(pc.type), pc.b)) return true;
  return false;
}

bool WitnessSearch::still_blocked(const PcSet& pcs, const Pose& pose, const Obstacle& o) const {
  if (!o.set) return false;
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  if (covered_by(A, B, pcs, o.ka, o.a, o.kb, o.b)) return false;  // verify judges those otherwise
  const double d = element_distance(A, pose, o.ka, o.a, B, o.kb, o.b).distance;
  if (d >= p_.min_clearance) return false;
  return d > p_.touch_tol || open_touch(A, pose, o.ka, o.a, B, o.kb, o.b, p_.touch_tol);
}

bool WitnessSearch::still_fails(const PcSet& pcs, const Pose& pose, const FailedPair& f) const {
  if (f.kind == FailedPair::Kind::kObstacle) return still_blocked(pcs, pose, f.obstacle());
  if (f.kind != FailedPair::Kind::kOverlap) return false;
  // verify's overlap test, for a pair that is a PC or covered by one (as recorded).
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  return overlap_at(pose, f.ka, f.a, f.kb, f.b,
                    element_distance(A, pose, f.ka, f.a, B, f.kb, f.b).distance);
}

bool WitnessSearch::overlap_at(const Pose& pose, ElementKind ka, int a, ElementKind kb, int b,
                               double d) const {
  return d <= p_.touch_tol && open_touch(*A_.model, pose, ka, a, *B_.model, kb, b, p_.touch_tol) &&
         !cones_disjoint(pose, ka, a, kb, b);
}

double WitnessSearch::verify(const PcSet& pcs, const Pose& pose, std::string* why,
                             FailedPair* failed) const {
  // The reason is written only when asked for: verify runs millions of times a run, most of
  // them to reject, and a message built each time was a heap allocation or five.
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
  if (local_margin(pcs, pose.R_BA) < verified_local_slack())
    return reject("locally penetrating");
  // Line and plane PCs need their rotational conditions (a rotation found by a motion may
  // only nearly satisfy them).
  {
    const RotConstraints c = rotation_constraints(pcs, A, B);
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
  // Pairs proven farther apart than good_clearance can neither touch nor lower the clearance
  // below what counts as good: not measured.
  NearPairs near(A_, B_, pose, p_.good_clearance);
  for (ElementPair e; near.next(e);) {
    const ElementKind ka = e.ka, kb = e.kb;
    const int a = e.a, b = e.b;
    const double d = element_distance(A, pose, ka, a, B, kb, b).distance;
    if (ka == ElementKind::kVertex) a_vertex_gap[a] = std::min(a_vertex_gap[a], d);
    if (kb == ElementKind::kVertex) b_vertex_gap[b] = std::min(b_vertex_gap[b], d);
    bool is_pc = false;
    for (const Pc& pc : pcs)
      if (a_kind(pc.type) == ka && b_kind(pc.type) == kb && pc.a == a && pc.b == b) is_pc = true;
    const bool covered = covered_by(A, B, pcs, ka, a, kb, b);
    if (is_pc) {
      if (d > p_.touch_tol)
        return reject_with([&] {
          return "PC " + to_string(pc_of(pcs, ka, a, kb, b)) + " apart by " + std::to_string(d);
        });
      // The open elements must touch: a face meeting an edge only at its own boundary
      // realises an edge-edge PC, not face-edge.
      if (!open_touch(A, pose, ka, a, B, kb, b, p_.touch_tol))
        return reject_with([&] {
          return "PC " + to_string(pc_of(pcs, ka, a, kb, b)) + " touches only on its boundary";
        });
      ++touching_pcs;
    }
    // Where two elements share open points, A's and B's tangent cones there must have
    // disjoint interiors; pairs that touch only through their boundaries are judged
    // as those boundary pairs. This catches a face of A running through a reflex edge
    // of B, which no pair reports as crossing.
    if ((is_pc || covered) && overlap_at(pose, ka, a, kb, b, d)) {
      if (failed) *failed = FailedPair{FailedPair::Kind::kOverlap, ka, kb, a, b};
      return reject_with([&] {
        return "A and B overlap where " + kind_name(ka) + std::to_string(a) + " touches " +
               kind_name(kb) + std::to_string(b);
      });
    }
    if (!is_pc && !covered) {
      // Closed elements that meet only on their boundaries do not touch: their boundary
      // elements do, and those pairs are judged on their own.
      if (d <= p_.touch_tol && !open_touch(A, pose, ka, a, B, kb, b, p_.touch_tol)) continue;
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

bool WitnessSearch::contacts_at(const Pose& pose, PcSet& out, std::string* why) const {
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
      dominated = j != i && in_closure(A, x.ka, x.a, y.ka, y.a) && in_closure(B, x.kb, x.b, y.kb, y.b);
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
    if (x.ka == K::kFace) t = x.kb == K::kFace ? PcType::kFF : x.kb == K::kEdge ? PcType::kFE : PcType::kFV;
    else if (x.ka == K::kEdge) t = x.kb == K::kFace ? PcType::kEF : PcType::kEE;
    else t = PcType::kVF;
    if (!out.insert(Pc{t, x.a, x.b})) return fail("more than three PCs, the fourth ");
  }
  return true;
}

bool WitnessSearch::plausible(const PcSet& pcs) const {
  // A point lies in at most one open element: one vertex cannot make two PCs.
  for (int i = 0; i < pcs.size(); ++i)
    for (int j = i + 1; j < pcs.size(); ++j) {
      const Pc& x = pcs[i];
      const Pc& y = pcs[j];
      if (a_kind(x.type) == ElementKind::kVertex && a_kind(y.type) == ElementKind::kVertex &&
          x.a == y.a)
        return false;
      if (b_kind(x.type) == ElementKind::kVertex && b_kind(y.type) == ElementKind::kVertex &&
          x.b == y.b)
        return false;
      // A PC whose two elements lie in the closures of another's is dominated by it, not
      // principal.
      const Polyhedron& A = *A_.model;
      const Polyhedron& B = *B_.model;
      if ((in_closure(A, a_kind(x.type), x.a, a_kind(y.type), y.a) &&
           in_closure(B, b_kind(x.type), x.b, b_kind(y.type), y.b)) ||
          (in_closure(A, a_kind(y.type), y.a, a_kind(x.type), x.a) &&
           in_closure(B, b_kind(y.type), y.b, b_kind(x.type), x.b)))
        return false;
      // Two PCs on one plane of B, or one plane of A, share their contact plane.
      const bool xb = b_kind(x.type) == ElementKind::kFace, yb = b_kind(y.type) == ElementKind::kFace;
      if (xb && yb && B_.face_plane[x.b] == B_.face_plane[y.b]) return false;
      const bool xa = a_kind(x.type) == ElementKind::kFace, ya = a_kind(y.type) == ElementKind::kFace;
      if (xa && ya && A_.face_plane[x.a] == A_.face_plane[y.a]) return false;
    }
  // Heights over a face-face contact: while faces a and b lie against each other, a point's
  // depth below A's face plane (along A's normal, into A) is its height over B's face plane
  // (along B's normal), whatever the spin and the slide in the plane. So every other PC's
  // contact point, a common point of its two elements, needs the two elements' height
  // ranges over that plane to meet.
  const double tol = 1e-9 * scale_ + p_.touch_tol;
  for (const Pc& ff : pcs) {
    if (ff.type != PcType::kFF) continue;
    const Face& fa = A_.model->faces()[ff.a];
    const Face& fb = B_.model->faces()[ff.b];
    for (const Pc& pc : pcs) {
      if (pc == ff) continue;
      double a_lo = std::numeric_limits<double>::infinity(), a_hi = -a_lo, b_lo = a_lo, b_hi = -a_lo;
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
      if (a_flat && b_flat) meet = std::abs(a_lo - b_lo) <= 2 * tol;
      else if (a_flat) meet = a_lo > b_lo + tol && a_lo < b_hi - tol;
      else if (b_flat) meet = b_lo > a_lo + tol && b_lo < a_hi - tol;
      else meet = std::max(a_lo, b_lo) < std::min(a_hi, b_hi) - tol;
      if (!meet) return false;
    }
  }
  return true;
}

double WitnessSearch::contact_margin(const PcSet& pcs, const Pose& pose) const {
  const Polyhedron& A = *A_.model;
  const Polyhedron& B = *B_.model;
  double m = std::numeric_limits<double>::infinity();
  // How far a point of an edge lies inside the open edge and inside the face (B's frame).
  auto edge_in_face = [&](const Vec3& p0, const Vec3& p1, const Polyhedron& fm, FaceId f, bool face_on_a) {
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
        m = std::min(m, edge_in_face(pose.apply(A.edge_point(EdgeId(pc.a), 0)), pose.apply(A.edge_point(EdgeId(pc.a), 1)),
                                     B, FaceId(pc.b), false));
        break;
      case PcType::kFE:
        m = std::min(m, edge_in_face(B.edge_point(EdgeId(pc.b), 0), B.edge_point(EdgeId(pc.b), 1), A, FaceId(pc.a), true));
        break;
      case PcType::kEE: {
        const Vec3 p0 = pose.apply(A.edge_point(EdgeId(pc.a), 0)), p1 = pose.apply(A.edge_point(EdgeId(pc.a), 1));
        const Vec3& q0 = B.edge_point(EdgeId(pc.b), 0);
        const Vec3& q1 = B.edge_point(EdgeId(pc.b), 1);
        const ClosestPoints cp = segment_segment(p0, p1, q0, q1);
        m = std::min({m, (cp.p_a - p0).norm(), (cp.p_a - p1).norm(), (cp.p_b - q0).norm(), (cp.p_b - q1).norm()});
        break;
      }
      case PcType::kFF: {
        // At the centroid of the largest piece of the overlap region.
        const std::optional<Vec3> x = face_overlap_centroid(A, pose, pc.a, B, pc.b);
        m = std::min(m, x ? std::max(0.0, std::min(B.face_inset(FaceId(pc.b), *x),
                                                   A.face_inset(FaceId(pc.a), pose.inverse_apply(*x))))
                          : 0.0);
        break;
      }
    }
  }
  return m;
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

std::vector<int> WitnessSearch::piece_slots(const PcSet& pcs) const {
  std::vector<int> slot_sizes;
  for (const Pc& pc : pcs) {
    switch (pc.type) {
      case PcType::kVF: case PcType::kEF: slot_sizes.push_back(int(B_.pieces[pc.b].size())); break;
      case PcType::kFV: case PcType::kFE: slot_sizes.push_back(int(A_.pieces[pc.a].size())); break;
      case PcType::kFF:
        slot_sizes.push_back(int(B_.pieces[pc.b].size()));
        slot_sizes.push_back(int(A_.pieces[pc.a].size()));
        break;
      case PcType::kEE: break;
    }
  }
  return slot_sizes;
}

bool WitnessSearch::refuted(const PcSet& pcs) const {
  if (!plausible(pcs)) return true;
  const RotConstraints c = rotation_constraints(pcs, *A_.model, *B_.model);
  if (c.align.empty()) return false;  // a continuous family of rotations: not decided here
  bool finite = false;
  const std::vector<Mat3> rots = align_family(c, {}, 0, &finite);
  if (!finite && !rots.empty()) return false;
  if (!finite) {
    // No other condition fixed the spin: the family is continuous unless a condition failed,
    // and align_family returns nothing either way. Tell them apart with one sample.
    if (!align_family(c, {}, 1).empty()) return false;
  }
  std::size_t combos = 1;
  const std::vector<int> slot_sizes = piece_slots(pcs);
  for (int n : slot_sizes) combos *= static_cast<std::size_t>(n);
  if (combos > 4096) return false;
  // Finitely many rotations: each must be locally penetrating or leave no room to place the
  // contacts inside their elements (the LP over every combination of convex pieces).
  for (const Mat3& R : rots) {
    if (local_margin(pcs, R) < verified_local_slack()) continue;
    std::vector<int> choice(slot_sizes.size(), 0);
    for (std::size_t k = 0; k < combos; ++k) {
      const LpResult r = solve(build_lp(pcs, R, choice));
      if (r.status == LpResult::Status::kOptimal && r.x[3] >= p_.min_margin) return false;
      for (std::size_t i = 0; i < choice.size() && ++choice[i] == slot_sizes[i]; ++i) choice[i] = 0;
    }
  }
  return true;
}

Witness WitnessSearch::find(const PcSet& pcs, const std::vector<Mat3>& seeds,
                            bool seeds_only) const {
  Witness best;
  if (!plausible(pcs)) return best;
  const std::vector<Mat3> rots = rotation_candidates(pcs, seeds, !seeds_only);
  if (debug_) std::cerr << "find " << to_string(pcs[0]) << (pcs.size() > 1 ? " +" : "") << ": " << rots.size() << " rotations\n";
  // Face-piece slots, in the order solve_translation consumes them.
  const std::vector<int> slot_sizes = piece_slots(pcs);
  std::vector<Mat3> near;  // rotations where the contacts held but the pose failed
  // Poses where the contacts held and the centred translation met another pair of elements.
  struct Blocked {
    Mat3 R;
    std::vector<int> pieces;
    Vec3 t;
    Obstacle obstacle;
  };
  std::vector<Blocked> blocked;
  // The pairs recent poses failed on, newest first. A pose whose verdict matters only if it
  // is a witness (every translation but the first of a rotation's pass or of a cut, whose
  // obstacle steers the cuts and the skipping of the pass's other translations) is refused without
  // a verification when one of them still fails there: most poses of a set that has no witness fail
  // on a pair met before.
  constexpr std::size_t kRecent = 8;
  std::array<FailedPair, kRecent> recent{};
  auto remember = [&](const FailedPair& f) {
    if (f.kind == FailedPair::Kind::kNone) return;
    auto same = [&](const FailedPair& g) {
      return g.kind == f.kind && g.ka == f.ka && g.kb == f.kb && g.a == f.a && g.b == f.b;
    };
    auto it = std::find_if(recent.begin(), recent.end(), same);
    if (it == recent.end()) it = recent.end() - 1;
    std::rotate(recent.begin(), it, it + 1);
    recent.front() = f;
  };
  // verify, keeping the pair the pose failed on (in f) among the recent ones.
  auto verify_remembering = [&](const Pose& pose, std::string* why, FailedPair& f) {
    const double clearance = verify(pcs, pose, why, &f);
    remember(f);
    return clearance;
  };
  // verify for a pose only a witness would change anything at: -1 when a recent pair proves
  // it fails.
  auto verify_unless_failing = [&](const Pose& pose) {
    for (const FailedPair& f : recent) {
      if (f.kind == FailedPair::Kind::kNone) break;
      if (still_fails(pcs, pose, f)) return -1.0;
    }
    FailedPair f;
    return verify_remembering(pose, nullptr, f);
  };
  // Returns true when a good witness was found.
  auto cut_obstacles = [&](const Mat3& R, const std::vector<int>& choice, Vec3 t, Obstacle obstacle) {
    constexpr int kMaxCuts = 4;  // obstacles avoided in turn before giving up on a rotation
    std::vector<LinearProgram::Row> cuts;
    for (int k = 0; k < kMaxCuts && obstacle.set; ++k) {
      LinearProgram::Row cut;
      if (!separating_cut(R, t, obstacle, cut)) return false;
      cuts.push_back(cut);
      double margin = 0;
      const std::vector<Vec3> ts = translations(pcs, R, choice, margin, false, cuts);
      if (debug_) std::cerr << "  cut " << k + 1 << ": " << ts.size() << " translations, margin " << margin << "\n";
      if (ts.empty()) return false;
      obstacle = Obstacle();
      for (const Vec3& tt : ts) {
        Pose pose;
        pose.R_BA = R;
        pose.t_BA = tt;
        double clearance = -1;
        if (&tt == &ts.front()) {
          FailedPair f;
          clearance = verify_remembering(pose, nullptr, f);
          obstacle = f.obstacle();
          t = tt;
        } else {
          if (still_blocked(pcs, pose, obstacle)) continue;
          clearance = verify_unless_failing(pose);
        }
        if (clearance >= p_.min_clearance && clearance > best.clearance) {
          best.found = true;
          best.pose = pose;
          best.clearance = clearance;
          best.margin = margin;
          return clearance >= p_.good_clearance;
        }
      }
    }
    return false;
  };
  constexpr std::size_t kMaxBlocked = 4;  // blocked poses the last stage climbs from
  auto try_rotation = [&](const Mat3& R) {
    std::vector<int> choice(slot_sizes.size(), 0);
    for (int combo = 0; combo < p_.max_piece_combinations; ++combo) {
      // Pass 0: centred translations; pass 1 (only when pass 0 placed the contacts but found
      // no witness): translations close to the elements' boundaries.
      TranslationMemo memo;
      for (int pass = 0; pass < 2; ++pass) {
        double margin = 0;
        const std::vector<Vec3> ts = translations(pcs, R, choice, margin, pass == 1, {}, &memo);
        if (pass == 0 && !ts.empty() && near.size() < 4) near.push_back(R);
        if (debug_) std::cerr << "  rotation, pass " << pass << ": " << ts.size() << " translations, margin " << margin << "\n";
        Obstacle first_obstacle;
        for (const Vec3& t : ts) {
          Pose pose;
          pose.R_BA = R;
          pose.t_BA = t;
          // Nearby translations are often blocked by the same pair: one distance decides.
          if (&t != &ts.front() && still_blocked(pcs, pose, first_obstacle)) continue;
          std::string why;
          double clearance = -1;
          if (&t == &ts.front() || debug_) {
            FailedPair f;
            clearance = verify_remembering(pose, debug_ ? &why : nullptr, f);
            if (&t == &ts.front()) first_obstacle = f.obstacle();
          } else {
            clearance = verify_unless_failing(pose);
          }
          if (debug_) std::cerr << "    t " << t.transpose() << " clearance " << clearance << " " << why << "\n";
          if (clearance >= p_.min_clearance && clearance > best.clearance) {
            best.found = true;
            best.pose = pose;
            best.clearance = clearance;
            best.margin = margin;
            if (clearance >= p_.good_clearance) return true;
          }
          if (clearance >= p_.min_clearance) break;  // a witness for this rotation; try others
        }
        if (ts.empty() || best.found) break;
        if (pass == 0 && first_obstacle.set && blocked.size() < kMaxBlocked)
          blocked.push_back({R, choice, ts.front(), first_obstacle});
        // The contacts were placed but the centred translation ran into another pair of
        // elements: move away from it (a half-space of translations where the pair is apart)
        // and place the contacts again, a few obstacles deep.
        if (pass == 0 && first_obstacle.set && cut_obstacles(R, choice, ts.front(), first_obstacle)) return true;
        if (best.found) break;
      }
      // Next combination of pieces (odometer); stop when all tried.
      std::size_t i = 0;
      while (i < choice.size() && ++choice[i] == slot_sizes[i]) choice[i++] = 0;
      if (i == choice.size()) break;
    }
    return false;
  };
  const double min_local = std::sin(p_.angle_margin);
  // Past the obstacles: a set whose contacts hold only in a thin range of orientations (a
  // peg tilted across a hole's rim, its corner near the far wall) is blocked at every
  // rotation sampled above, by pairs of elements that a small turn would clear. From each
  // blocked pose, climb over the rotations the conditions leave free, with the translation
  // chosen by a program that keeps the contacts inside their elements and pushes every
  // obstacle met so far beyond its separating cut (obstacle_margin); where that margin
  // reaches min_margin, try the program's translations, and when one meets a new pair, add
  // it and climb on.
  constexpr int kMaxObstacles = 8;     // pairs pushed apart at once
  constexpr int kMaxEvaluations = 160;  // programs solved per blocked pose
  constexpr double kFirstTurn = 0.02;   // rad, the largest turn about an axis
  constexpr double kLastTurn = 1e-3;   // rad
  auto past_obstacles = [&]() -> Witness {
    for (const Blocked& b : blocked) {
      std::vector<Obstacle> obstacles{b.obstacle};
      auto known = [&](const Obstacle& o) {
        return std::any_of(obstacles.begin(), obstacles.end(), [&](const Obstacle& x) {
          return x.ka == o.ka && x.kb == o.kb && x.a == o.a && x.b == o.b;
        });
      };
      Mat3 R = b.R;
      LpVector x, xq;
      std::vector<LinearProgram::Row> cuts, cq;
      std::vector<std::vector<Vec3>> cut_points, cpq;
      double m = obstacle_margin(pcs, R, b.pieces, obstacles, b.t, x, cuts, cut_points);
      if (!std::isfinite(m)) continue;
      double turn = kFirstTurn;
      // A climb that stalls after meeting new obstacles starts again from the blocked pose
      // with all of them: the first climbs turned without knowing them.
      std::size_t obstacles_at_start = 1;
      for (int evals = 1; evals < kMaxEvaluations;) {
        if (turn < kLastTurn && obstacles.size() > obstacles_at_start) {
          obstacles_at_start = obstacles.size();
          R = b.R;
          m = obstacle_margin(pcs, R, b.pieces, obstacles, b.t, x, cuts, cut_points);
          ++evals;
          if (!std::isfinite(m)) break;
          turn = kFirstTurn;
        }
        if (m >= p_.min_margin) {
          double margin = 0;
          const std::vector<Vec3> ts = translations(pcs, R, b.pieces, margin, false, cuts);
          if (debug_)
            std::cerr << "  past obstacles: " << obstacles.size() << " cleared, " << ts.size()
                      << " translations\n";
          Obstacle next;
          for (const Vec3& tt : ts) {
            Pose pose;
            pose.R_BA = R;
            pose.t_BA = tt;
            FailedPair f;
            const double clearance = verify_remembering(pose, nullptr, f);
            if (&tt == &ts.front()) next = f.obstacle();
            if (clearance >= p_.min_clearance) {
              best.found = true;
              best.pose = pose;
              best.clearance = clearance;
              best.margin = margin;
              return best;
            }
          }
          if (!next.set || known(next) || static_cast<int>(obstacles.size()) >= kMaxObstacles)
            break;
          obstacles.push_back(next);
          const Vec3 t = x.head<3>();
          m = obstacle_margin(pcs, R, b.pieces, obstacles, t, x, cuts, cut_points);
          ++evals;
          if (!std::isfinite(m)) break;
          turn = kFirstTurn;
          continue;
        }
        if (turn < kLastTurn) break;
        // The step of the program linearised in the turn first; where it does not raise the
        // margin (at a kink of the smallest margin, or where a cut's best axis changes), the
        // turns about each axis the conditions leave free.
        std::vector<Mat3> tries;
        if (Mat3 Q; obstacle_step(pcs, R, b.pieces, x, cuts, cut_points, turn, Q))
          tries.push_back(Q);
        for (const Mat3& Q : rotation_steps(pcs, R, turn)) tries.push_back(Q);
        bool moved = false;
        for (const Mat3& Q : tries) {
          if (evals >= kMaxEvaluations) break;
          ++evals;
          if (local_margin(pcs, Q) <= min_local) continue;
          const double mq = obstacle_margin(pcs, Q, b.pieces, obstacles, x.head<3>(), xq, cq, cpq);
          if (mq > m) {
            m = mq;
            R = Q;
            x = xq;
            cuts.swap(cq);
            cut_points.swap(cpq);
            moved = true;
            break;
          }
        }
        if (debug_)
          std::cerr << "    turn " << turn << (moved ? " gained, margin " : " no gain, margin ")
                    << m << "\n";
        turn = moved ? std::min(2 * turn, kFirstTurn) : 0.5 * turn;
      }
      if (debug_) {
        std::cerr << "  past obstacles: margin " << m << " with " << obstacles.size()
                  << " obstacles:";
        for (const Obstacle& o : obstacles)
          std::cerr << " " << kind_name(o.ka) << o.a << "-" << kind_name(o.kb) << o.b;
        std::cerr << "\n";
      }
    }
    return best;
  };
  for (const Mat3& R : rots)
    if (try_rotation(R)) return best;
  if (best.found) return best;
  if (seeds_only) {
    // The neighbours' witnesses are a few hundredths of a radian from where the set holds:
    // look that close around each, then climb past the obstacles met.
    for (const Mat3& R : rotation_candidates(pcs, turned_about_axes(seeds, {0.01, 0.025}), false))
      if (try_rotation(R)) return best;
    if (best.found) return best;
    return past_obstacles();
  }
  // Two point PCs: rotations built to place both contacts inside their elements, where the
  // spread above left too few locally admissible ones (two e-e crossings) or none that
  // fits (a peg's corner just inside a hole's rim).
  for (const Mat3& R : anchored_rotations(pcs))
    if (try_rotation(R)) return best;
  if (best.found) return best;
  // Where no rotation tried could place the contacts, climb the margin: from the rotations
  // that came closest, step along the rotations the conditions leave free while the
  // (possibly negative) margin grows, and try each rotation that reaches min_margin.
  // Narrow CFs, e.g. a vertex of A reaching a riser of B while an edge of A lies on the
  // tread, live in a small region of such rotations that a fixed sample misses.
  if (near.empty()) {
    constexpr int kStarts = 2;            // closest rotations climbed from
    constexpr int kMaxSteps = 32;         // evaluations per climb
    constexpr double kFirstStep = 0.2;    // rad
    constexpr double kLastStep = 1e-2;    // rad
    const std::vector<int> first_pieces(slot_sizes.size(), 0);
    // Lexicographic: first the local non-penetration slack (a cosine) until it is positive,
    // then the contacts' margin inside their elements (mm).
    auto score = [&](const Mat3& R) {
      const double local = local_margin(pcs, R);
      if (local <= min_local) return std::make_pair(0, local);
      return std::make_pair(1, signed_margin(pcs, R, first_pieces));
    };
    std::vector<std::pair<std::pair<int, double>, Mat3>> starts;
    auto by_score = [](const auto& x, const auto& y) { return x.first > y.first; };
    for (const Mat3& R : rots) starts.push_back({score(R), R});
    std::stable_sort(starts.begin(), starts.end(), by_score);
    if (starts.size() > kStarts) starts.resize(kStarts);
    if (starts.size() < kStarts) {
      // Too few rotations hold locally: climb also from the locally penetrating ones that
      // come closest.
      std::vector<std::pair<std::pair<int, double>, Mat3>> more;
      for (const Mat3& R : family_samples(pcs, spread_rotations(pcs, seeds), p_.theta_samples)) {
        const double local = local_margin(pcs, R);
        if (local <= min_local) more.push_back({{0, local}, R});
      }
      std::stable_sort(more.begin(), more.end(), by_score);
      for (std::size_t i = 0; i < more.size() && starts.size() < kStarts; ++i) starts.push_back(more[i]);
    }
    for (auto [m, R] : starts) {
      if (!std::isfinite(m.second)) continue;
      if (debug_) std::cerr << "  climb from " << m.first << " / " << m.second << "\n";
      double h = kFirstStep;
      const auto done = [&] { return m.first == 1 && m.second >= p_.min_margin; };
      int evals = 0;
      for (; evals < kMaxSteps && h >= kLastStep && !done();) {
        bool moved = false;
        for (const Mat3& Q : rotation_steps(pcs, R, h)) {
          const auto mq = score(Q);
          ++evals;
          if (mq > m) {
            m = mq;
            R = Q;
            moved = true;
            break;
          }
        }
        if (!moved) h *= 0.5;
      }
      if (debug_) std::cerr << "  climbed to " << m.first << " / " << m.second << " in " << evals << " evaluations\n";
      if (done() && try_rotation(R)) return best;
      if (best.found) return best;
    }
  }
  if (best.found || near.empty()) return best;
  // The contacts could be placed but the pose touched something else: look closer around
  // those rotations, where valid sets with a narrow range of orientations live.
  for (const Mat3& R : rotation_candidates(pcs, turned_about_axes(near, {0.04, 0.12, 0.3}), false))
    if (try_rotation(R)) return best;
  if (best.found) return best;
  // A one-parameter family: a part leaning in a gap (a peg tilted in a hole, an edge resting
  // on one wall and the rim on its face) holds in a narrow range of the parameter, a few
  // hundredths of a radian wide, just inside the end of the range where its contacts are
  // locally admissible. Walk the family from the rotations above to each such end and try the
  // rotations just inside it. (Where the two conditions are one, e.g. an edge on a face and a
  // face parallel to that edge on an edge parallel to that face, the rotations form a
  // surface and the walk follows curves on it; it still finds such ends, not all of them.)
  constexpr double kWalkStep = 0.03;  // rad
  constexpr int kWalkSteps = 60;      // up to 1.8 rad each way
  constexpr int kInside = 4;          // rotations tried inside each end, kWalkStep apart
  const RotConstraints c = rotation_constraints(pcs, *A_.model, *B_.model);
  std::vector<Mat3> ends;
  for (const Mat3& R : near)
    for (const std::vector<Mat3>& path : walk_family(c, R, kWalkStep, kWalkSteps)) {
      std::size_t k = 0;
      while (k < path.size() && local_margin(pcs, path[k]) > min_local) ++k;
      if (debug_) std::cerr << "  walk: " << path.size() << " steps, end at " << k << "\n";
      if (k == path.size()) continue;  // no end within reach
      for (int i = 1; i <= kInside && static_cast<int>(k) - i >= 0; ++i) add_unique(ends, path[k - i]);
    }
  for (const Mat3& R : ends)
    if (try_rotation(R)) return best;
  if (best.found) return best;
  return past_obstacles();
}

void WitnessSearch::freedoms(const PcSet& pcs, const Pose& pose, CfRecord& out) const {
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
      case PcType::kVF: add(pose.apply(A.vertices()[pc.a].p), nrm); break;
      case PcType::kFV: add(B.vertices()[pc.b].p, nrm); break;
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
        add(element_distance(A, pose, ElementKind::kEdge, pc.a, B, ElementKind::kEdge, pc.b).p_b, nrm);
        break;
    }
  }
  const Freedoms f = freedoms_from_points(pts, n, pose.t_BA, L, Params{});
  out.dof = f.dof;
  out.translation_dof = f.translation_dof;
  out.pure_rotation = f.pure_rotation;
}

}  // namespace cf::gen
