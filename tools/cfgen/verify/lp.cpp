#include "cfgen/verify/lp.hpp"

#include <glpk.h>
#include <Eigen/Dense>

#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace cf::gen {

// The witness search solves millions of programs of at most ten variables (thirteen with a
// turn's three: LinearProgram::kMaxVars) and a few dozen rows; a general solver spends most
// of its time building and freeing its problem. This one is dense and small:
//  1. the equality rows are solved once, x = x0 + N z, leaving d <= 13 free coordinates z;
//  2. the rest, G z <= h (bounds included, rows scaled to unit length), is solved through its
//     dual, min h.y subject to G^T y = -c_z, y >= 0: a tableau of only d rows, pivoted by
//     Bland's rule, which cannot cycle on the degenerate vertices these programs are full of;
//  3. z is read from the rows of G the dual's optimal basis holds tight.
// Every solution is then checked against the original rows and bounds. What it does not solve
// is nearly always infeasible by far (a translation cut off by an obstacle), which a second
// dense program shows (surely_infeasible). The rest goes to GLPK: programs of touching poses
// are feasible only within GLPK's relative tolerances (margin 0, rows missed by 1e-6 on a
// right side of 40), and their answers steer the search. That is a few in a million.
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
constexpr int kMaxVars = LinearProgram::kMaxVars;
constexpr int kMaxEqs = 2 * kMaxVars;  // equality rows beyond this go to GLPK
// Storage for the variables' dimension lives in the objects themselves. The maxima are above
// Eigen's small-product threshold (8), so products pick the same kernels as for MatrixXd.
using VarMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxVars, kMaxVars>;
using VarVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxVars, 1>;
using EqMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxEqs, kMaxVars>;
using EqMatT = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxVars, kMaxEqs>;
using EqVec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxEqs, 1>;
using MatMap = Eigen::Map<MatrixXd>;
using RowMatMap =
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>;
using VecMap = Eigen::Map<VectorXd>;

// Per-thread storage for the matrices whose size follows the number of rows, grown and
// never freed: a run solves millions of programs.
struct Workspace {
  std::vector<double> G, h, Gz, hz, htol, At, hk, hk_tol, T, tol;
  std::vector<int> keep, basic, tight;
  std::vector<char> live;
  // The last equality system and its solution: the witness search solves runs of programs
  // with the same equalities (the same contacts at one rotation, other objectives or bounds).
  struct Equalities {
    bool set = false;
    bool consistent = false;
    EqMat E;
    EqVec f;
    VarVec x0;
    VarMat N;
    bool same(const EqMat& e, const EqVec& g) const {
      return set && e.rows() == E.rows() && e.cols() == E.cols() &&
             std::memcmp(e.data(), E.data(), sizeof(double) * static_cast<std::size_t>(e.size())) ==
                 0 &&
             std::memcmp(g.data(), f.data(), sizeof(double) * static_cast<std::size_t>(g.size())) ==
                 0;
    }
  } eq;
};

Workspace& workspace() {
  thread_local Workspace w;
  return w;
}

template <typename Map = MatMap>
Map as_matrix(std::vector<double>& buf, int rows, int cols) {
  const std::size_t need = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols);
  if (buf.size() < need) buf.resize(need);
  return Map(buf.data(), rows, cols);
}

VecMap as_vector(std::vector<double>& buf, int rows) {
  if (buf.size() < static_cast<std::size_t>(rows)) buf.resize(static_cast<std::size_t>(rows));
  return VecMap(buf.data(), rows);
}

// Tableau entries below this are zero. The programs' coefficients are unit directions, and a
// witness near a degenerate pose has entries of 1e-9 that are rounding of zero: pivoting on
// them multiplies the rounding by 1e9.
constexpr double kPivotTol = 1e-7;
// Reduced costs above -kCostTol (1 + |b|) are non-negative: a reduced cost of the dual is the
// slack of a primal row a.x <= b.
constexpr double kCostTol = 1e-9;
constexpr double kPhase1Tol = 1e-8;  // a dual residual above this: the dual has no solution
constexpr int kMaxPivots = 5000;     // Bland's rule terminates; this only guards rounding loops

