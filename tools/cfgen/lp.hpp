#pragma once
// Small linear programs for the witness search (translation with the largest margin).

#include <Eigen/Core>

#include <utility>
#include <vector>

namespace cf::gen {

/// minimise c.x subject to rows (a_i . x  REL_i  b_i) and per-variable bounds.
struct LinearProgram {
  enum class Rel { kLessEq, kEq, kGreaterEq };
  struct Row {
    std::vector<std::pair<int, double>> a;  // sparse coefficients (variable, value)
    Rel rel;
    double b;
  };
  int num_vars = 0;
  std::vector<Row> rows;
  std::vector<double> c;                  // objective, size num_vars
  std::vector<std::pair<bool, double>> lower, upper;  // (finite?, value) per variable

  explicit LinearProgram(int n)
      : num_vars(n), c(n, 0.0), lower(n, {false, 0.0}), upper(n, {false, 0.0}) {}
  void add(std::vector<std::pair<int, double>> a, Rel rel, double b) {
    rows.push_back({std::move(a), rel, b});
  }
};

struct LpResult {
  enum class Status { kOptimal, kInfeasible, kUnbounded } status = Status::kInfeasible;
  Eigen::VectorXd x;  // the optimum, rounded to double from the exact solution
};

/// Solves in double precision: a small dense simplex first, GLPK's primal simplex for what it
/// leaves (lp.cpp says why). Exactness is not needed here: every pose built from a solution
/// is verified on its own before it is accepted, and every solution meets each row within
/// 1e-7 (1 + |b|).
LpResult solve(const LinearProgram& lp);

namespace internal {
/// The dense solver alone (for its tests): kOptimal with a solution, or kInfeasible meaning
/// "not solved here", whatever the program's true status.
LpResult dense_solve(const LinearProgram& lp);
/// GLPK's primal simplex alone (for the tests' reference): its status and solution, the
/// solution checked against every row.
LpResult glpk_solve(const LinearProgram& lp);
}  // namespace internal

}  // namespace cf::gen
