// The verify layer (tools/cfgen/verify/verifier.hpp) on hand-made poses with known answers: a
// 10 mm cube A on a 40 x 40 x 10 mm slab B, placed by hand. What a witness is, the PCs that
// hold at a pose, the contact plane, the margin and the freedoms, and the reasons a pose is
// refused.

#include "cfgen/verify/verifier.hpp"
#include "analysed_pair.hpp"
#include "cfgen/verify/rotation_conditions.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <string>

namespace {

using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Pose;
using cf::Vec3;

// Faces of cf::test::box: 0 bottom (-z), 1 top (+z).
constexpr int kBottom = 0, kTop = 1;

// The search's lengths in mm (SearchParams' defaults): touch 1e-9, clearance 1e-2 (at least)
// and 1.0 (good), margin 1e-2.
const cf::gen::SearchParams kParams{};

Pose at(const Vec3& t) {
  Pose p;
  p.t_BA = t;
  return p;
}

const PcSet kOnTop({Pc{PcType::kFF, kBottom, kTop}});  // A's bottom face on B's top face

}  // namespace

TEST_CASE(
    "a cube lying on a slab: the face-face PC is a witness, with the contact's plane, margin and "
    "freedoms",
    "[verify]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::Verifier v(p.ai, p.bi, kParams);
  const Pose pose = at({15, 15, 10});  // centred, 15 mm from every side of the slab
  std::string why;
  // Every other pair is at least 15 mm apart: the clearance is reported as good_clearance.
  CHECK(v.verify(kOnTop, pose, &why) == kParams.good_clearance);
  CHECK(why.empty());
  PcSet held;
  REQUIRE(v.contacts_at(pose, held));
  CHECK(held == kOnTop);
  const auto [n, d] = v.contact_plane(kOnTop[0], pose);
  CHECK((n - Vec3(0, 0, 1)).norm() < 1e-15);  // into A
  CHECK(d == 10);
  // The overlap is A's whole bottom face; its centroid is 5 mm inside A's face, 20 inside B's.
  CHECK(v.contact_margin(kOnTop, pose) == Approx(5).margin(1e-9));
  cf::CfRecord r;
  v.freedoms(kOnTop, pose, r);
  CHECK(r.dof == 3);  // slide in the plane (2) and turn about its normal (1)
  CHECK(r.translation_dof == 2);
}

TEST_CASE("poses that are not witnesses are refused, each with its reason", "[verify]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::Verifier v(p.ai, p.bi, kParams);
  std::string why;
  // Lifted 5 um: above the touch tolerance, below min_clearance: A's bottom edges are
  // contacts too close to count as clear (pairs are judged vertices and edges first).
  CHECK(v.verify(kOnTop, at({15, 15, 10.005}), &why) < 0);
  CHECK_THAT(why, Catch::StartsWith("extra contact e"));
  // Lifted 0.5 mm: every pair clear, and the PC does not hold.
  CHECK(v.verify(kOnTop, at({15, 15, 10.5}), &why) < 0);
  CHECK_THAT(why, Catch::StartsWith("PC f-f:0:1 apart by 0.5"));
  // A vertex-face PC where the face lies on the face: the face-face contact is an extra one.
  const PcSet vertex_only({Pc{PcType::kVF, 0, kTop}});
  CHECK(v.verify(vertex_only, at({15, 15, 10}), &why) < 0);
  CHECK_FALSE(why.empty());
  // Sunk 1 mm into the slab: the faces are 1 mm apart, A overlaps B.
  CHECK(v.verify(kOnTop, at({15, 15, 9}), &why) < 0);
  // Hanging over the slab's edge by 2 mm is still the face-face CF: B's top edge under A's
  // face lies in the closure of the PC's face. The overlap is x in [32, 40]: its centroid is
  // 4 mm inside both faces.
  PcSet held;
  REQUIRE(v.contacts_at(at({32, 15, 10}), held));
  CHECK(held == kOnTop);
  CHECK(v.verify(kOnTop, at({32, 15, 10}), &why) == kParams.good_clearance);
  CHECK(v.contact_margin(kOnTop, at({32, 15, 10})) == Approx(4).margin(1e-9));
}

