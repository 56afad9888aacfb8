// The witness search's small LP solver (tools/cfgen/verify/lp.cpp: a dense simplex, GLPK for what
// it leaves) against GLPK's primal simplex alone, a solver written apart from the dense one, on
// random programs of the witness search's shapes: up to ten variables, equality rows, bounds,
// and degenerate vertices where many rows meet.
#include <catch2/catch.hpp>

#include <limits>
#include <random>

#include "cfgen/verify/lp.hpp"

using cf::gen::LinearProgram;
using cf::gen::LpResult;
using Rel = LinearProgram::Rel;
using Status = LpResult::Status;

namespace {

// GLPK's answer, the reference: its status, and its objective when optimal.
struct Reference {
  Status status;
  double objective;
};

double objective(const LinearProgram& lp, const LpResult& r) {
  double v = 0;
  for (int j = 0; j < lp.num_vars; ++j) v += lp.c[j] * r.x[j];
  return v;
}

Reference glpk_solve(const LinearProgram& lp) {
  const LpResult r = cf::gen::internal::glpk_solve(lp);
  return {r.status, r.status == Status::kOptimal ? objective(lp, r) : 0.0};
}

// A feasible program: its rows pass through or near a random point x, every third one through
// one vertex v beside it (a degenerate vertex); bounded in a box around x, or only partly
// (then sometimes unbounded).
LinearProgram random_program(std::mt19937& rng, bool& bounded_box) {
  std::uniform_int_distribution<int> nvars(2, 10);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = nvars(rng);
  LinearProgram lp(n);
  Eigen::VectorXd x(n);
  for (int j = 0; j < n; ++j) x[j] = 20 * u(rng);
  const int neq = std::uniform_int_distribution<int>(0, std::min(3, n - 1))(rng);
  for (int k = 0; k < neq; ++k) {
    std::vector<std::pair<int, double>> a;
    double b = 0;
    for (int j = 0; j < n; ++j)
      if (u(rng) > -0.2) {
        const double v = u(rng);
        a.push_back({j, v});
        b += v * x[j];
      }
    if (!a.empty()) lp.add(a, Rel::kEq, b);
  }
  if (!lp.rows.empty() && u(rng) > 0.5) {
    const LinearProgram::Row repeated = lp.rows.front();
    lp.rows.push_back(repeated);
  }
  // A degenerate vertex: several rows through one point v, and slack rows around x.
  Eigen::VectorXd v = x;
  for (int j = 0; j < n; ++j) v[j] += 5 * u(rng);
  const int nin = std::uniform_int_distribution<int>(n, 3 * n + 6)(rng);
  for (int k = 0; k < nin; ++k) {
    std::vector<std::pair<int, double>> a;
    double at_x = 0, at_v = 0;
    for (int j = 0; j < n; ++j) {
      const double c = u(rng);
      a.push_back({j, c});
      at_x += c * x[j];
      at_v += c * v[j];
    }
    const bool through_v = k % 3 == 0 && at_v >= at_x;  // keeps x feasible
    lp.add(a, Rel::kLessEq, through_v ? at_v : at_x + 10 * (u(rng) + 1.0));
  }
  bounded_box = u(rng) > -0.5;
  for (int j = 0; j < n; ++j) {
    if (bounded_box || u(rng) > 0) lp.lower[j] = {true, x[j] - 30};
    if (bounded_box || u(rng) > 0) lp.upper[j] = {true, x[j] + 30};
    lp.c[j] = u(rng) > 0.3 ? u(rng) : 0.0;  // zero costs: faces of optima
  }
  return lp;
}

}  // namespace

TEST_CASE("lp: matches GLPK's optimum on random programs with degenerate vertices", "[lp]") {
  std::mt19937 rng(20261202);
  int optimal = 0, unbounded = 0, dense_answered = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    bool box = false;
    const LinearProgram lp = random_program(rng, box);
    const Reference ref = glpk_solve(lp);
    const LpResult got = cf::gen::solve(lp);
    const LpResult dense = cf::gen::internal::dense_solve(lp);
    INFO("trial " << trial << ", " << lp.num_vars << " variables, " << lp.rows.size() << " rows");
    REQUIRE(ref.status != Status::kInfeasible);  // x is feasible by construction
    REQUIRE(got.status == ref.status);
    // The dense solver answers only with an optimum, never with an unbounded program's.
    if (ref.status == Status::kUnbounded) CHECK(dense.status != Status::kOptimal);
    if (got.status == Status::kOptimal) {
      ++optimal;
      // Objective agreement: both solvers work in double precision on rows of unit size
      // and right sides up to ~100; 1e-6 relative is far above their rounding.
      const double tol = 1e-6 * (1 + std::abs(ref.objective));
      CHECK(objective(lp, got) == Approx(ref.objective).margin(tol));
      if (dense.status == Status::kOptimal) {
        ++dense_answered;
        CHECK(objective(lp, dense) == Approx(ref.objective).margin(tol));
      }
    } else {
      ++unbounded;
    }
  }
  CHECK(optimal > 2000);
  CHECK(unbounded > 10);  // 19 with this seed
  // GLPK is the fallback for marginal programs only; random ones are not marginal.
  CHECK(dense_answered == optimal);
}

