// Tests of the one-parameter rotation families the witness search samples
// (tools/cfgen/decide/rotation_family.cpp): the spins about an axis that keep a set's PCs
// locally admissible (admissible_spins), the residual that makes the PCs' planes meet
// where their normals are dependent (translation_residual), and the finitely many rotations
// three perpendicularity conditions leave (perp_roots).

#include "cfgen/decide/rotation_family.hpp"
#include "analysed_pair.hpp"
#include "cfgen/verify/verifier.hpp"
#include "fixtures.hpp"

#include <cf/geometry.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
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
    "height difference is the faces', with or without a third PC; independent planes leave no "
    "residual",
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
  // The two edges alone: their planes are parallel, and meet where the offsets agree; the
  // residual is the offsets' difference itself.
  cf::PcSet two;
  two.insert(cf::Pc{cf::PcType::kEF, e_near, floor_top});
  two.insert(cf::Pc{cf::PcType::kEF, e_far, wall_top});
  for (double theta : {0.0, 0.3, root, 1.2}) {
    const std::optional<double> r = cf::gen::internal::translation_residual(
        A, B, two, cf::gen::axis_angle(Vec3::UnitZ(), theta));
    REQUIRE(r.has_value());
    CHECK(std::abs(std::abs(*r) - std::abs(40 * std::sin(theta) - 30)) < kRounding);
  }
  // An edge on the floor's top and a vertex on the wall's side: independent planes.
  cf::PcSet across;
  across.insert(cf::Pc{cf::PcType::kEF, e_near, floor_top});
  across.insert(cf::Pc{cf::PcType::kVF, 3, wall});
  CHECK(!cf::gen::internal::translation_residual(A, B, across, Mat3::Identity()).has_value());

  // Three faces of B at right angles: the planes always meet.
  const int bottom = cf::test::face_with_plane(B, -Vec3::UnitZ(), 0);
  REQUIRE(bottom >= 0);
  cf::PcSet corner;
  corner.insert(cf::Pc{cf::PcType::kFF, 2, floor_top});
  corner.insert(cf::Pc{cf::PcType::kFF, 5, wall});
  corner.insert(cf::Pc{cf::PcType::kFF, 0, bottom});
  CHECK(!cf::gen::internal::translation_residual(A, B, corner, Mat3::Identity()).has_value());
}

namespace {

cf::Vec3 unit_in(std::mt19937_64& rng) {
  std::normal_distribution<double> g;
  return cf::Vec3(g(rng), g(rng), g(rng)).normalized();
}

// The largest residual of the three conditions at R.
double worst(const cf::gen::RotConstraints& c, const Mat3& R) {
  double r = 0;
  for (const auto& [u, w] : c.perp) r = std::max(r, std::abs((R * u).dot(w)));
  return r;
}

bool listed(const std::vector<Mat3>& roots, const Mat3& R) {
  constexpr double kSame = 1e-6;  // Frobenius: one root, found two ways
  return std::any_of(roots.begin(), roots.end(),
                     [&](const Mat3& Q) { return (Q - R).norm() < kSame; });
}

}  // namespace

TEST_CASE(
    "perp roots: every rotation meeting three perpendicularity conditions, whatever rotation a "
    "projection starts from",
    "[rotation_family][cfgen]") {
  std::mt19937_64 rng(11);
  std::size_t total = 0, projected = 0;
  for (int trial = 0; trial < 40; ++trial) {
    // Conditions met by a known rotation: u_i random, w_i random across R* u_i.
    const Mat3 R_star =
        cf::gen::axis_angle(unit_in(rng), std::uniform_real_distribution<>(0, 3)(rng));
    cf::gen::RotConstraints c;
    for (int i = 0; i < 3; ++i) {
      const Vec3 u = unit_in(rng);
      c.perp.push_back({u, (R_star * u).cross(unit_in(rng)).normalized()});
    }
    const std::optional<std::vector<Mat3>> roots = cf::gen::internal::perp_roots(c);
    REQUIRE(roots.has_value());
    CHECK(roots->size() <= 8);      // a resultant of degree 8 in e^(i phi)
    CHECK(roots->size() % 2 == 0);  // generic roots come in pairs (the torus' degree is even)
    for (const Mat3& R : *roots) {
      CHECK(worst(c, R) <= cf::gen::kRotAccepted);
      CHECK((R.transpose() * R - Mat3::Identity()).norm() < 1e-12);
      CHECK(R.determinant() > 0);
    }
    CHECK(listed(*roots, R_star));
    total += roots->size();
    // Every rotation Gauss-Newton reaches from 200 random starts is one of them.
    for (int s = 0; s < 200; ++s) {
      Mat3 R = cf::gen::axis_angle(unit_in(rng), std::uniform_real_distribution<>(0, M_PI)(rng));
      if (!cf::gen::internal::project_perp(c, R)) continue;
      ++projected;
      CHECK(listed(*roots, R));
    }
  }
  CHECK(projected > 4000);  // most starts converge
  CHECK(total >= 80);       // at least the known root and its partner each time
}