enum class Dual { kOptimal, kInfeasible, kUnbounded };

// min h.y subject to A y = b, y >= 0, A of size d x m. On kOptimal, `basis` lists the basic
// columns (< m) of the rows that were not found redundant.
struct DualSimplex {
  int d, m;
  // d constraint rows, then the cost row; m columns, then the right side. Phase 1's
  // artificial columns are not stored: they never enter the basis and nothing reads them.
  RowMatMap T;
  std::vector<int>& basic;   // basic column of each row; m + i: row i's artificial (not stored)
  std::vector<char>& live;   // rows not removed as redundant
  std::vector<double>& tol;  // per column: reduced costs above -tol are non-negative

  DualSimplex(const MatMap& A, const VarVec& b, Workspace& w)
      : d(int(A.rows())),
        m(int(A.cols())),
        T(as_matrix<RowMatMap>(w.T, d + 1, m + 1)),
        basic(w.basic),
        live(w.live),
        tol(w.tol) {
    T.setZero();
    basic.resize(d);
    live.assign(d, 1);
    tol.assign(m, kCostTol);
    for (int i = 0; i < d; ++i) {
      const double s = b[i] < 0 ? -1.0 : 1.0;
      T.row(i).head(m) = s * A.row(i);
      T(i, m) = s * b[i];
      basic[i] = m + i;
    }
  }

  void pivot(int r, int c) {
    T.row(r) /= T(r, c);
    for (int i = 0; i <= d; ++i)
      if (i != r && T(i, c) != 0.0) T.row(i) -= T(i, c) * T.row(r);
    basic[r] = c;
  }

  // Runs the simplex on the cost row as it stands; columns >= `enter_limit` never enter.
  Dual run(int enter_limit) {
    for (int it = 0; it < kMaxPivots; ++it) {
      int c = -1;
      for (int j = 0; j < enter_limit; ++j)
        if (T(d, j) < -tol[j]) {
          c = j;
          break;
        }
      if (c < 0) return Dual::kOptimal;
      int r = -1;
      double best = 0.0;
      for (int i = 0; i < d; ++i) {
        if (!live[i] || T(i, c) <= kPivotTol) continue;
        const double ratio = T(i, m) / T(i, c);
        const double tie = 1e-12 * (1 + std::abs(best));
        if (r < 0 || ratio < best - tie) {
          best = ratio;
          r = i;
        } else if (ratio <= best + tie && basic[i] < basic[r]) {
          r = i;  // Bland: among ties, the smallest basic column leaves
        }
      }
      if (r < 0) return Dual::kUnbounded;
      pivot(r, c);
    }
    return Dual::kUnbounded;  // not reached in practice; treated as "no solution"
  }

  Dual solve(const VecMap& h, const VecMap& h_tol) {
    // Phase 1: minimise the sum of the artificials.
    T.row(d).setZero();
    for (int i = 0; i < d; ++i) T.row(d) -= T.row(i);
    run(m);
    if (-T(d, m) > kPhase1Tol) return Dual::kInfeasible;
    // Drive the artificials out of the basis; a row where none can leave is redundant.
    for (int i = 0; i < d; ++i) {
      if (basic[i] < m) continue;
      int c = -1;
      for (int j = 0; j < m && c < 0; ++j)
        if (std::abs(T(i, j)) > kPivotTol) c = j;
      if (c >= 0)
        pivot(i, c);
      else
        live[i] = 0;
    }
    // Phase 2: the true costs, reduced against the basis.
    for (int j = 0; j < m; ++j) tol[j] = h_tol[j];
    T.row(d).setZero();
    T.row(d).head(m) = h.transpose();
    for (int i = 0; i < d; ++i)
      if (live[i] && basic[i] < m) T.row(d) -= h[basic[i]] * T.row(i);
    return run(m);
  }
};

