#include "cfgen/decide/rotation_family.hpp"

#include "cfgen/verify/verifier.hpp"

#include <cf/geometry.hpp>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <limits>

namespace cf::gen::internal {
namespace {

// Solutions theta of a cos(theta) + b sin(theta) == d to within tol (rad); `all` when it
// holds for every theta. Where |d| exceeds hypot(a, b) by at most tol, the closest theta.
// A condition that varies along the circle by no more than its tolerance (tol above
// rounding: the models' precision) holds on an arc or nowhere, not at isolated roots: `all`
// when it holds somewhere, and the caller checks each rotation it takes.
bool trig_solve(double a, double b, double d, std::vector<double>& out, bool& all,
                double tol = kRotTol) {
  const double r = std::hypot(a, b);
  all = false;
  if (r < 1e-12 || (tol > kRotTol && r <= 2 * tol)) {
    all = std::abs(d) < tol + r;
    return all;
  }
  double c = d / r;
  if (std::abs(c) > 1 + std::max(1e-9, tol / r)) return false;
  c = std::clamp(c, -1.0, 1.0);
  const double phi = std::atan2(b, a);
  const double delta = std::acos(c);
  out.push_back(phi + delta);
  if (delta > 1e-9 && delta < M_PI - 1e-9) out.push_back(phi - delta);
  return true;
}

// The tolerance trig_solve takes for a condition of tolerance t: kRotTol on exact models,
// whose conditions are met to rounding; t where the models' precision sets it.
double solve_tol(double t) { return t > kRotAccepted ? t : kRotTol; }

// theta maximising trace(S^T Rot(axis, theta) R0): the family member closest to S.
double closest_theta(const Vec3& axis, const Mat3& R0, const Mat3& S) {
  const Mat3 Q = R0 * S.transpose();
  Mat3 K;
  K << 0, -axis.z(), axis.y(), axis.z(), 0, -axis.x(), -axis.y(), axis.x(), 0;
  const double c = Q.trace() - axis.dot(Q * axis);
  const double s = (Q * K).trace();
  return std::atan2(s, c);
}

}  // namespace

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

// Rotations R = Rot(axis, theta) * R0 satisfying all constraints; finitely many or samples.
std::vector<Mat3> align_family(const RotConstraints& c, const std::vector<Mat3>& seeds, int samples,
                               bool* finite_out) {
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
  auto consider = [&](const Vec3& u0, const Vec3& w, double target, double tol) {
    const Vec3 u = R0 * u0;
    const Vec3 u_par = u.dot(axis) * axis;
    const double A = (u - u_par).dot(w);
    const double B = axis.cross(u).dot(w);
    const double C = u_par.dot(w);
    std::vector<double> sol;
    bool all = false;
    if (!trig_solve(A, B, target - C, sol, all, solve_tol(tol))) return false;
    if (all) return true;
    if (!finite) {
      thetas = sol;
      finite = true;
    }
    return true;
  };
  for (std::size_t i = 1; i < c.align.size(); ++i)
    if (!consider(c.align[i].first, c.align[i].second, 1.0, c.align_tol_of(i))) return {};
  for (std::size_t i = 0; i < c.perp.size(); ++i)
    if (!consider(c.perp[i].first, c.perp[i].second, 0.0, c.perp_tol_of(i))) return {};
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
  const double rank_tol = c.max_tol() > kRotAccepted ? c.max_tol() : 0;
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
    double worst = 0;  // a plain loop: GCC 12 misreads maxCoeff on a bounded vector here
    for (int i = 0; i < k; ++i) worst = std::max(worst, std::abs(r[i]));
    if (worst < 1e-14) return true;
    Eigen::CompleteOrthogonalDecomposition<Jac> cod;
    // Conditions the same to within their tolerance (an edge along a face's normal against
    // an edge along another face's, each to the models' precision) count as one: a
    // rank-deficient step, not a huge one along their difference.
    if (rank_tol > 0) cod.setThreshold(rank_tol);
    cod.compute(J);
    const Eigen::Vector3d d = -cod.solve(r);
    if (!d.allFinite() || d.norm() < 1e-16) break;
    const double ang = std::min(d.norm(), 0.5);
    R = axis_angle(d.normalized(), ang) * R;
  }
  return satisfies(c, R);
}

