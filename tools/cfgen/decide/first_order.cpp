#include "cfgen/decide/first_order.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace cf::gen {
namespace {

// The rows of one program. A term (R x) . y with R = R_c Q is (Q x) . y', y' = R_c^T y,
// = x . y' + v . (x cross y') + E(x) . y': alpha = x . y', beta = x cross y', and a
// remainder of at most gamma |x| |y|.
class Rows {
 public:
  Rows(const Mat3& R_c, double theta_max, LinearProgram& lp)
      : Rt_(R_c.transpose()), rho_(std::sin(theta_max)), gamma_(1 - std::cos(theta_max)), lp_(lp) {
    for (int k = 0; k < 3; ++k) {
      lp_.lower[static_cast<std::size_t>(k)] = {true, -rho_};
      lp_.upper[static_cast<std::size_t>(k)] = {true, rho_};
    }
  }
  double rho() const { return rho_; }
  double gamma() const { return gamma_; }
  const Mat3& Rt() const { return Rt_; }

  // alpha + beta . v + rem >= thr, as -beta . v <= alpha + rem - thr.
  void at_least(const Vec3& beta, double alpha, double rem, double thr) {
    lp_.add({{0, -beta.x()}, {1, -beta.y()}, {2, -beta.z()}}, LinearProgram::Rel::kLessEq,
            alpha + rem - thr);
  }
  // (R x) . y >= thr.
  void turned_at_least(const Vec3& x, const Vec3& y, double thr) {
    const Vec3 yp = Rt_ * y;
    at_least(x.cross(yp), x.dot(yp), gamma_ * x.norm() * y.norm(), thr);
  }
  // |(R x) . y| <= tol: both sides.
  void turned_within(const Vec3& x, const Vec3& y, double tol) {
    const Vec3 yp = Rt_ * y;
    const Vec3 beta = x.cross(yp);
    const double alpha = x.dot(yp), rem = gamma_ * x.norm() * y.norm();
    at_least(beta, alpha, rem, -tol);    // alpha + beta . v >= -tol - rem
    at_least(-beta, -alpha, rem, -tol);  // alpha + beta . v <= tol + rem
  }

 private:
  Mat3 Rt_;
  double rho_, gamma_;
  LinearProgram& lp_;
};

// An e-e with its normal's sign: N = sign c / |c|, c = (R a) x b = R_c c', c' = (Q a) x b'
// = m + (a (v . b') - v (a . b')) + E(a) x b', m = a x b'. Each wedge term t / |c'| >= slack
// needs t >= slack |c'| >= slack (|m| - rho - gamma). B's terms -sign w' . c' (w' = R_c^T w)
// are affine in v up to gamma; A's, sign (Q w) . c', up to the products of the turn's
// first-order parts and its remainders.
void ee_rows(const ModelInfo& A, const ModelInfo& B, const Pc& pc, double sign, double slack,
             Rows& rows) {
  const Vec3& a = A.model->edges()[static_cast<std::size_t>(pc.a)].dir;
  const Vec3 bp = rows.Rt() * B.model->edges()[static_cast<std::size_t>(pc.b)].dir;
  const Vec3 m = a.cross(bp);
  const double rho = rows.rho(), gamma = rows.gamma(), ab = a.dot(bp);
  const double thr = slack * std::max(0.0, m.norm() - rho - gamma);
  const EdgeWedge& wb = B.wedges[static_cast<std::size_t>(pc.b)];
  for (const Vec3& w : {wb.into_left, wb.into_right}) {
    const Vec3 wp = rows.Rt() * w;
    rows.at_least(sign * (ab * wp - wp.dot(a) * bp), -sign * wp.dot(m), gamma, thr);
  }
  const double rem_a = 2 * gamma + rho * rho + 2 * rho * gamma + gamma * gamma;
  const EdgeWedge& wa = A.wedges[static_cast<std::size_t>(pc.a)];
  for (const Vec3& w : {wa.into_left, wa.into_right})
    rows.at_least(sign * (w.dot(a) * bp - ab * w + w.cross(m)), sign * w.dot(m), rem_a, thr);
}

// The rows of every PC but the e-e ones (ee_rows) and the f-f ones (not tested).
void pc_rows(const ModelInfo& A, const ModelInfo& B, const Pc& pc, double slack, double rot_tol,
             Rows& rows) {
  const Polyhedron& mA = *A.model;
  const Polyhedron& mB = *B.model;
  const auto ia = static_cast<std::size_t>(pc.a), ib = static_cast<std::size_t>(pc.b);
  switch (pc.type) {
    // A vertex's edge rays, as the analysis lists them: in the order of the vertex's edges,
    // ascending edge index (the order the certificate file's rows follow).
    case PcType::kVF:
      for (const Vec3& d : A.cones[ia].rays) rows.turned_at_least(d, mB.faces()[ib].normal, slack);
      break;
    case PcType::kFV:
      for (const Vec3& d : B.cones[ib].rays) rows.turned_at_least(mA.faces()[ia].normal, d, slack);
      break;
    case PcType::kEF:
      for (const Vec3& w : {A.wedges[ia].into_left, A.wedges[ia].into_right})
        rows.turned_at_least(w, mB.faces()[ib].normal, slack);
      rows.turned_within(mA.edges()[ia].dir, mB.faces()[ib].normal, rot_tol);
      break;
    case PcType::kFE:
      for (const Vec3& w : {B.wedges[ib].into_left, B.wedges[ib].into_right})
        rows.turned_at_least(mA.faces()[ia].normal, w, slack);
      rows.turned_within(mA.faces()[ia].normal, mB.edges()[ib].dir, rot_tol);
      break;
    case PcType::kEE:
    case PcType::kFF:
      break;
  }
}

// Multipliers on one or two rows that prove the program (rows -beta . v <= b over the box
// |v_k| <= rho) infeasible: y . b + rho |sum y_i beta_i|_1 < 0, checked by farkas_gap. The
// sum is piecewise linear in the pair's weight t, so its least value is at an end or where a
// coordinate of t beta_i + (1 - t) beta_j changes sign. Most cubes the test refutes are
// refuted by one or two terms that turn apart; the rest go to farkas().
std::optional<FarkasCertificate> pair_proof(const LinearProgram& lp) {
  const std::size_t n = lp.rows.size();
  std::vector<Vec3> beta(n);
  for (std::size_t i = 0; i < n; ++i)
    for (const auto& [j, coef] : lp.rows[i].a) beta[i][j] = -coef;
  const double rho = lp.upper[0].second;
  auto value = [&](std::size_t i, std::size_t j, double t) {
    return t * lp.rows[i].b + (1 - t) * lp.rows[j].b +
           rho * (t * beta[i] + (1 - t) * beta[j]).lpNorm<1>();
  };
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i; j < n; ++j) {
      double best_t = 1, best = value(i, j, 1);
      auto take = [&](double t) {
        if (t >= 0 && t <= 1 && value(i, j, t) < best) best = value(i, j, best_t = t);
      };
      take(0);
      for (int k = 0; k < 3; ++k)
        if (const double d = beta[i][k] - beta[j][k]; d != 0) take(-beta[j][k] / d);
      if (!(best < 0)) continue;
      std::vector<double> y(n, 0.0);
      y[i] += best_t;
      y[j] += 1 - best_t;
      const double gap = farkas_gap(lp, y);
      if (gap < 0) return FarkasCertificate{std::move(y), gap};
    }
  return std::nullopt;
}

}  // namespace