// Trust but verify: a solution that misses a row or a bound by more than 1e-7 (1 + |b|) is no
// solution.
template <typename Vec>
bool meets_rows(const LinearProgram& lp, const Vec& x) {
  using Rel = LinearProgram::Rel;
  for (const auto& r : lp.rows) {
    double v = 0;
    for (const auto& [j, a] : r.a) v += a * x[j];
    const double tol = 1e-7 * (1 + std::abs(r.b));
    const bool ok = r.rel == Rel::kEq       ? std::abs(v - r.b) <= tol
                    : r.rel == Rel::kLessEq ? v <= r.b + tol
                                            : v >= r.b - tol;
    if (!ok) return false;
  }
  for (int j = 0; j < lp.num_vars; ++j) {
    const auto [lf, lv] = lp.lower[j];
    const auto [uf, uv] = lp.upper[j];
    if ((lf && x[j] < lv - 1e-7 * (1 + std::abs(lv))) ||
        (uf && x[j] > uv + 1e-7 * (1 + std::abs(uv))))
      return false;
  }
  return true;
}

}  // namespace

LpResult internal::dense_solve(const LinearProgram& lp) {
  using Rel = LinearProgram::Rel;
  const int n = lp.num_vars;
  LpResult out;
  Workspace& w = workspace();

  // Split the rows and bounds into equalities E x = f and inequalities G x <= h.
  int ne = 0, ni = 0;
  for (const auto& r : lp.rows) (r.rel == Rel::kEq ? ne : ni) += 1;
  for (int j = 0; j < n; ++j) {
    const auto [lf, lv] = lp.lower[j];
    const auto [uf, uv] = lp.upper[j];
    if (lf && uf && lv == uv) {
      ++ne;
    } else {
      ni += int(lf) + int(uf);
    }
  }
  if (n > kMaxVars || ne > kMaxEqs) return out;  // not solved here
  EqMat E = EqMat::Zero(ne, n);
  EqVec f(ne);
  MatMap G = as_matrix(w.G, ni, n);
  G.setZero();
  VecMap h = as_vector(w.h, ni);
  int ie = 0, ii = 0;
  for (const auto& r : lp.rows) {
    if (r.rel == Rel::kEq) {
      for (const auto& [j, v] : r.a) E(ie, j) += v;
      f[ie++] = r.b;
    } else {
      const double s = r.rel == Rel::kLessEq ? 1.0 : -1.0;
      for (const auto& [j, v] : r.a) G(ii, j) += s * v;
      h[ii++] = s * r.b;
    }
  }
  for (int j = 0; j < n; ++j) {
    const auto [lf, lv] = lp.lower[j];
    const auto [uf, uv] = lp.upper[j];
    if (lf && uf && lv == uv) {
      E(ie, j) = 1.0;
      f[ie++] = lv;
      continue;
    }
    if (lf) G(ii, j) = -1.0, h[ii++] = -lv;
    if (uf) G(ii, j) = 1.0, h[ii++] = uv;
  }

  // 1. x = x0 + N z over the solutions of the equalities.
  VarVec x0 = VarVec::Zero(n);
  VarMat N = VarMat::Identity(n, n);
  if (ne > 0) {
    Workspace::Equalities& c = w.eq;
    if (!c.same(E, f)) {
      c.set = true;
      c.E = E;
      c.f = f;
      Eigen::CompleteOrthogonalDecomposition<EqMat> cod(E);
      cod.setThreshold(1e-12);
      c.x0 = cod.solve(f);
      c.consistent =
          (E * c.x0 - f).lpNorm<Eigen::Infinity>() <= kCostTol * (1 + f.lpNorm<Eigen::Infinity>());
      if (c.consistent) {
        // The null space of E: the columns of Q past E^T's rank, from E^T P = Q R.
        Eigen::ColPivHouseholderQR<EqMatT> qr(E.transpose());
        qr.setThreshold(1e-12);
        const VarMat Q = qr.householderQ();
        c.N = Q.rightCols(n - int(qr.rank()));
      }
    }
    if (!c.consistent) return out;  // inconsistent equalities
    x0 = c.x0;
    N = c.N;
  }
  const int d = int(N.cols());
  const VarVec cz = N.transpose() * Eigen::Map<const VectorXd>(lp.c.data(), n);
  MatMap Gz = as_matrix(w.Gz, ni, d);
  // Coefficient-wise: tens of rows by at most 12 columns, below where a blocked product pays.
  Gz.noalias() = G.lazyProduct(N);
  VecMap hz = as_vector(w.hz, ni);
  hz.noalias() = h - G * x0;
  // Unit rows; a row with no z in it is a fixed condition on x0.
  std::vector<int>& keep = w.keep;
  keep.clear();
  VecMap htol = as_vector(w.htol, ni);
  for (int i = 0; i < ni; ++i) {
    const double len = Gz.row(i).norm();
    if (len <= 1e-12) {
      if (hz[i] < -kCostTol * (1 + std::abs(h[i]))) return out;  // infeasible
      continue;
    }
    Gz.row(i) /= len;
    hz[i] /= len;
    htol[i] = kCostTol * (1 + std::abs(h[i])) / len;
    keep.push_back(i);
  }
  const int m = int(keep.size());

  VarVec z = VarVec::Zero(d);
  if (d > 0) {
    MatMap At = as_matrix(w.At, d, m);
    VecMap hk = as_vector(w.hk, m), hk_tol = as_vector(w.hk_tol, m);
    for (int k = 0; k < m; ++k) {
      At.col(k) = Gz.row(keep[k]).transpose();
      hk[k] = hz[keep[k]];
      hk_tol[k] = htol[keep[k]];
    }
    DualSimplex ds(At, -cz, w);
    const Dual st = ds.solve(hk, hk_tol);
    if (st != Dual::kOptimal) return out;  // infeasible or unbounded: GLPK decides
    // 3. The primal optimum makes the basic rows tight.
    std::vector<int>& tight = w.tight;
    tight.clear();
    for (int i = 0; i < d; ++i)
      if (ds.live[i] && ds.basic[i] < m) tight.push_back(ds.basic[i]);
    if (!tight.empty()) {
      VarMat Gt(tight.size(), d);
      VarVec ht(tight.size());
      for (std::size_t k = 0; k < tight.size(); ++k) {
        Gt.row(k) = At.col(tight[k]).transpose();
        ht[k] = hk[tight[k]];
      }
      z = Gt.completeOrthogonalDecomposition().solve(ht);
    }
  }
  out.x = x0 + N * z;

  if (meets_rows(lp, out.x)) out.status = LpResult::Status::kOptimal;
  return out;
}