namespace {

// The rotations meeting c.perp[0], R = Rot(w1, phi) R0 Rot(u1, psi) with R0 u1 perpendicular
// to w1 (every such rotation once), and on them the other two conditions, each
// [1 cos psi sin psi] M [1 cos phi sin phi]^T.
struct PerpTorus {
  Vec3 u1, w1;
  Mat3 R0;
  Mat3 M[2];

  Mat3 rotation(double phi, double psi) const {
    return axis_angle(w1, phi) * R0 * axis_angle(u1, psi);
  }
  // (C, A, B) of condition k + 1 at phi: it reads A cos psi + B sin psi + C == 0.
  Vec3 at(int k, double phi) const { return M[k] * Vec3(1, std::cos(phi), std::sin(phi)); }
};

PerpTorus perp_torus(const RotConstraints& c) {
  PerpTorus t;
  t.u1 = c.perp[0].first.normalized();
  t.w1 = c.perp[0].second.normalized();
  Eigen::Index least = 0;  // the axis farthest from w1, for a well-conditioned perpendicular
  t.w1.cwiseAbs().minCoeff(&least);
  t.R0 = align(t.u1, t.w1.cross(Vec3::Unit(least)).normalized());
  for (int k = 0; k < 2; ++k) {
    const Vec3 u = c.perp[k + 1].first, w = c.perp[k + 1].second;
    // Rot(u1, psi) u and Rot(w1, -phi) w, each split into its constant, cos and sin parts.
    const Vec3 X[3] = {u.dot(t.u1) * t.u1, u - u.dot(t.u1) * t.u1, t.u1.cross(u)};
    const Vec3 Y[3] = {w.dot(t.w1) * t.w1, w - w.dot(t.w1) * t.w1, -t.w1.cross(w)};
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) t.M[k](a, b) = (t.R0 * X[a]).dot(Y[b]);
  }
  return t;
}

// The two conditions at phi as a linear system in (cos psi, sin psi): its determinant and
// Cramer's numerators. A common root psi exists where nx^2 + ny^2 == det^2.
struct PerpCramer {
  double det, nx, ny;
};
PerpCramer perp_cramer(const PerpTorus& t, double phi) {
  const Vec3 g = t.at(0, phi), h = t.at(1, phi);  // (C, A, B) each
  return {g[1] * h[2] - h[1] * g[2], h[0] * g[2] - g[0] * h[2], h[1] * g[0] - g[1] * h[0]};
}

// The real roots phi of a trigonometric polynomial of degree at most 4, given by its values
// at 16 equally spaced angles: the unit-circle roots of z^4 F (a polynomial of degree 8 in
// z = e^(i phi)), with a band around the circle so that a nearly double root is kept (the
// caller polishes each). Nothing when F vanishes identically.
std::optional<std::vector<double>> trig_roots(const std::array<double, 16>& F) {
  using C = std::complex<double>;
  std::array<C, 9> a{};  // a[m]: the coefficient of e^(i (m - 4) phi)
  double scale = 0;
  for (int m = 0; m < 9; ++m) {
    for (int j = 0; j < 16; ++j) a[m] += F[j] * std::polar(1.0 / 16, -(m - 4) * 2 * M_PI * j / 16);
    scale = std::max(scale, std::abs(a[m]));
  }
  if (scale < 1e-12) return std::nullopt;
  int lo = 0, hi = 8;
  while (std::abs(a[lo]) <= 1e-13 * scale) ++lo;
  while (std::abs(a[hi]) <= 1e-13 * scale) --hi;
  std::vector<double> phis;
  const int d = hi - lo;
  if (d == 0) return phis;
  Eigen::MatrixXcd comp = Eigen::MatrixXcd::Zero(d, d);
  for (int r = 1; r < d; ++r) comp(r, r - 1) = 1;
  for (int r = 0; r < d; ++r) comp(r, d - 1) = -a[lo + r] / a[hi];
  const Eigen::VectorXcd z = Eigen::ComplexEigenSolver<Eigen::MatrixXcd>(comp, false).eigenvalues();
  for (int r = 0; r < d; ++r)
    if (std::abs(std::log(std::abs(z[r]))) < 0.05) phis.push_back(std::arg(z[r]));
  return phis;
}

}  // namespace