TEST_CASE("perp roots: dependent or missing conditions leave no finite answer",
          "[rotation_family][cfgen]") {
  const Vec3 x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  cf::gen::RotConstraints c;
  c.perp = {{x, z}, {x, z}, {y, x}};  // the first two the same: a curve of rotations
  CHECK_FALSE(cf::gen::internal::perp_roots(c).has_value());
  c.perp = {{x, z}, {y, x}};  // two conditions: a curve
  CHECK_FALSE(cf::gen::internal::perp_roots(c).has_value());
  // x, y and z all across z: impossible, a rotation keeps them spanning space.
  c.perp = {{x, z}, {y, z}, {z, z}};
  const std::optional<std::vector<Mat3>> none = cf::gen::internal::perp_roots(c);
  REQUIRE(none.has_value());
  CHECK(none->empty());
}

TEST_CASE(
    "align family: a condition that holds along the whole spin to its tolerance is a family, "
    "not two roots",
    "[rotation_family]") {
  // One f-f (A's +z face against B's +z face: R z = -z) and an e-f whose edge of A runs
  // 2e-7 rad off +z and whose face of B has a normal 1e-7 rad off perpendicular to B's: read
  // from float32 files, a box's vertical edge against a wall at a right angle to the floor.
  // Over the spin, (R u) . w runs between -3e-7 and 1e-7: exactly zero at two spins, within
  // the models' precision at every one.
  cf::gen::RotConstraints c;
  c.align.push_back({Vec3(0, 0, 1), Vec3(0, 0, -1)});
  c.perp.push_back({Vec3(2e-7, 0, 1).normalized(), Vec3(1, 0, 1e-7).normalized()});
  constexpr int kSamples = 12;
  bool finite = false;
  // Exact models (kRotAccepted, 1e-8): the two roots.
  CHECK(cf::gen::internal::align_family(c, {}, kSamples, &finite).size() == 2);
  CHECK(finite);
  // Tolerance 5e-7 (models known to their precision): every sampled spin, no finite claim.
  c.align_tol = {5e-7};
  c.perp_tol = {5e-7};
  const std::vector<Mat3> rots = cf::gen::internal::align_family(c, {}, kSamples, &finite);
  CHECK_FALSE(finite);
  CHECK(rots.size() == kSamples);
  for (const Mat3& R : rots) CHECK(cf::gen::satisfies(c, R));
}

TEST_CASE("project perp: two conditions equal to their tolerance are projected onto as one",
          "[rotation_family]") {
  // An e-f and an f-e whose conditions are the same to 1e-7: A's edge along +x on B's face of
  // normal +y, and A's face of normal +x (1e-7 off the edge) against B's edge along +y (1e-7
  // off the normal). Treated as two independent rows, Gauss-Newton steps along their
  // difference, a direction they barely constrain.
  cf::gen::RotConstraints c;
  c.perp.push_back({Vec3(1, 0, 0), Vec3(0, 1, 0)});
  c.perp.push_back({Vec3(1, 1e-7, 0).normalized(), Vec3(0, 1, 1e-7).normalized()});
  c.perp_tol = {5e-7, 5e-7};
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g;
  int projected = 0;
  for (int k = 0; k < 50; ++k) {
    Mat3 R = cf::gen::axis_angle(Vec3(g(rng), g(rng), g(rng)).normalized(), 0.3);
    if (cf::gen::internal::project_perp(c, R)) ++projected;
    CHECK(cf::gen::satisfies(c, R));
  }
  CHECK(projected == 50);
}

TEST_CASE(
    "translation residual: planes parallel to within a given sine count as parallel, not as "
    "meeting",
    "[rotation_family][cfgen]") {
  // An e-f on B's floor top (normal +y) and an f-v on A's bottom face (normal -y, turned with
  // A): at a turn of 1e-7 rad about z the planes are 1e-7 from parallel, as two faces at a
  // right angle in the design are in a float32 file. Exact models keep rounding's 1e-9 and see
  // two planes meeting in a line; models known to their precision pass it (direction_tol).
  const cf::Polyhedron A = cf::test::box(40, 10, 10, "A");
  const cf::Polyhedron B = cf::test::small_l_block();
  const int e_near = cf::test::edge_between(A, 0, 4);
  const int bottom = face_with_normal(A, Vec3(0, -1, 0));
  const int floor_top = cf::test::face_with_plane(B, Vec3::UnitY(), 10);
  REQUIRE(e_near >= 0);
  REQUIRE(bottom >= 0);
  REQUIRE(floor_top >= 0);
  cf::PcSet pcs;
  pcs.insert(cf::Pc{cf::PcType::kEF, e_near, floor_top});
  pcs.insert(cf::Pc{cf::PcType::kFV, bottom, 0});
  const Mat3 R = cf::gen::axis_angle(Vec3::UnitZ(), 1e-7);
  CHECK_FALSE(cf::gen::internal::translation_residual(A, B, pcs, R).has_value());
  CHECK(cf::gen::internal::translation_residual(A, B, pcs, R, 1e-6).has_value());
  CHECK_FALSE(cf::gen::internal::translation_residual(A, B, pcs, R, 1e-8).has_value());
}