LpResult internal::glpk_solve(const LinearProgram& lp) {
  glp_term_out(GLP_OFF);  // per thread; GLPK prints scaling reports otherwise
  glp_prob* P = glp_create_prob();
  glp_set_obj_dir(P, GLP_MIN);
  const int m = static_cast<int>(lp.rows.size());
  if (m > 0) glp_add_rows(P, m);
  glp_add_cols(P, lp.num_vars);
  for (int j = 0; j < lp.num_vars; ++j) {
    const auto [lf, lv] = lp.lower[j];
    const auto [uf, uv] = lp.upper[j];
    const int type = lf && uf ? (lv == uv ? GLP_FX : GLP_DB) : lf ? GLP_LO : uf ? GLP_UP : GLP_FR;
    glp_set_col_bnds(P, j + 1, type, lf ? lv : 0.0, uf ? uv : 0.0);
    glp_set_obj_coef(P, j + 1, lp.c[j]);
  }
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  for (int i = 0; i < m; ++i) {
    const auto& r = lp.rows[i];
    const int type = r.rel == LinearProgram::Rel::kEq       ? GLP_FX
                     : r.rel == LinearProgram::Rel::kLessEq ? GLP_UP
                                                            : GLP_LO;
    glp_set_row_bnds(P, i + 1, type, r.b, r.b);
    for (const auto& [j, v] : r.a) {
      if (v == 0.0) continue;
      ia.push_back(i + 1);
      ja.push_back(j + 1);
      ar.push_back(v);
    }
  }
  glp_load_matrix(P, static_cast<int>(ar.size()) - 1, ia.data(), ja.data(), ar.data());
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.it_lim = 2000;  // tiny programs; a run this long means cycling on a degenerate vertex
  // No glp_scale_prob: the rows are already unit-scaled (directions, mm).
  LpResult out;
  if (glp_simplex(P, &parm) == 0) {
    const int st = glp_get_status(P);
    if (st == GLP_OPT) {
      out.status = LpResult::Status::kOptimal;
      out.x.resize(lp.num_vars);
      for (int j = 0; j < lp.num_vars; ++j) out.x[j] = glp_get_col_prim(P, j + 1);
      if (!meets_rows(lp, out.x)) out.status = LpResult::Status::kInfeasible;
    } else if (st == GLP_UNBND) {
      out.status = LpResult::Status::kUnbounded;
    }
  }
  glp_delete_prob(P);
  return out;
}