std::vector<int> first_order_signs(const PcSet& pcs, std::size_t choice) {
  std::vector<int> out;
  for (const Pc& pc : pcs)
    if (pc.type == PcType::kEE) {
      out.push_back((choice & 1) ? -1 : 1);
      choice >>= 1;
    }
  return out;
}

std::vector<LinearProgram> first_order_programs(const ModelInfo& a, const ModelInfo& b,
                                                const PcSet& pcs, const Mat3& R_c, double theta_max,
                                                double slack, double rot_tol) {
  constexpr double kLargestTurn = M_PI / 4;  // beyond, the remainders swamp the terms
  if (!(theta_max < kLargestTurn)) return {};
  std::vector<int> ee;
  for (int k = 0; k < pcs.size(); ++k) {
    if (pcs[k].type == PcType::kFF) return {};
    if (pcs[k].type == PcType::kEE) ee.push_back(k);
  }
  std::vector<LinearProgram> out;
  for (std::size_t choice = 0; choice < (std::size_t{1} << ee.size()); ++choice) {
    LinearProgram lp(3);
    Rows rows(R_c, theta_max, lp);
    const std::vector<int> signs = first_order_signs(pcs, choice);
    for (int k = 0, e = 0; k < pcs.size(); ++k) {
      if (pcs[k].type == PcType::kEE)
        ee_rows(a, b, pcs[k], signs[static_cast<std::size_t>(e++)], slack, rows);
      else
        pc_rows(a, b, pcs[k], slack, rot_tol, rows);
    }
    out.push_back(std::move(lp));
  }
  return out;
}

bool first_order_refutes(const ModelInfo& a, const ModelInfo& b, const PcSet& pcs, const Mat3& R_c,
                         double theta_max, double slack, double rot_tol,
                         std::vector<FarkasCertificate>* proofs) {
  const std::vector<LinearProgram> programs =
      first_order_programs(a, b, pcs, R_c, theta_max, slack, rot_tol);
  if (programs.empty()) return false;
  std::vector<FarkasCertificate> found;
  for (const LinearProgram& lp : programs) {
    std::optional<FarkasCertificate> proof = pair_proof(lp);
    if (!proof && solve(lp).status == LpResult::Status::kOptimal) return false;
    if (!proof) proof = farkas(lp);
    if (!proof) return false;
    found.push_back(std::move(*proof));
  }
  if (proofs) *proofs = std::move(found);
  return true;
}

}  // namespace cf::gen