std::optional<std::vector<Mat3>> perp_roots(const RotConstraints& c) {
  if (!c.align.empty() || c.perp.size() != 3) return std::nullopt;
  for (const auto& [u, w] : c.perp)
    if (u.norm() < 1e-12 || w.norm() < 1e-12) return std::nullopt;
  const PerpTorus t = perp_torus(c);
  std::array<double, 16> F{};
  for (int j = 0; j < 16; ++j) {
    const PerpCramer p = perp_cramer(t, 2 * M_PI * j / 16);
    F[j] = p.nx * p.nx + p.ny * p.ny - p.det * p.det;
  }
  const std::optional<std::vector<double>> phis = trig_roots(F);
  if (!phis) return std::nullopt;
  std::vector<Mat3> out;
  for (double phi : *phis) {
    std::vector<double> psis;
    const PerpCramer p = perp_cramer(t, phi);
    const Vec3 g = t.at(0, phi), h = t.at(1, phi);
    if (std::abs(p.det) > 1e-6 * g.tail<2>().norm() * h.tail<2>().norm()) {
      psis.push_back(std::atan2(p.ny / p.det, p.nx / p.det));
    } else {
      // The conditions are parallel in (cos psi, sin psi) here: each one's own roots.
      bool all_g = false, all_h = false;
      trig_solve(g[1], g[2], -g[0], psis, all_g);
      trig_solve(h[1], h[2], -h[0], psis, all_h);
      if (all_g && all_h) return std::nullopt;  // a circle of rotations at this phi
    }
    for (double psi : psis) {
      Mat3 R = t.rotation(phi, psi);
      if (project_perp(c, R)) add_unique(out, R);
    }
  }
  return out;
}