namespace {

// True when every x misses some row or bound of lp by far more than the 1e-7 (1 + |b|) that
// meets_rows allows, so that GLPK could return no solution either: the least violation s of
// the rows a.x <= b + (1 + |b|) s, over x and s >= -1, is above kSureViolation. Nearly every
// program the dense solver leaves is infeasible by far, and this program of one more variable
// costs a fraction of GLPK's set-up. False when it cannot tell.
bool surely_infeasible(const LinearProgram& lp) {
  // A hundred times meets_rows' tolerance: the dense solver's optimum is within its reduced
  // cost tolerance (1e-9) of the least violation.
  constexpr double kSureViolation = 1e-5;
  using Rel = LinearProgram::Rel;
  const int n = lp.num_vars, s = n;
  if (n + 1 > LinearProgram::kMaxVars) return false;
  // Per thread and reused, as the dense solver's buffers: no allocation per program.
  thread_local LinearProgram rl(0);
  rl.num_vars = n + 1;
  rl.c.assign(static_cast<std::size_t>(n + 1), 0.0);
  rl.lower.assign(static_cast<std::size_t>(n + 1), {false, 0.0});
  rl.upper.assign(static_cast<std::size_t>(n + 1), {false, 0.0});
  rl.rows.clear();
  rl.c[s] = 1.0;
  rl.lower[s] = {true, -1.0};
  auto add = [&](const LinearProgram::Coefs& a, double sign, double b) {
    // sign (a.x) - (1 + |b|) s <= sign b
    LinearProgram::Coefs row;
    for (const auto& [j, v] : a) row.push_back({j, sign * v});
    row.push_back({s, -(1 + std::abs(b))});
    rl.add(row, Rel::kLessEq, sign * b);
  };
  for (const auto& r : lp.rows) {
    if (r.a.size() + 1 > static_cast<std::size_t>(LinearProgram::kMaxVars)) return false;
    if (r.rel != Rel::kGreaterEq) add(r.a, 1.0, r.b);
    if (r.rel != Rel::kLessEq) add(r.a, -1.0, r.b);
  }
  for (int j = 0; j < n; ++j) {
    if (lp.lower[j].first) add({{j, 1.0}}, -1.0, lp.lower[j].second);
    if (lp.upper[j].first) add({{j, 1.0}}, 1.0, lp.upper[j].second);
  }
  const LpResult r = internal::dense_solve(rl);
  return r.status == LpResult::Status::kOptimal && r.x[s] > kSureViolation;
}

}  // namespace

LpResult solve(const LinearProgram& lp) {
  LpResult r = internal::dense_solve(lp);
  if (r.status == LpResult::Status::kOptimal || surely_infeasible(lp)) return r;
  return internal::glpk_solve(lp);
}

}  // namespace cf::gen

