#include "lp.hpp"

#include <glpk.h>

#include <cmath>

namespace cf::gen {

LpResult solve(const LinearProgram& lp) {
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
    const int type = r.rel == LinearProgram::Rel::kEq        ? GLP_FX
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
      // Trust but verify: a solution that misses a row is no solution.
      for (int i = 0; i < m && out.status == LpResult::Status::kOptimal; ++i) {
        const auto& r = lp.rows[i];
        double v = 0;
        for (const auto& [j, a] : r.a) v += a * out.x[j];
        const double tol = 1e-7 * (1 + std::abs(r.b));
        const bool ok = r.rel == LinearProgram::Rel::kEq       ? std::abs(v - r.b) <= tol
                        : r.rel == LinearProgram::Rel::kLessEq ? v <= r.b + tol
                                                               : v >= r.b - tol;
        if (!ok) out.status = LpResult::Status::kInfeasible;
      }
    } else if (st == GLP_UNBND) {
      out.status = LpResult::Status::kUnbounded;
    }
  }
  glp_delete_prob(P);
  return out;
}

}  // namespace cf::gen