// Walks a one-parameter family of rotations (one alignment with its spin free, or two
// perpendicularity conditions) away from R by steps of about h rad, at most n steps along
// each branch: the rotations along each branch, R excluded. Where the two conditions'
// gradients coincide (an axis-aligned pose, where branches of the family cross), each branch
// is entered by a small turn about a coordinate axis projected back onto the conditions.
// Empty for other families.
std::vector<std::vector<Mat3>> walk_family(const RotConstraints& c, const Mat3& R, double h,
                                           int n) {
  std::vector<std::vector<Mat3>> paths;
  const bool spin = c.align.size() == 1 && c.perp.empty();
  if (!spin && !(c.align.empty() && c.perp.size() == 2)) return paths;
  // The axis keeping the conditions to first order (zero where it is not unique).
  auto tangent = [&](const Mat3& Q) -> Vec3 {
    if (spin) return c.align[0].second;
    const Vec3 w = (Q * c.perp[0].first)
                       .cross(c.perp[0].second)
                       .cross((Q * c.perp[1].first).cross(c.perp[1].second));
    return w.norm() < 1e-6 ? Vec3::Zero() : Vec3(w.normalized());
  };
  auto step = [&](const Mat3& Q, const Vec3& axis, Mat3& out) {
    out = axis_angle(axis, h) * Q;
    return spin || project_perp(c, out);
  };
  std::vector<Mat3> starts;
  const Vec3 w0 = tangent(R);
  std::vector<Vec3> kicks;
  if (w0.norm() > 0)
    kicks = {w0, -w0};
  else
    for (int ax = 0; ax < 3; ++ax)
      kicks.push_back(Vec3::Unit(ax)), kicks.push_back(-Vec3::Unit(ax));
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

std::vector<Mat3> project_onto(const RotConstraints& c, const Mat3& R) {
  if (!c.align.empty()) return align_family(c, {R}, 0);
  Mat3 out = R;
  if (!c.perp.empty() && !project_perp(c, out)) return {};
  return {out};
}

std::vector<double> admissible_spins(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs,
                                     const Vec3& axis, const Mat3& R0, int samples,
                                     double min_local, std::pair<double, double>* best) {
  constexpr double kSpinResolution = 2e-3;  // rad: the narrowest arc halved
  std::vector<double> out;
  if (best) *best = {0.0, -std::numeric_limits<double>::infinity()};
  std::vector<std::pair<double, double>> arcs;  // centre, half-width (rad)
  for (int k = samples - 1; k >= 0; --k) arcs.push_back({2 * M_PI * k / samples, M_PI / samples});
  while (!arcs.empty()) {
    const auto [phi, half] = arcs.back();
    arcs.pop_back();
    const Mat3 R = R0 * axis_angle(axis, phi);
    // The bound first: most arcs hold no admissible spin, and it rules them out alone.
    if (local_margin_bound(a, b, pcs, R, TurnBound{0, half, axis}, nullptr, EeBound::kDirect) <=
        min_local)
      continue;
    const double margin = local_margin_bound(a, b, pcs, R, TurnBound{});
    if (best && margin > best->second) *best = {phi, margin};
    if (margin > min_local) {
      out.push_back(phi);
    } else if (half >= 2 * kSpinResolution) {
      arcs.push_back({phi + half / 2, half / 2});
      arcs.push_back({phi - half / 2, half / 2});
    }
  }
  return out;
}

std::optional<double> translation_residual(const Polyhedron& A, const Polyhedron& B,
                                           const PcSet& pcs, const Mat3& R, double dependent) {
  if (pcs.size() != 3 && pcs.size() != 2) return std::nullopt;
  Vec3 n[3];
  double h[3];
  int i = 0;
  for (const Pc& pc : pcs) {
    const auto face_a = [&](const Vec3& p_B) {  // A's face through the point p_B of B
      const Face& f = A.faces()[pc.a];
      n[i] = R * f.normal;
      h[i] = n[i].dot(p_B) - f.offset;
    };
    const auto face_b = [&](const Vec3& p_A) {  // B's face through the point R p_A + t
      const Face& f = B.faces()[pc.b];
      n[i] = f.normal;
      h[i] = f.offset - n[i].dot(R * p_A);
    };
    switch (pc.type) {
      case PcType::kFF:
        face_b(A.faces()[pc.a].centroid);
        break;
      case PcType::kVF:
        face_b(A.vertices()[pc.a].p);
        break;
      case PcType::kEF:
        face_b(A.vertices()[A.edges()[pc.a].v0.index()].p);
        break;
      case PcType::kFV:
        face_a(B.vertices()[pc.b].p);
        break;
      case PcType::kFE:
        face_a(B.vertices()[B.edges()[pc.b].v0.index()].p);
        break;
      case PcType::kEE: {
        const Edge& ea = A.edges()[pc.a];
        const Edge& eb = B.edges()[pc.b];
        const Vec3 m = (R * ea.dir).cross(eb.dir);
        if (m.norm() < 1e-9) return std::nullopt;  // parallel edges: not a PC
        n[i] = m.normalized();
        h[i] = n[i].dot(B.vertices()[eb.v0.index()].p - R * A.vertices()[ea.v0.index()].p);
        break;
      }
    }
    ++i;
  }
  if (pcs.size() == 2) {
    if (n[0].cross(n[1]).norm() > dependent) return std::nullopt;
    return h[1] - (n[0].dot(n[1]) > 0 ? h[0] : -h[0]);
  }
  if (std::abs(n[0].cross(n[1]).dot(n[2])) > dependent) return std::nullopt;
  // The plane of the normals, from the first pair not near parallel: the same pair all along
  // a family, so that the residual's sign is continuous there.
  Vec3 m = n[0].cross(n[1]);
  if (m.norm() < 1e-3) m = n[1].cross(n[2]);
  if (m.norm() < 1e-3) m = n[2].cross(n[0]);
  if (m.norm() < 1e-3) return std::nullopt;  // all three near parallel
  m.normalize();
  const Vec3 z(n[1].cross(n[2]).dot(m), n[2].cross(n[0]).dot(m), n[0].cross(n[1]).dot(m));
  return z.dot(Vec3(h[0], h[1], h[2])) / z.norm();
}

namespace {

// The perpendicularity conditions' residuals and the planes' (scaled by 1 / size), and their
// Jacobian in a turn of R (numerical).
bool consistency_rows(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs,
                      const RotConstraints& c, const Mat3& R, double dependent, Eigen::VectorXd& r,
                      Eigen::MatrixXd* J) {
  const double size = std::max((A.bbox_max() - A.bbox_min()).norm(), 1e-9);
  auto rows = [&](const Mat3& Q, Eigen::VectorXd& out) {
    const std::optional<double> t = translation_residual(A, B, pcs, Q, dependent);
    if (!t) return false;
    out.resize(static_cast<Eigen::Index>(c.perp.size()) + 1);
    for (std::size_t i = 0; i < c.perp.size(); ++i)
      out[static_cast<Eigen::Index>(i)] = (Q * c.perp[i].first).dot(c.perp[i].second);
    out[out.size() - 1] = *t / size;
    return true;
  };
  if (!rows(R, r)) return false;
  if (!J) return true;
  constexpr double kH = 1e-7;  // rad: a forward difference's step
  J->resize(r.size(), 3);
  Eigen::VectorXd rq;
  for (int a = 0; a < 3; ++a) {
    if (!rows(axis_angle(Vec3::Unit(a), kH) * R, rq)) return false;
    J->col(a) = (rq - r) / kH;
  }
  return true;
}

// The direction of the curve at R: the Jacobian's null vector.
Vec3 consistent_tangent(const Eigen::MatrixXd& J) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(J, Eigen::ComputeFullV);
  return svd.matrixV().col(2);
}

}  // namespace