TEST_CASE("neither solid inside the other: a cube deep inside a large box is refused", "[verify]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(100, 100, 100, "B"));
  const cf::gen::Verifier v(p.ai, p.bi, kParams);
  std::string why;
  // No element pair within good_clearance: only the point-in-solid test can tell.
  CHECK(v.verify(PcSet(), at({45, 45, 45}), &why) < 0);
  CHECK(why == "A inside B");
  PcSet held;
  REQUIRE(v.contacts_at(at({45, 45, 45}), held));
  CHECK(held.empty());
  // Beside the box, 5 mm off its side: not a contact, but a pose with no PC at all.
  CHECK(v.verify(PcSet(), at({105, 45, 45}), &why) == kParams.good_clearance);
}

TEST_CASE(
    "local margin bound: over a cube of rotations or an arc about an axis, no rotation has a "
    "larger local margin than the bound at the centre",
    "[verify]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::small_l_block());
  const cf::gen::Verifier v(p.ai, p.bi, kParams);
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random_unit = [&] { return Vec3(u(rng), u(rng), u(rng)).normalized(); };
  auto random_pc = [&] {
    const auto type = static_cast<PcType>(std::uniform_int_distribution<int>(0, 5)(rng));
    const auto na = static_cast<int>(p.A.num_elements(cf::a_kind(type)));
    const auto nb = static_cast<int>(p.B.num_elements(cf::b_kind(type)));
    return Pc{type, std::uniform_int_distribution<int>(0, na - 1)(rng),
              std::uniform_int_distribution<int>(0, nb - 1)(rng)};
  };
  std::size_t bounded = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    PcSet s({random_pc()});
    s.insert(random_pc());
    const cf::Mat3 R_c = Eigen::AngleAxisd(3 * u(rng), random_unit()).toRotationMatrix();
    // The bound with nothing turned is the margin itself.
    CHECK(cf::gen::local_margin_bound(p.ai, p.bi, s, R_c, {}) == v.local_margin(s, R_c));
    const double half = std::pow(10.0, -3 + 3 * (u(rng) + 1) / 2);  // 1e-3 .. 1 rad
    const bool arc = trial % 2 == 1;
    const Vec3 axis = random_unit();
    const cf::gen::TurnBound turn =
        arc ? cf::gen::TurnBound{0, half, axis} : cf::gen::TurnBound{std::sqrt(3.0) * half};
    const double bound = cf::gen::local_margin_bound(p.ai, p.bi, s, R_c, turn);
    for (int k = 0; k < 20; ++k) {
      // A rotation of the cube of axis-angle offsets (any turn of angle <= sqrt(3) half), or
      // of the arc R_c Rot(axis, d).
      const cf::Mat3 R =
          arc ? cf::Mat3(R_c * Eigen::AngleAxisd(half * u(rng), axis).toRotationMatrix())
              : cf::Mat3(Eigen::AngleAxisd(std::sqrt(3.0) * half * std::abs(u(rng)), random_unit())
                             .toRotationMatrix() *
                         R_c);
      const double m = v.local_margin(s, R);
      INFO(cf::to_string(s) << " half " << half << (arc ? " arc" : " cube"));
      CHECK(m <= bound + 1e-12);  // rounding of the products
      bounded += m > -1 ? 1 : 0;
    }
  }
  CHECK(bounded > 10000);  // most samples are not degenerate (-1), so the check has teeth
}