TEST_CASE("lp: infeasible programs are reported infeasible", "[lp]") {
  SECTION("contradicting rows") {
    LinearProgram lp(2);
    lp.add({{0, 1.0}, {1, 1.0}}, Rel::kLessEq, 1.0);
    lp.add({{0, 1.0}, {1, 1.0}}, Rel::kGreaterEq, 2.0);
    CHECK(cf::gen::solve(lp).status == Status::kInfeasible);
    CHECK(cf::gen::internal::dense_solve(lp).status == Status::kInfeasible);
  }
  SECTION("inconsistent equalities") {
    LinearProgram lp(3);
    lp.add({{0, 1.0}, {1, 2.0}}, Rel::kEq, 1.0);
    lp.add({{0, 2.0}, {1, 4.0}}, Rel::kEq, 3.0);
    CHECK(cf::gen::solve(lp).status == Status::kInfeasible);
    CHECK(cf::gen::internal::dense_solve(lp).status == Status::kInfeasible);
  }
  SECTION("an equality outside a bound") {
    LinearProgram lp(2);
    lp.upper[0] = {true, 1.0};
    lp.add({{0, 1.0}}, Rel::kEq, 2.0);
    CHECK(cf::gen::solve(lp).status == Status::kInfeasible);
    CHECK(cf::gen::internal::dense_solve(lp).status == Status::kInfeasible);
  }
}

TEST_CASE("lp: a program the dense solver leaves is infeasible only beyond the rows' tolerance",
          "[lp]") {
  // x <= 1 and x >= 1 + gap: solutions may miss a row by 1e-7 (1 + |b|), 2e-7 here. The dense
  // solver settles neither; a gap inside the tolerance is GLPK's to solve, one a thousand
  // times wider (beyond the check for programs infeasible by far, 1e-5) is infeasible.
  auto program = [](double gap) {
    LinearProgram lp(2);
    lp.add({{0, 1.0}}, Rel::kLessEq, 1.0);
    lp.add({{0, 1.0}}, Rel::kGreaterEq, 1.0 + gap);
    lp.add({{1, 1.0}, {0, -1.0}}, Rel::kLessEq, 0.0);
    lp.c[1] = -1.0;
    return lp;
  };
  const LinearProgram inside = program(5e-8);
  CHECK(cf::gen::internal::dense_solve(inside).status == Status::kInfeasible);
  const LpResult r = cf::gen::solve(inside);
  REQUIRE(r.status == Status::kOptimal);
  CHECK(r.x[0] == Approx(1.0).margin(2e-7));
  CHECK(r.x[1] == Approx(1.0).margin(2e-7));
  CHECK(cf::gen::solve(program(5e-5)).status != Status::kOptimal);
  CHECK(cf::gen::solve(program(5e-4)).status != Status::kOptimal);
}

TEST_CASE("lp: a vertex where many rows meet, and fixed variables", "[lp]") {
  // max s subject to s <= x_i for the 3 coordinates and sum x = 3, s in [0, 10]: the optimum
  // x = (1, 1, 1), s = 1 lies on four rows at once.
  LinearProgram lp(4);
  for (int i = 0; i < 3; ++i) lp.add({{i, 1.0}, {3, -1.0}}, Rel::kGreaterEq, 0.0);
  lp.add({{0, 1.0}, {1, 1.0}, {2, 1.0}}, Rel::kEq, 3.0);
  lp.add({{0, 1.0}, {1, 1.0}, {2, 1.0}}, Rel::kEq, 3.0);  // repeated
  lp.lower[3] = {true, 0.0};
  lp.upper[3] = {true, 10.0};
  lp.c[3] = -1.0;
  const LpResult r = cf::gen::internal::dense_solve(lp);
  REQUIRE(r.status == Status::kOptimal);
  CHECK(r.x[3] == Approx(1.0).margin(1e-12));
  for (int i = 0; i < 3; ++i) CHECK(r.x[i] == Approx(1.0).margin(1e-12));

  lp.lower[0] = lp.upper[0] = {true, 0.5};  // fixed: now s <= 0.5
  const LpResult f = cf::gen::internal::dense_solve(lp);
  REQUIRE(f.status == Status::kOptimal);
  CHECK(f.x[0] == Approx(0.5).margin(1e-12));
  CHECK(f.x[3] == Approx(0.5).margin(1e-12));
}