namespace cf::gen {
namespace {

void require_box_form(const LinearProgram& lp) {
  for (const auto& r : lp.rows)
    if (r.rel != LinearProgram::Rel::kLessEq)
      throw std::invalid_argument("farkas: a row that is not a.x <= b");
  for (int j = 0; j < lp.num_vars; ++j)
    if (!lp.lower[j].first || !lp.upper[j].first || !std::isfinite(lp.lower[j].second) ||
        !std::isfinite(lp.upper[j].second))
      throw std::invalid_argument("farkas: variable " + std::to_string(j) +
                                  " without finite bounds");
}

}  // namespace

double farkas_gap(const LinearProgram& lp, const std::vector<double>& y) {
  require_box_form(lp);
  if (y.size() != lp.rows.size())
    throw std::invalid_argument("farkas_gap: " + std::to_string(y.size()) + " multipliers for " +
                                std::to_string(lp.rows.size()) + " rows");
  std::vector<double> r(static_cast<std::size_t>(lp.num_vars), 0.0);
  double gap = 0, size = 0;  // size: sum of the magnitudes of every term, for the rounding bound
  for (std::size_t i = 0; i < y.size(); ++i) {
    if (!(y[i] >= 0)) return std::numeric_limits<double>::infinity();
    gap += y[i] * lp.rows[i].b;
    size += y[i] * std::abs(lp.rows[i].b);
    for (const auto& [j, v] : lp.rows[i].a) {
      r[static_cast<std::size_t>(j)] += y[i] * v;
      size +=
          y[i] * std::abs(v) * std::max(std::abs(lp.lower[j].second), std::abs(lp.upper[j].second));
    }
  }
  for (int j = 0; j < lp.num_vars; ++j)
    gap -= std::min(r[j] * lp.lower[j].second, r[j] * lp.upper[j].second);
  // Each term is rounded a few times and each sum adds at most (number of terms) units of
  // roundoff of its largest partial sum: 1e-12 of the terms' magnitude would cover that. The
  // margin is 1e-10: a certificate is rechecked on rows rebuilt from the models, each widened
  // by how far the face frames it was given lie from the faces' vertices (the models'
  // planarity), and a refutation by less than that is not one the checker can accept (oracle
  // seed 7402 had one short by 9.4e-11 mm at 1e-12). Such a cell stays open and is split.
  return gap + kFarkasMargin * size;
}

std::optional<FarkasCertificate> farkas(const LinearProgram& lp) {
  require_box_form(lp);
  glp_term_out(GLP_OFF);
  glp_prob* P = glp_create_prob();
  glp_set_obj_dir(P, GLP_MIN);
  const int m = static_cast<int>(lp.rows.size()), n = lp.num_vars;
  if (m > 0) glp_add_rows(P, m);
  glp_add_cols(P, n + 1);
  for (int j = 0; j < n; ++j) {
    const double lo = lp.lower[j].second, hi = lp.upper[j].second;
    glp_set_col_bnds(P, j + 1, lo == hi ? GLP_FX : GLP_DB, lo, hi);
  }
  glp_set_col_bnds(P, n + 1, GLP_LO, -1.0, 0.0);  // s, the least violation
  glp_set_obj_coef(P, n + 1, 1.0);
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  for (int i = 0; i < m; ++i) {
    const auto& row = lp.rows[static_cast<std::size_t>(i)];
    glp_set_row_bnds(P, i + 1, GLP_UP, 0.0, row.b);
    for (const auto& [j, v] : row.a) {
      if (v == 0.0) continue;
      ia.push_back(i + 1);
      ja.push_back(j + 1);
      ar.push_back(v);
    }
    ia.push_back(i + 1);
    ja.push_back(n + 1);
    ar.push_back(-(1 + std::abs(row.b)));
  }
  glp_load_matrix(P, static_cast<int>(ar.size()) - 1, ia.data(), ja.data(), ar.data());
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.it_lim = 5000;
  std::optional<FarkasCertificate> out;
  if (glp_simplex(P, &parm) == 0 && glp_get_status(P) == GLP_OPT && glp_get_obj_val(P) > 0) {
    FarkasCertificate c;
    c.y.resize(static_cast<std::size_t>(m));
    // A row's dual is the objective's rate as its right side grows: <= 0 for a binding a.x <= b
    // of a minimisation; its negation is the row's weight.
    for (int i = 0; i < m; ++i)
      c.y[static_cast<std::size_t>(i)] = std::max(0.0, -glp_get_row_dual(P, i + 1));
    c.gap = farkas_gap(lp, c.y);
    if (c.gap < 0) out = std::move(c);
  }
  glp_delete_prob(P);
  return out;
}

}  // namespace cf::gen
