// The first-order test of a cube of rotations (tools/cfgen/decide/first_order): at every
// rotation R = R_c Q of the cube where the PCs keep the slack, the program of the normals'
// signs there holds at v = sin(theta) w, (w, theta) Q's axis and angle; and the test refutes
// a cube around a pose where two PCs reach the limit of their cones while turning apart,
// which the terms bounded one at a time leave open.

#include "cfgen/decide/first_order.hpp"
#include "analysed_pair.hpp"
#include "cfgen/verify/rotation_conditions.hpp"
#include "cfgen/verify/verifier.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>

namespace {

using cf::Mat3;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Vec3;

// The largest amount by which v breaks a row of the program (<= 0: v meets every row).
double worst_row(const cf::gen::LinearProgram& lp, const Vec3& v) {
  double worst = -HUGE_VAL;
  for (const auto& row : lp.rows) {
    double lhs = 0;
    for (const auto& [j, coef] : row.a) lhs += coef * v[j];
    worst = std::max(worst, lhs - row.b);
  }
  return worst;
}

// The sign of each e-e's normal (the verifier's sigma) at which its wedge terms are largest,
// as the program index first_order_programs gives it.
unsigned signs_at(const cf::test::AnalysedPair& p, const PcSet& s, const Mat3& R) {
  unsigned signs = 0;
  int e = 0;
  for (const Pc& pc : s) {
    if (pc.type != PcType::kEE) continue;
    const Vec3 N = (R * p.A.edges()[pc.a].dir).cross(p.B.edges()[pc.b].dir).normalized();
    // Of the two normals, the one B's wedge lies behind (both into-face vectors away from it).
    const auto& wb = p.bi.wedges[static_cast<std::size_t>(pc.b)];
    const double plus = std::min(-wb.into_left.dot(N), -wb.into_right.dot(N));
    const double minus = std::min(wb.into_left.dot(N), wb.into_right.dot(N));
    if (minus > plus) signs |= 1u << e;
    ++e;
  }
  return signs;
}

}  // namespace

TEST_CASE(
    "first order: at every rotation of the cube where the PCs keep the slack, the program of "
    "its normals' signs holds at v = sin(theta) w",
    "[cells]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::small_l_block());
  const cf::gen::SearchParams params{};
  const cf::gen::Verifier v(p.ai, p.bi, params);
  const double slack = v.verified_local_slack();
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_unit = [&] { return Vec3(u(rng), u(rng), u(rng)).normalized(); };
  auto random_point_pc = [&] {  // v-f, f-v, e-e: no rotational condition
    static const PcType kTypes[] = {PcType::kVF, PcType::kFV, PcType::kEE, PcType::kEE};
    const PcType type = kTypes[std::uniform_int_distribution<int>(0, 3)(rng)];
    const auto na = static_cast<int>(p.A.num_elements(cf::a_kind(type)));
    const auto nb = static_cast<int>(p.B.num_elements(cf::b_kind(type)));
    return Pc{type, std::uniform_int_distribution<int>(0, na - 1)(rng),
              std::uniform_int_distribution<int>(0, nb - 1)(rng)};
  };
  int held = 0;
  for (int trial = 0; trial < 4000; ++trial) {
    PcSet s({random_point_pc()});
    s.insert(random_point_pc());
    if (trial % 2) s.insert(random_point_pc());
    const Mat3 R_c = Eigen::AngleAxisd(3 * u(rng), random_unit()).toRotationMatrix();
    const double theta_max = 0.7 * std::pow(10.0, -2.5 * (u(rng) + 1) / 2);  // 2e-3 .. 0.7
    const auto programs = cf::gen::first_order_programs(p.ai, p.bi, s, R_c, theta_max, slack, 1e-8);
    REQUIRE(!programs.empty());
    for (int k = 0; k < 30; ++k) {
      const Vec3 w = random_unit();
      const double theta = theta_max * std::abs(u(rng));
      const Mat3 R = R_c * Eigen::AngleAxisd(theta, w).toRotationMatrix();
      if (v.local_margin(s, R) < slack) continue;
      ++held;
      const auto& lp = programs[signs_at(p, s, R)];
      INFO(cf::to_string(s) << " theta_max " << theta_max << " theta " << theta);
      CHECK(worst_row(lp, std::sin(theta) * w) <= 1e-12);
    }
  }
  CHECK(held > 500);  // enough rotations keep the slack for the check to have teeth
}

TEST_CASE(
    "first order: the rotational condition of an e-f holds at v = sin(theta) w wherever it "
    "holds at R",
    "[cells]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::small_l_block());
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int ea = std::uniform_int_distribution<int>(0, p.A.num_edges() - 1)(rng);
    const int fb = std::uniform_int_distribution<int>(0, p.B.num_faces() - 1)(rng);
    const PcSet s({Pc{PcType::kEF, ea, fb}});
    // A rotation taking A's edge into B's face's plane, and a centre near it.
    Mat3 R =
        Eigen::AngleAxisd(3 * u(rng), Vec3(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    const Vec3 n = p.B.faces()[fb].normal, d = R * p.A.edges()[ea].dir;
    R = Eigen::Quaterniond::FromTwoVectors(d, (d - d.dot(n) * n).normalized()).toRotationMatrix() *
        R;
    if (std::abs((R * p.A.edges()[ea].dir).dot(n)) > 1e-12) continue;
    const double theta_max = 0.5 * std::abs(u(rng)) + 1e-3;
    const Vec3 w = Vec3(u(rng), u(rng), u(rng)).normalized();
    const double theta = theta_max * std::abs(u(rng));
    const Mat3 R_c = R * Eigen::AngleAxisd(theta, w).toRotationMatrix().transpose();
    const auto programs = cf::gen::first_order_programs(p.ai, p.bi, s, R_c, theta_max, 0, 1e-8);
    REQUIRE(programs.size() == 1);
    // Only the rotational rows (the last two): the wedge rows hold only where it is admissible.
    cf::gen::LinearProgram rot(3);
    rot.rows.assign(programs[0].rows.end() - 2, programs[0].rows.end());
    CHECK(worst_row(rot, std::sin(theta) * w) <= 1e-12);
    ++checked;
  }
  CHECK(checked > 1000);
}

TEST_CASE(
    "first order: a cube about a rotation where two PCs reach their cones' limit while turning "
    "apart is refuted, where the terms bounded one at a time leave it open",
    "[cells]") {
  // A 10 mm cube on a slab's top face: v-f of the cube's bottom corner 0 and v-f of its
  // corner 1 on the same face. At the identity the bottom face lies flat: both corners'
  // edge rays along the bottom face are at the limit (margin 0). A tilt that lifts corner
  // 0's rays lowers corner 1's: no rotation keeps both at the slack (they are one face: the
  // two PCs' margins cannot both be positive).
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::SearchParams params{};
  const cf::gen::Verifier v(p.ai, p.bi, params);
  const double slack = v.verified_local_slack();
  const int top = 1;  // cf::test::box's face 1 is +z
  const PcSet s({Pc{PcType::kVF, 0, top}, Pc{PcType::kVF, 1, top}});
  const Mat3 R_c = Mat3::Identity();
  const double theta_max = 0.01;
  CHECK(cf::gen::local_margin_bound(p.ai, p.bi, s, R_c, cf::gen::TurnBound{theta_max}) >= slack);
  std::vector<cf::gen::FarkasCertificate> proofs;
  CHECK(cf::gen::first_order_refutes(p.ai, p.bi, s, R_c, theta_max, slack, 1e-8, &proofs));
  CHECK(proofs.size() == 1);
}