TEST_CASE("lp: a touching pose's program, feasible only within tolerance, is solved", "[lp]") {
  // Written by the witness search for a peg touching a hole's wall (the largest margin of two
  // contacts at one rotation): the rows meet only at margin 0, and only up to rounding of
  // 1e-6 on right sides of 35. GLPK's relative tolerance accepts it, and so must solve().
  LinearProgram lp(8);
  lp.c[3] = -1;
  lp.lower[3] = {true, 0};
  lp.upper[3] = {true, 164.92422502470643};
  lp.add({{2, -1}, {4, 7.2164496600635175e-16}}, Rel::kEq, 15.000000612127661);
  lp.add({{0, -0.70710678118654746}, {1, 0.70710678118654746}, {4, -0.70710681004252163}},
         Rel::kGreaterEq, -21.213203002756799);
  lp.add({{0, 1}, {4, 0.99999999999999956}, {3, -1}}, Rel::kGreaterEq, 14.999999387872354);
  lp.add({{1, -1}, {4, 4.0808510459733327e-08}, {3, -1}}, Rel::kGreaterEq, -65.000000000000028);
  lp.add({{0, -1}, {4, -0.99999999999999956}, {3, -1}}, Rel::kGreaterEq, -34.99999938787235);
  lp.add({{4, 1}, {3, -1}}, Rel::kGreaterEq, 0);
  lp.add({{4, 1}, {3, 1}}, Rel::kLessEq, 30);
  lp.add({{0, 1.1379786002407855e-15},
          {1, 4.0808510431977751e-08},
          {2, -0.99999999999999956},
          {5, 1.1379786002407855e-15}},
         Rel::kEq, 15.000000816170346);
  lp.add({{0, -0.99999999999999956},
          {1, 4.0808510459733327e-08},
          {2, 7.2164496600635175e-16},
          {5, -0.99999999999999956},
          {3, -1}},
         Rel::kGreaterEq, -134.99999918382974);
  lp.add({{0, -4.0808510459733327e-08},
          {1, -0.99999999999999845},
          {2, -4.0808510459733327e-08},
          {5, -4.0808510459733327e-08},
          {3, -1}},
         Rel::kGreaterEq, -35.000004897021228);
  lp.add({{0, 0.99999999999999956},
          {1, -4.0808510459733327e-08},
          {2, -7.2164496600635175e-16},
          {5, 0.99999999999999956},
          {3, -1}},
         Rel::kGreaterEq, 104.99999918382973);
  lp.add({{0, 4.0808510459733327e-08},
          {1, 0.99999999999999845},
          {2, 4.0808510459733327e-08},
          {5, 4.0808510459733327e-08},
          {3, -1}},
         Rel::kGreaterEq, 5.0000048970212241);
  lp.add({{5, 1}, {3, -1}}, Rel::kGreaterEq, 0);
  lp.add({{5, 1}, {3, 1}}, Rel::kLessEq, 100);
  lp.add({{0, 1}, {6, -4.0808510459733327e-08}}, Rel::kEq, 34.99999938787235);
  lp.add({{1, 1}, {6, -0.99999999999999845}, {7, -1}}, Rel::kEq, 5.0000000000000231);
  lp.add({{2, 1}, {6, -4.0808510459733327e-08}}, Rel::kEq, -15.000000612127661);
  lp.add({{6, 1}, {3, -1}}, Rel::kGreaterEq, 0);
  lp.add({{6, 1}, {3, 1}}, Rel::kLessEq, 30);
  lp.add({{7, 1}, {3, -1}}, Rel::kGreaterEq, 0);
  lp.add({{7, 1}, {3, 1}}, Rel::kLessEq, 60);
  const LpResult r = cf::gen::solve(lp);
  REQUIRE(r.status == Status::kOptimal);
  CHECK(r.x[3] == Approx(0.0).margin(1e-5));  // margin 0, up to the rows' tolerance
}

