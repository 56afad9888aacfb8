#pragma once
// Small linear programs for the witness search (translation with the largest margin).

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <stdexcept>
#include <utility>
#include <vector>

namespace cf::gen {

/// minimise c.x subject to rows (a_i . x  REL_i  b_i) and per-variable bounds.
struct LinearProgram {
  /// At most this many variables: the witness search's programs have ten at most, thirteen
  /// with a turn's three (WitnessSearch::obstacle_step), and the solver keeps its work in
  /// fixed-size storage (no allocation per program).
  static constexpr int kMaxVars = 14;
  enum class Rel { kLessEq, kEq, kGreaterEq };
  /// A row's sparse coefficients (variable, value), stored inline: a program is built and
  /// solved some million times in a run, and a heap block per row was a tenth of its time.
  class Coefs {
   public:
    Coefs() = default;
    Coefs(std::initializer_list<std::pair<int, double>> a) {
      for (const auto& x : a) push_back(x);
    }
    Coefs(const std::vector<std::pair<int, double>>& a) {  // NOLINT: implicit on purpose
      for (const auto& x : a) push_back(x);
    }
    /// Throws std::length_error past kMaxVars entries.
    void push_back(const std::pair<int, double>& x) {
      if (n_ == kMaxVars)
        throw std::length_error("LinearProgram row with more than kMaxVars coefficients");
      v_[n_++] = x;
    }
    std::size_t size() const { return n_; }
    bool empty() const { return n_ == 0; }
    const std::pair<int, double>* begin() const { return v_.data(); }
    const std::pair<int, double>* end() const { return v_.data() + n_; }

   private:
    std::array<std::pair<int, double>, kMaxVars> v_{};
    std::size_t n_ = 0;
  };
  struct Row {
    Coefs a;
    Rel rel;
    double b;
  };
  int num_vars = 0;
  std::vector<Row> rows;
  std::vector<double> c;                              // objective, size num_vars
  std::vector<std::pair<bool, double>> lower, upper;  // (finite?, value) per variable

  /// Throws std::length_error when n > kMaxVars.
  explicit LinearProgram(int n)
      : num_vars(n), c(n, 0.0), lower(n, {false, 0.0}), upper(n, {false, 0.0}) {
    if (n > kMaxVars) throw std::length_error("LinearProgram with more than kMaxVars variables");
  }
  void add(const Coefs& a, Rel rel, double b) { rows.push_back({a, rel, b}); }
};

/// A program's variables, in fixed-size storage.
using LpVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, LinearProgram::kMaxVars, 1>;

struct LpResult {
  enum class Status { kOptimal, kInfeasible, kUnbounded } status = Status::kInfeasible;
  LpVector x;  // the optimum, size num_vars when kOptimal
};

/// Solves in double precision: a small dense simplex first, GLPK's primal simplex for what it
/// leaves (lp.cpp says why). Exactness is not needed here: every pose built from a solution
/// is verified on its own before it is accepted, and every solution meets each row within
/// 1e-7 (1 + |b|).
LpResult solve(const LinearProgram& lp);

/// A proof that a program has no solution (Farkas' lemma over a box): multipliers y >= 0, one
/// per row a_i . x <= b_i, with y . b < min over the variables' box of (A^T y) . x. Summing
/// the rows with these weights gives a row no point of the box meets.
struct FarkasCertificate {
  std::vector<double> y;  // per row, >= 0
  /// y . b - min over the box of (A^T y) . x, computed in double with the rounding bound
  /// below added: negative when the certificate holds.
  double gap = 0;
};

/// The multipliers of an infeasible program, read from the duals of its least-violation
/// program (min s subject to a_i . x - (1 + |b_i|) s <= b_i, GLPK's simplex); std::nullopt when
/// that program's optimum is not above 0 or its multipliers do not prove infeasibility once
/// rounding is accounted for (farkas_gap). The checker in tests/oracle rechecks a certificate
/// in exact arithmetic.
/// Preconditions: every row is Rel::kLessEq and every variable has finite lower and upper
/// bounds; @throws std::invalid_argument otherwise.
std::optional<FarkasCertificate> farkas(const LinearProgram& lp);

/// Fraction of the terms' magnitude a Farkas gap must clear (farkas_gap): rounding, and the
/// deviation of the rows an independent checker rebuilds from the models (lp.cpp).
constexpr double kFarkasMargin = 1e-10;

/// y . b - min over the box of (A^T y) . x plus kFarkasMargin of its terms' magnitude:
/// negative proves the program (kLessEq rows, finite bounds) has no solution, with a margin
/// over rounding and over rows rebuilt from the models by an independent checker.
/// Preconditions: y.size() == lp.rows.size(); @throws std::invalid_argument otherwise.
double farkas_gap(const LinearProgram& lp, const std::vector<double>& y);

namespace internal {
/// The dense solver alone (for its tests): kOptimal with a solution, or kInfeasible meaning
/// "not solved here", whatever the program's true status.
LpResult dense_solve(const LinearProgram& lp);
/// GLPK's primal simplex alone (for the tests' reference): its status and solution, the
/// solution checked against every row.
LpResult glpk_solve(const LinearProgram& lp);
}  // namespace internal

}  // namespace cf::gen
