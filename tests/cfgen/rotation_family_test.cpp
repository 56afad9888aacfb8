// Tests of the one-parameter rotation families the witness search samples
// (tools/cfgen/decide/rotation_family.cpp): the spins about an axis that keep a set's PCs
// locally admissible (admissible_spins), and the residual that makes the PCs' planes meet
// where their normals are dependent (translation_residual).

#include "cfgen/decide/rotation_family.hpp"
#include "analysed_pair.hpp"
#include "cfgen/verify/verifier.hpp"
#include "fixtures.hpp"

#include <cf/geometry.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <optional>
#include <vector>

namespace {

using cf::Mat3;
using cf::Vec3;

int vertex_at(const cf::Polyhedron& m, const Vec3& p) {
  for (std::size_t i = 0; i < m.vertices().size(); ++i)
    if ((m.vertices()[i].p - p).norm() < 1e-9) return static_cast<int>(i);
  return -1;
}

int face_with_normal(const cf::Polyhedron& m, const Vec3& n) {
  for (std::size_t i = 0; i < m.faces().size(); ++i)
    if ((m.faces()[i].normal - n).norm() < 1e-9) return static_cast<int>(i);
  return -1;
}

}  // namespace

TEST_CASE(
    "admissible spins: a vertex standing on a face is admissible only in three arcs narrower than "
    "the samples' spacing, and the spins found lie in each of them",
    "[rotation_family][cfgen]") {
  // A cube's corner at the origin, its edges along +x, +y, +z, on the top face (normal +z) of
  // a slab: locally admissible exactly when R^T e_z lies in the open positive octant, every
  // component above the margin. Spinning A about its diagonal d turns m = R^T e_z on a circle
  // about d; at 54 degrees from d (the axes are 54.7356 degrees from it) the circle enters
  // the octant only near each axis, in arcs about 0.028 rad wide (components 0.009 at the
  // middle, the margin 1e-3 at the ends), 120 degrees apart.
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const int v = vertex_at(p.A, Vec3::Zero());
  const int top = face_with_normal(p.B, Vec3::UnitZ());
  REQUIRE(v >= 0);
  REQUIRE(top >= 0);
  cf::PcSet pcs;
  pcs.insert(cf::Pc{cf::PcType::kVF, v, top});
  const Vec3 d = Vec3::Ones().normalized();
  const double theta = 54.0 * M_PI / 180;
  const Vec3 w = (Vec3::UnitX() - d.dot(Vec3::UnitX()) * d).normalized();
  const Vec3 nearest_x = std::cos(theta) * d + std::sin(theta) * w;  // m at the arc's middle
  constexpr int kSamples = 24;
  // The arcs' middles sit halfway between two samples: no sample centre is admissible.
  const double middle = M_PI / kSamples;
  const Vec3 m0 = cf::gen::axis_angle(d, middle) * nearest_x;  // R(phi)^T e_z = Rot(d, -phi) m0
  const Mat3 R0 = cf::gen::align(m0, Vec3::UnitZ());
  REQUIRE((R0.transpose() * Vec3::UnitZ() - m0).norm() < 1e-12);
  const double min_local = std::sin(1e-3);
  auto margin = [&](double phi) {
    return cf::gen::local_margin_bound(p.ai, p.bi, pcs, R0 * cf::gen::axis_angle(d, phi), {});
  };
  for (int k = 0; k < kSamples; ++k) CHECK(margin(2 * M_PI * k / kSamples) <= min_local);

  const std::vector<double> spins =
      cf::gen::internal::admissible_spins(p.ai, p.bi, pcs, d, R0, kSamples, min_local);
  for (double phi : spins) CHECK(margin(phi) > min_local);
  // One arc about each of middle, middle + 2 pi / 3, middle + 4 pi / 3 (each axis in turn).
  constexpr double kHalfArc = 0.014;  // rad, from the components above (0.009 +- 0.572 delta)
  for (int arc = 0; arc < 3; ++arc) {
    const double centre = middle + 2 * M_PI * arc / 3;
    CHECK(margin(centre) > 0.008);
    int inside = 0;
    for (double phi : spins)
      if (std::abs(std::remainder(phi - centre, 2 * M_PI)) < kHalfArc) ++inside;
    CHECK(inside >= 1);
  }
  CHECK(spins.size() <= 12);  // a few spins each arc, not a dense sampling
}