bool project_consistent(const Polyhedron& A, const Polyhedron& B, const PcSet& pcs,
                        const RotConstraints& c, Mat3& R, double dependent) {
  if (!c.align.empty()) return false;
  // As project_perp: conditions equal to within their tolerance count as one, and then hold
  // to it rather than to rounding.
  const double rank_tol = c.max_tol() > kRotAccepted ? c.max_tol() : 0;
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  for (int it = 0; it < 40; ++it) {
    if (!consistency_rows(A, B, pcs, c, R, dependent, r, &J)) return false;
    if (r.cwiseAbs().maxCoeff() < 1e-13) return true;
    if (rank_tol > 0 && std::abs(r[r.size() - 1]) < 1e-13 && satisfies(c, R)) return true;
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
    if (rank_tol > 0) cod.setThreshold(rank_tol);
    cod.compute(J);
    const Eigen::Vector3d d = -cod.solve(r);
    if (!d.allFinite() || d.norm() < 1e-16) return false;
    R = axis_angle(d.normalized(), std::min(d.norm(), 0.3)) * R;
  }
  return false;
}

std::vector<std::vector<Mat3>> walk_consistent(const Polyhedron& A, const Polyhedron& B,
                                               const PcSet& pcs, const RotConstraints& c,
                                               const Mat3& R, double h, int n, double dependent) {
  std::vector<std::vector<Mat3>> paths;
  Eigen::VectorXd r;
  Eigen::MatrixXd J;
  if (!consistency_rows(A, B, pcs, c, R, dependent, r, &J)) return paths;
  const Vec3 t0 = consistent_tangent(J);
  for (double sg : {1.0, -1.0}) {
    std::vector<Mat3> path;
    Mat3 Q = R;
    Vec3 dir = sg * t0;
    for (int k = 0; k < n; ++k) {
      Mat3 next = axis_angle(dir, h) * Q;
      if (!project_consistent(A, B, pcs, c, next, dependent) ||
          !consistency_rows(A, B, pcs, c, next, dependent, r, &J))
        break;
      Vec3 t = consistent_tangent(J);
      dir = t.dot(dir) < 0 ? Vec3(-t) : t;  // keep going the same way
      path.push_back(next);
      Q = next;
    }
    paths.push_back(std::move(path));
  }
  return paths;
}

}  // namespace cf::gen::internal