TEST_CASE(
    "local margin bound of an e-e near parallel edges: sound, and below zero over a cube that "
    "holds the parallel rotation when the two wedges face the same way",
    "[verify]") {
  // Two boxes, every edge along an axis: at the identity each x edge of A is parallel to each
  // x edge of B. Over a cube of half-width 0.01 rad about the identity, the contact normal of
  // such a pair may point anywhere perpendicular to the edges; the margin is positive at some
  // rotation of the cube only if the wedges can face each other.
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::Verifier v(p.ai, p.bi, kParams);
  const double half = 0.01;
  const cf::gen::TurnBound turn{std::sqrt(3.0) * half};
  // What bounding each term by the turn alone gives at parallel edges: the edges' sine may
  // reach the turn, so the bound is at least that.
  const double per_term = turn.unit();
  REQUIRE(per_term > v.verified_local_slack());
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int same_way = 0, facing = 0;
  for (int ea = 0; ea < static_cast<int>(p.A.num_edges()); ++ea)
    for (int eb = 0; eb < static_cast<int>(p.B.num_edges()); ++eb) {
      if (std::abs(p.A.edges()[ea].dir.dot(p.B.edges()[eb].dir)) < 1 - 1e-12) continue;
      const PcSet s({Pc{PcType::kEE, ea, eb}});
      const double bound = cf::gen::local_margin_bound(p.ai, p.bi, s, cf::Mat3::Identity(), turn);
      double best = -1;  // the largest margin sampled in the cube
      for (int k = 0; k < 4000; ++k) {
        const Vec3 r(u(rng), u(rng), u(rng));
        const cf::Mat3 R = Eigen::AngleAxisd(half * r.norm(), r.normalized()).toRotationMatrix();
        best = std::max(best, v.local_margin(s, R));
      }
      INFO(cf::to_string(s) << " bound " << bound << " sampled " << best);
      CHECK(best <= bound + 1e-12);
      // Wedges that face the same way (the two quarter-spaces are one): no normal is outside
      // both solids at any rotation near parallel, and the bound shows it.
      const auto& wa = p.ai.wedges[static_cast<std::size_t>(ea)];
      const auto& wb = p.bi.wedges[static_cast<std::size_t>(eb)];
      auto in_b = [&](const Vec3& w) {
        return (w - wb.into_left).norm() < 1e-9 || (w - wb.into_right).norm() < 1e-9;
      };
      if (in_b(wa.into_left) && in_b(wa.into_right)) {
        ++same_way;
        CHECK(bound < 0);
      } else {
        ++facing;
        CHECK(bound <= per_term + 1e-12);
      }
    }
  CHECK(same_way > 0);
  CHECK(facing > 0);
}

TEST_CASE(
    "models known to a precision: a face tilted within it still lies on the other face; beyond "
    "it, not",
    "[verify]") {
  // The cube on the slab, tilted about x through the centre of its bottom face. Exact models
  // hold the face-face condition to 1e-8; models read to 1e-5 mm (float32 of 100 mm
  // coordinates) hold it to 4 (1e-5 / 10 + 1e-5 / 40) = 5e-6 rad (kRotPerPrecision over the
  // two faces' widths), and the tilted face lies along B's to that tilt.
  cf::test::AnalysedPair exact(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  cf::test::AnalysedPair rounded(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  rounded.ai = cf::gen::analyse_model(rounded.A, 1e-5);
  rounded.bi = cf::gen::analyse_model(rounded.B, 1e-5);
  const cf::gen::RotConstraints c = cf::gen::rotation_constraints(kOnTop, rounded.ai, rounded.bi);
  REQUIRE(c.align_tol.size() == 1);
  CHECK(c.align_tol[0] == Approx(5e-6).epsilon(1e-9));
  auto tilted = [](double angle) {
    Pose p;
    p.R_BA = Eigen::AngleAxisd(angle, Vec3::UnitX()).toRotationMatrix();
    p.t_BA = Vec3(15, 15, 10) - p.R_BA * Vec3(5, 5, 0);  // the bottom face's centre at (20, 20, 10)
    return p;
  };
  std::string why;
  const cf::gen::Verifier v_exact(exact.ai, exact.bi, kParams);
  const cf::gen::Verifier v_rounded(rounded.ai, rounded.bi, kParams);
  CHECK(v_exact.verify(kOnTop, tilted(2e-6), &why) < 0);
  CHECK(why == "a line or plane PC is not parallel to its face");
  CHECK(v_rounded.verify(kOnTop, tilted(2e-6), &why) == kParams.good_clearance);
  CHECK(v_rounded.verify(kOnTop, tilted(2e-5), &why) < 0);
  CHECK(why == "a line or plane PC is not parallel to its face");
  // The tilt allowed to the face's vertices: (5e-6 - 1e-8) rad over its 14.1 mm diagonal.
  CHECK(cf::gen::tilt_allowance(rounded.ai, rounded.bi, kOnTop[0]) ==
        Approx((5e-6 - cf::gen::kRotAccepted) * std::sqrt(200.0)).epsilon(1e-9));
  CHECK(cf::gen::tilt_allowance(exact.ai, exact.bi, kOnTop[0]) == 0);
}