TEST_CASE("admissible spins: the samples' centres where they are admissible, none where none is",
          "[rotation_family][cfgen]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const int v = vertex_at(p.A, Vec3::Zero());
  const int top = face_with_normal(p.B, Vec3::UnitZ());
  cf::PcSet pcs;
  pcs.insert(cf::Pc{cf::PcType::kVF, v, top});
  const Vec3 d = Vec3::Ones().normalized();
  const double min_local = std::sin(1e-3);
  // m0 = d: the diagonal straight up, every spin admissible (margin 1/sqrt(3)): exactly the
  // 24 centres, nothing halved.
  const Mat3 up = cf::gen::align(d, Vec3::UnitZ());
  const std::vector<double> all =
      cf::gen::internal::admissible_spins(p.ai, p.bi, pcs, d, up, 24, min_local);
  REQUIRE(all.size() == 24);
  for (int k = 0; k < 24; ++k) CHECK(all[k] == Approx(2 * M_PI * k / 24).margin(1e-12));
  // The diagonal pointing down: every ray below the face at every spin.
  const Mat3 down = cf::gen::align(d, -Vec3::UnitZ());
  CHECK(cf::gen::internal::admissible_spins(p.ai, p.bi, pcs, d, down, 24, min_local).empty());
}

TEST_CASE(
    "translation residual: two parallel edges on two parallel faces meet only where the edges' "
    "height difference is the faces'; independent planes leave no residual",
    "[rotation_family][cfgen]") {
  // A 40 x 10 x 10 box turned by theta about z: its edges along z at x = 0 and x = 40 rise
  // 40 sin(theta) apart. On the small L-block's floor top (y = 10) and wall top (y = 40), 30
  // apart, the two contact planes are parallel, so with any third PC the planes meet only
  // where 40 sin(theta) = 30; the residual is the offsets' difference over sqrt(2) (the rows'
  // left null vector (1, -1, 0) / sqrt(2)).
  const cf::Polyhedron A = cf::test::box(40, 10, 10, "A");
  const cf::Polyhedron B = cf::test::small_l_block();
  const int e_near = cf::test::edge_between(A, 0, 4), e_far = cf::test::edge_between(A, 1, 5);
  const int floor_top = cf::test::face_with_plane(B, Vec3::UnitY(), 10);
  const int wall_top = cf::test::face_with_plane(B, Vec3::UnitY(), 40);
  const int wall = cf::test::face_with_plane(B, Vec3::UnitX(), 10);
  REQUIRE(e_near >= 0);
  REQUIRE(e_far >= 0);
  REQUIRE(floor_top >= 0);
  REQUIRE(wall_top >= 0);
  REQUIRE(wall >= 0);
  cf::PcSet pcs;
  pcs.insert(cf::Pc{cf::PcType::kEF, e_near, floor_top});
  pcs.insert(cf::Pc{cf::PcType::kEF, e_far, wall_top});
  pcs.insert(cf::Pc{cf::PcType::kVF, 3, wall});  // any third PC
  auto residual = [&](double theta) {
    const std::optional<double> r = cf::gen::internal::translation_residual(
        A, B, pcs, cf::gen::axis_angle(Vec3::UnitZ(), theta));
    REQUIRE(r.has_value());
    return *r;
  };
  constexpr double kRounding = 1e-12;  // mm: a few operations on tens of mm
  const double root = std::asin(0.75);
  for (double theta : {0.0, 0.3, root, 1.2})
    CHECK(std::abs(std::abs(residual(theta)) - std::abs(40 * std::sin(theta) - 30) / std::sqrt(2)) <
          kRounding);
  CHECK((residual(root - 0.01) > 0) != (residual(root + 0.01) > 0));

  // Three faces of B at right angles: the planes always meet.
  const int bottom = cf::test::face_with_plane(B, -Vec3::UnitZ(), 0);
  REQUIRE(bottom >= 0);
  cf::PcSet corner;
  corner.insert(cf::Pc{cf::PcType::kFF, 2, floor_top});
  corner.insert(cf::Pc{cf::PcType::kFF, 5, wall});
  corner.insert(cf::Pc{cf::PcType::kFF, 0, bottom});
  CHECK(!cf::gen::internal::translation_residual(A, B, corner, Mat3::Identity()).has_value());
}