TEST_CASE("lp: programs beyond the fixed capacity are refused with a message") {
  // The solver keeps its work in fixed-size storage; a larger program is a caller's bug and
  // must say so rather than write past the storage.
  constexpr int kMax = LinearProgram::kMaxVars;
  CHECK_THROWS_WITH(LinearProgram(kMax + 1), Catch::Contains("more than kMaxVars variables"));
  LinearProgram::Coefs row;
  for (int j = 0; j < kMax; ++j) row.push_back({j, 1.0});
  CHECK(row.size() == static_cast<std::size_t>(kMax));
  CHECK_THROWS_WITH(row.push_back({0, 1.0}), Catch::Contains("more than kMaxVars coefficients"));
  // At the capacity, a program still solves: min sum x subject to x >= 1 in every coordinate.
  LinearProgram lp(kMax);
  for (int j = 0; j < kMax; ++j) {
    lp.c[j] = 1.0;
    lp.add({{j, 1.0}}, Rel::kGreaterEq, 1.0);
  }
  const LpResult r = cf::gen::internal::dense_solve(lp);
  REQUIRE(r.status == Status::kOptimal);
  for (int j = 0; j < kMax; ++j) CHECK(r.x[j] == Approx(1.0).margin(1e-9));
}

// Farkas certificates (cf::gen::farkas): multipliers of the rows that prove a program has no
// solution in its box, checked here by summing the rows by hand.
TEST_CASE("farkas: an infeasible program gets multipliers whose combined row no point meets",
          "[lp][farkas]") {
  // x + y <= 1, -x <= -1, -y <= -1 (x >= 1, y >= 1): infeasible; box [-5, 5]^2.
  LinearProgram lp(2);
  lp.add({{0, 1.0}, {1, 1.0}}, Rel::kLessEq, 1.0);
  lp.add({{0, -1.0}}, Rel::kLessEq, -1.0);
  lp.add({{1, -1.0}}, Rel::kLessEq, -1.0);
  for (int j = 0; j < 2; ++j) {
    lp.lower[j] = {true, -5.0};
    lp.upper[j] = {true, 5.0};
  }
  const auto proof = cf::gen::farkas(lp);
  REQUIRE(proof);
  REQUIRE(proof->y.size() == 3);
  for (double y : proof->y) CHECK(y >= 0);
  // The combined row y1 (x + y) - y2 x - y3 y <= y1 - y2 - y3: its left side is 0 only when
  // y1 = y2 = y3, and then the right side is -y1 < 0 (0 <= negative: no point meets it).
  CHECK(proof->y[0] == Approx(proof->y[1]).epsilon(1e-9));
  CHECK(proof->y[0] == Approx(proof->y[2]).epsilon(1e-9));
  CHECK(proof->gap < 0);
  CHECK(cf::gen::farkas_gap(lp, proof->y) == proof->gap);
  // Weights that prove nothing: a row alone, or a negative weight.
  CHECK(cf::gen::farkas_gap(lp, {1.0, 0.0, 0.0}) > 0);
  CHECK(cf::gen::farkas_gap(lp, {1.0, -1.0, 1.0}) == std::numeric_limits<double>::infinity());
}

TEST_CASE("farkas: a feasible program has none; the box alone can refute", "[lp][farkas]") {
  LinearProgram lp(1);
  lp.add({{0, 1.0}}, Rel::kLessEq, 2.0);  // x <= 2
  lp.lower[0] = {true, 0.0};
  lp.upper[0] = {true, 1.0};
  CHECK_FALSE(cf::gen::farkas(lp));
  lp.add({{0, -1.0}}, Rel::kLessEq, -3.0);  // x >= 3, outside the box [0, 1]
  const auto proof = cf::gen::farkas(lp);
  REQUIRE(proof);
  CHECK(proof->y[1] > 0);  // x >= 3 with x <= 1 from the box
  CHECK(proof->gap < 0);
}

TEST_CASE("farkas: its preconditions are refused with the reason", "[lp][farkas]") {
  LinearProgram lp(1);
  lp.add({{0, 1.0}}, Rel::kGreaterEq, 2.0);
  lp.lower[0] = {true, 0.0};
  lp.upper[0] = {true, 1.0};
  CHECK_THROWS_WITH(cf::gen::farkas(lp), "farkas: a row that is not a.x <= b");
  LinearProgram open(1);
  open.add({{0, 1.0}}, Rel::kLessEq, 2.0);
  CHECK_THROWS_WITH(cf::gen::farkas(open), "farkas: variable 0 without finite bounds");
  open.lower[0] = {true, 0.0};
  open.upper[0] = {true, 1.0};
  CHECK_THROWS_WITH(cf::gen::farkas_gap(open, {1.0, 2.0}), "farkas_gap: 2 multipliers for 1 rows");
}
