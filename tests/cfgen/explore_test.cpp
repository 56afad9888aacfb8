// Tests of cfgen's closure by motion (tools/cfgen/decide/explore.cpp) and of the witness checks it
// relies on (WitnessSearch::contacts_at, the tangent-cone test in verify). Poses and answers
// are worked out by hand on boxes and the bundled L-block (slab 120 x 20 x 80 along x and z,
// wall 0 <= x <= 20 up to y = 80).

#include "cfgen/decide/explore.hpp"
#include "analysed_pair.hpp"
#include "cfgen/enumerate/enumerate.hpp"
#include "cfgen/generate.hpp"
#include "fixtures.hpp"
#include "mesh/model_loader.hpp"
#include "scratch.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

using cf::ElementKind;
using cf::Pc;
using cf::PcSet;
using cf::PcType;
using cf::Polyhedron;
using cf::Pose;
using cf::Vec3;

namespace {

// Exact events are computed in closed form from coordinates of tens of mm: they agree with
// the hand values to rounding, far below the generator's touch tolerance (1e-9 mm).
constexpr double kExact = 1e-9;
// Rotational events are refined by bisection to double precision.
constexpr double kAngle = 1e-9;

std::string off_box(double x0, double y0, double z0, double x1, double y1, double z1) {
  std::ostringstream os;
  os << "OFF\n8 6 0\n";
  for (int i = 0; i < 8; ++i)
    os << ((i & 1) ? x1 : x0) << ' ' << ((i & 2) ? y1 : y0) << ' ' << ((i & 4) ? z1 : z0) << '\n';
  // Outward, counter-clockwise seen from outside.
  os << "4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
  return os.str();
}

// An L-section prism along z: CCW section points in the xy plane, extruded from z0 to z1.
std::string off_prism(const std::vector<std::pair<double, double>>& sec, double z0, double z1) {
  const std::size_t n = sec.size();
  std::ostringstream os;
  os << "OFF\n" << 2 * n << ' ' << n + 2 << " 0\n";
  for (double z : {z0, z1})
    for (const auto& [x, y] : sec) os << x << ' ' << y << ' ' << z << '\n';
  os << n;
  for (std::size_t i = n; i-- > 0;) os << ' ' << i;
  os << '\n' << n;
  for (std::size_t i = 0; i < n; ++i) os << ' ' << n + i;
  os << '\n';
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    os << "4 " << i << ' ' << j << ' ' << n + j << ' ' << n + i << '\n';
  }
  return os.str();
}

Polyhedron load_text(const std::string& name, const std::string& text) {
  return cf::tools::load_model(cf::test::write_file(name, text));
}

Polyhedron l_block() {
  return cf::tools::load_model(std::string(CF_SOURCE_DIR) + "/data/models/l_block.off");
}

// The index of the face of m with this outward normal and plane offset.
int face_of(const Polyhedron& m, const Vec3& n, double offset) {
  const int f = cf::test::face_with_plane(m, n, offset);
  if (f < 0) FAIL("no face with that plane");
  return f;
}

int edge_of(const Polyhedron& m, const Vec3& a, const Vec3& b) {
  for (std::size_t e = 0; e < m.num_edges(); ++e) {
    const Vec3 p = m.edge_point(cf::EdgeId(int(e)), 0), q = m.edge_point(cf::EdgeId(int(e)), 1);
    if (((p - a).norm() < 1e-9 && (q - b).norm() < 1e-9) ||
        ((p - b).norm() < 1e-9 && (q - a).norm() < 1e-9))
      return static_cast<int>(e);
  }
  FAIL("no such edge");
  return -1;
}

int vertex_of(const Polyhedron& m, const Vec3& x) {
  const int v = cf::test::vertex_at(m, x);
  if (v < 0) FAIL("no such vertex");
  return v;
}

using Pair = cf::test::AnalysedPair;

bool has(const std::vector<cf::gen::Discovery>& ds, const PcSet& s) {
  for (const auto& d : ds)
    if (d.pcs == s) return true;
  return false;
}

}  // namespace

TEST_CASE("first contact of a translation: exact gap, dominated pairs ignored", "[explore]") {
  const Polyhedron A = load_text("cube10.off", off_box(0, 0, 0, 10, 10, 10));
  const Polyhedron B = l_block();
  Pose pose;
  pose.t_BA = Vec3(50, 33.25, 30);  // 13.25 mm above the slab
  SECTION("falling onto the slab") {
    const double s =
        cf::gen::first_contact_translation(A, B, pose, Vec3(0, -1, 0), 1e-8, 1e3, 1e-9, PcSet());
    CHECK(std::abs(s - 13.25) < kExact);
  }
  SECTION("sliding on the slab into the wall: the slab's own pairs do not stop it") {
    pose.t_BA.y() = 20;
    const int top = face_of(A, Vec3(0, -1, 0), 0), slab = face_of(B, Vec3(0, 1, 0), 20);
    const PcSet kept({Pc{PcType::kFF, top, slab}});
    const double s =
        cf::gen::first_contact_translation(A, B, pose, Vec3(-1, 0, 0), 1e-8, 1e3, 1e-9, kept);
    CHECK(std::abs(s - 30.0) < kExact);  // from x = 50 to the wall's face at x = 20
  }
  SECTION("moving away meets nothing") {
    const double s =
        cf::gen::first_contact_translation(A, B, pose, Vec3(0, 1, 0), 1e-8, 1e3, 1e-9, PcSet());
    CHECK(std::isinf(s));
  }
}

TEST_CASE("first contact of a rotation: an edge on the slab tilts onto its face", "[explore]") {
  const Polyhedron A = load_text("cube10r.off", off_box(0, 0, 0, 10, 10, 10));
  const Polyhedron B = l_block();
  // The cube rests on its edge x = 0, y = 0 (along z), tilted by 0.3 rad about it.
  const double tilt = 0.3;
  Pose pose;
  pose.R_BA = Eigen::AngleAxisd(tilt, Vec3::UnitZ()).toRotationMatrix();
  pose.t_BA = Vec3(50, 20, 30);
  const int edge = edge_of(A, Vec3(0, 0, 0), Vec3(0, 0, 10)), slab = face_of(B, Vec3(0, 1, 0), 20);
  const PcSet kept({Pc{PcType::kEF, edge, slab}});
  // Turning back about the edge (-z through (50, 20)) lands the bottom face after `tilt`.
  const double phi = cf::gen::first_contact_rotation(A, B, pose, Vec3(50, 20, 30), Vec3(0, 0, -1),
                                                     1e-9, M_PI, 1e-9, kept);
  CHECK(std::abs(phi - tilt) < kAngle);
  // The other way, the opposite face lands after pi/2 - tilt.
  const double phi2 = cf::gen::first_contact_rotation(A, B, pose, Vec3(50, 20, 30), Vec3(0, 0, 1),
                                                      1e-9, M_PI, 1e-9, kept);
  CHECK(std::abs(phi2 - (M_PI / 2 - tilt)) < kAngle);
}

TEST_CASE("contacts_at reads the PCs of a pose, and refuses degenerate touches", "[explore]") {
  Pair p(load_text("cube10c.off", off_box(0, 0, 0, 10, 10, 10)), l_block());
  const cf::gen::WitnessSearch search(p.ai, p.bi, cf::gen::SearchParams{});
  const int bottom = face_of(p.A, Vec3(0, -1, 0), 0), left = face_of(p.A, Vec3(-1, 0, 0), 0);
  const int slab = face_of(p.B, Vec3(0, 1, 0), 20), wall = face_of(p.B, Vec3(1, 0, 0), 20);
  Pose pose;
  pose.t_BA = Vec3(20, 20, 30);  // in the L's inner corner: on the slab and against the wall
  PcSet got;
  REQUIRE(search.contacts_at(pose, got));
  CHECK(got == PcSet({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kFF, left, wall}}));
  pose.t_BA = Vec3(50, 25, 30);  // in the air
  REQUIRE(search.contacts_at(pose, got));
  CHECK(got.empty());
  // A vertex of the cube exactly on the slab's far edge (x = 120, y = 20): a v-e touch.
  pose.R_BA = Eigen::AngleAxisd(0.4, Vec3(1, 0, 1).normalized()).toRotationMatrix();
  pose.t_BA = Vec3(120, 20, 30);
  std::string why;
  CHECK_FALSE(search.contacts_at(pose, got, &why));
  CHECK(why.find("degenerate touch") != std::string::npos);
}

TEST_CASE("verify: a bracket whose foot runs into the wall through the reflex edge is refused",
          "[explore]") {
  // A's L section: a foot 10 <= x <= 25, 20 <= y <= 25 and an upright 20 <= x <= 25 up to
  // y = 50. Placed as is (identity pose), its bottom face lies on the slab, its upright's
  // inner face (x = 20) on the wall's face and its reflex edge (20, 25) on that face: every
  // pair of elements meets only on boundaries, yet the foot is 10 mm inside the wall.
  Pair bad(
      load_text("bracket_in.off",
                off_prism({{10, 20}, {25, 20}, {25, 50}, {20, 50}, {20, 25}, {10, 25}}, 20, 60)),
      l_block());
  const cf::gen::WitnessSearch search(bad.ai, bad.bi, cf::gen::SearchParams{});
  const int bottom = face_of(bad.A, Vec3(0, -1, 0), -20),
            inner = face_of(bad.A, Vec3(-1, 0, 0), -20);
  const int slab = face_of(bad.B, Vec3(0, 1, 0), 20), wall = face_of(bad.B, Vec3(1, 0, 0), 20);
  const PcSet cf_set({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kFF, inner, wall}});
  std::string why;
  CHECK(search.verify(cf_set, Pose(), &why) < 0);
  CHECK(why.find("overlap") != std::string::npos);

  // The same CF with the foot on the room side: the bracket's convex corner edge lies along
  // the L's reflex edge (collinear edges whose sectors, 90 and 270 degrees, only meet on their
  // sides), which the cone test must accept.
  Pair good(
      load_text("bracket_out.off",
                off_prism({{20, 20}, {35, 20}, {35, 25}, {25, 25}, {25, 50}, {20, 50}}, 20, 60)),
      l_block());
  const cf::gen::WitnessSearch search2(good.ai, good.bi, cf::gen::SearchParams{});
  const int bottom2 = face_of(good.A, Vec3(0, -1, 0), -20),
            outer2 = face_of(good.A, Vec3(-1, 0, 0), -20);
  const PcSet cf_set2({Pc{PcType::kFF, bottom2, slab}, Pc{PcType::kFF, outer2, wall}});
  std::string why2;
  CHECK(search2.verify(cf_set2, Pose(), &why2) >= cf::gen::SearchParams{}.min_clearance);
  INFO(why2);
}

TEST_CASE(
    "verify names the pair a pose failed on, and a pair that still fails proves a pose refused",
    "[explore]") {
  using Kind = cf::gen::WitnessSearch::FailedPair::Kind;
  // The bracket whose foot runs into the wall (above): it fails where a corner of its inner
  // face touches the wall (a pair the inner face's PC covers, with the foot on the wall's
  // inside), and keeps failing there as it slides along the wall; moved off the wall, that
  // pair no longer touches.
  Pair bad(
      load_text("bracket_in2.off",
                off_prism({{10, 20}, {25, 20}, {25, 50}, {20, 50}, {20, 25}, {10, 25}}, 20, 60)),
      l_block());
  const cf::gen::WitnessSearch search(bad.ai, bad.bi, cf::gen::SearchParams{});
  const int bottom = face_of(bad.A, Vec3(0, -1, 0), -20),
            inner = face_of(bad.A, Vec3(-1, 0, 0), -20);
  const int slab = face_of(bad.B, Vec3(0, 1, 0), 20), wall = face_of(bad.B, Vec3(1, 0, 0), 20);
  const PcSet cf_set({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kFF, inner, wall}});
  cf::gen::WitnessSearch::FailedPair failed;
  REQUIRE(search.verify(cf_set, Pose(), nullptr, &failed) < 0);
  CHECK(failed.kind == Kind::kOverlap);
  CHECK(failed.kb == ElementKind::kFace);
  CHECK(failed.b == wall);
  CHECK(search.still_fails(cf_set, Pose(), failed));
  for (double dz : {-5.0, -1.0, 2.0, 7.0}) {
    Pose slid;
    slid.t_BA = Vec3(0, 0, dz);
    CHECK(search.still_fails(cf_set, slid, failed));
    CHECK(search.verify(cf_set, slid) < 0);
  }
  Pose off_wall;
  off_wall.t_BA = Vec3(1, 0, 0);
  CHECK_FALSE(search.still_fails(cf_set, off_wall, failed));

  // A cube face down on the slab, slid towards and into the wall: whenever a pair another
  // pose failed on still fails, verify refuses the pose (the property that lets the witness
  // search skip verifying it).
  Pair p(load_text("cube10f.off", off_box(0, 0, 0, 10, 10, 10)), l_block());
  const cf::gen::WitnessSearch cube(p.ai, p.bi, cf::gen::SearchParams{});
  const PcSet on_slab(
      {Pc{PcType::kFF, face_of(p.A, Vec3(0, -1, 0), 0), face_of(p.B, Vec3(0, 1, 0), 20)}});
  std::vector<Pose> poses;
  std::vector<cf::gen::WitnessSearch::FailedPair> pairs;
  for (int i = 0; i <= 40; ++i) {
    Pose x;
    x.R_BA = Eigen::AngleAxisd(0.05 * (i % 7), Vec3::UnitY()).toRotationMatrix();
    x.t_BA = Vec3(4 + 0.5 * i, 20, 30 + 0.25 * (i % 5));
    cf::gen::WitnessSearch::FailedPair f;
    if (cube.verify(on_slab, x, nullptr, &f) < 0 && f.kind != Kind::kNone) pairs.push_back(f);
    poses.push_back(x);
  }
  REQUIRE(pairs.size() >= 5);  // the cube is inside the wall for x < 20 (i < 32)
  int proofs = 0;
  for (const Pose& x : poses)
    for (const auto& f : pairs)
      if (cube.still_fails(on_slab, x, f)) {
        ++proofs;
        CHECK(cube.verify(on_slab, x) < 0);
      }
  CHECK(proofs > static_cast<int>(pairs.size()));  // pairs prove other poses than their own
}

TEST_CASE(
    "exploring from a cube on the slab meets the wall, and breaking the slab contact leaves the "
    "wall",
    "[explore]") {
  Pair p(load_text("cube10e.off", off_box(0, 0, 0, 10, 10, 10)), l_block());
  const cf::gen::WitnessSearch search(p.ai, p.bi, cf::gen::SearchParams{});
  const int bottom = face_of(p.A, Vec3(0, -1, 0), 0), left = face_of(p.A, Vec3(-1, 0, 0), 0);
  const int slab = face_of(p.B, Vec3(0, 1, 0), 20), wall = face_of(p.B, Vec3(1, 0, 0), 20);
  Pose on_slab;
  on_slab.t_BA = Vec3(60, 20, 30);
  const PcSet one({Pc{PcType::kFF, bottom, slab}});
  const PcSet two({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kFF, left, wall}});
  REQUIRE(search.verify(one, on_slab) > 0);
  const auto from_one = cf::gen::explore_translations(search, one, on_slab);
  // Sliding towards -x ends in the inner corner. The slide directions are 0.3 + k pi / 4 in
  // the slab's plane; the ones with a -x component reach the wall face flat (the cube is not
  // turned), so {bottom-slab, left-wall} is met.
  CHECK(has(from_one, two));
  // Every discovery is a pose where its set holds.
  for (const auto& d : from_one) {
    PcSet again;
    REQUIRE(search.contacts_at(d.pose, again));
    CHECK(again == d.pcs);
  }
  Pose in_corner;
  in_corner.t_BA = Vec3(20, 20, 30);
  REQUIRE(search.verify(two, in_corner) > 0);
  const auto from_two = cf::gen::explore_translations(search, two, in_corner);
  CHECK(has(from_two, PcSet({Pc{PcType::kFF, left, wall}})));  // lifted off the slab
  CHECK(has(from_two, one));                                   // moved off the wall
}

TEST_CASE("exploring rotations from a vertex on the slab lands an edge", "[explore]") {
  Pair p(load_text("cube10v.off", off_box(0, 0, 0, 10, 10, 10)), l_block());
  const cf::gen::WitnessSearch search(p.ai, p.bi, cf::gen::SearchParams{});
  const int slab = face_of(p.B, Vec3(0, 1, 0), 20);
  // Vertex 0 (the origin) down: the cube's diagonal (1, 1, 1) along +y, its three edges rising
  // at asin(1 / sqrt 3) = 35.3 degrees above the slab, plus a small turn so none is special.
  Pose pose;
  pose.R_BA = Eigen::AngleAxisd(0.05, Vec3(1, 0, 0)).toRotationMatrix() *
              Eigen::Quaterniond::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3::UnitY())
                  .toRotationMatrix();
  pose.t_BA = Vec3(60, 20, 40);
  const int v0 = vertex_of(p.A, Vec3::Zero());
  const PcSet vf({Pc{PcType::kVF, v0, slab}});
  REQUIRE(search.verify(vf, pose) > 0);
  const auto turned = cf::gen::explore_rotations(search, vf, pose);
  int edges_landed = 0;
  for (const auto& d : turned) {
    if (d.pcs.size() == 1 && d.pcs[0].type == PcType::kEF && d.pcs[0].b == slab) ++edges_landed;
    PcSet again;
    REQUIRE(search.contacts_at(d.pose, again));
    CHECK(again == d.pcs);
    // The vertex stays on the slab: every rotation here turns about it.
    CHECK(std::abs(d.pose.apply(p.A.vertices()[v0].p).y() - 20) < kExact);
  }
  CHECK(edges_landed >= 2);
}

namespace {

// The search's lengths as cfgen sets them from the smaller model's bounding-box diagonal.
cf::gen::SearchParams params_for(const Polyhedron& A, const Polyhedron& B) {
  return cf::tools::scaled_search(A, B, cf::tools::RelativeLengths{});
}

PcSet parse_set(const std::string& text) {
  PcSet s;
  std::istringstream is(text);
  for (std::string w; is >> w;) s.insert(*cf::pc_from_string(w));
  return s;
}

}  // namespace

// Pairs drawn by the independent oracle (tests/oracle, seeds 171, 1011 and 1002: a box on
// two stairs, a slab on steep stairs, a box against a T-slot block, all placed by random
// rigid motions) and CFs it sampled that the search used to miss: two face alignments solved
// as a double root (a rounding error e in the models' angles moved the rotation by sqrt(e));
// a contact set whose rotations place the contacts only in a narrow region (climbing the LP
// margin); two e-e crossings that no spread rotation holds locally (anchored rotations); a
// centred translation running into another part of B (separating cuts).
TEST_CASE("find: CFs of randomly placed pairs that need exact alignments, climbing and cuts",
          "[explore]") {
  struct Case {
    const char* a;
    const char* b;
    std::vector<const char*> sets;
  };
  const std::vector<Case> cases = {
      {"stairs_box_A.off",
       "stairs_B.off",
       {"f-f:0:4 f-f:2:7", "f-f:0:4 f-f:3:7", "e-f:1:4 v-f:5:7", "e-f:4:7 v-f:6:4",
        "e-f:5:7 v-f:5:4", "e-f:6:7 v-f:7:4", "v-f:0:7 v-f:4:4", "v-f:1:4 e-e:11:16",
        "f-v:4:5 e-e:6:7", "e-e:1:10 e-e:7:16", "e-e:3:10 e-e:6:16", "e-e:7:16 e-e:8:10"}},
      {"stairs_slab_A.off",
       "stairs_steep_B.off",
       {"e-e:5:6 e-e:6:16", "e-e:5:16 e-e:7:6", "e-e:0:16 e-e:3:8", "e-e:2:16 e-e:8:6",
        "v-f:0:7 v-f:1:4"}},
      {"tslot_box_A.off", "tslot_B.off", {"f-e:5:21"}},
  };
  for (const Case& c : cases) {
    const std::string dir = std::string(CF_SOURCE_DIR) + "/tests/data/models/";
    const Pair p(cf::tools::load_model(dir + c.a), cf::tools::load_model(dir + c.b));
    const cf::gen::SearchParams params = params_for(p.A, p.B);
    const cf::gen::WitnessSearch search(p.ai, p.bi, params);
    for (const char* text : c.sets) {
      INFO(c.b << ": " << text);
      const PcSet s = parse_set(text);
      const cf::gen::Witness w = search.find(s, {});
      REQUIRE(w.found);
      CHECK(search.verify(s, w.pose) >= params.min_clearance);
      PcSet at;
      REQUIRE(search.contacts_at(w.pose, at));
      CHECK(at == s);
    }
  }
}

TEST_CASE("plausible: a dominated PC, and heights over a face-face contact that cannot meet",
          "[explore]") {
  // A 10 mm cube on the L-block's slab (top y = 20).
  const Pair p(load_text("cube10h.off", off_box(0, 0, 0, 10, 10, 10)), l_block());
  const cf::gen::WitnessSearch search(p.ai, p.bi, cf::gen::SearchParams{});
  const int bottom = face_of(p.A, Vec3(0, -1, 0), 0), top = face_of(p.A, Vec3(0, 1, 0), 10);
  const int slab = face_of(p.B, Vec3(0, 1, 0), 20), wall = face_of(p.B, Vec3(1, 0, 0), 20);
  const int slab_under = face_of(p.B, Vec3(0, -1, 0), 0);
  const PcSet on_slab({Pc{PcType::kFF, bottom, slab}});
  CHECK(search.plausible(on_slab));
  // The cube's side face against the wall: heights 0..10 over the slab meet the wall's 0..60.
  const int side = face_of(p.A, Vec3(-1, 0, 0), 0);
  CHECK(search.plausible(PcSet({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kFF, side, wall}})));
  // An edge of the bottom face on the slab is dominated by the face-face PC.
  const int bottom_edge = edge_of(p.A, Vec3(0, 0, 0), Vec3(10, 0, 0));
  CHECK_FALSE(
      search.plausible(PcSet({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kEF, bottom_edge, slab}})));
  // The cube's top (10 mm over the slab) cannot touch the slab's underside (20 mm below it).
  const int top_edge = edge_of(p.A, Vec3(0, 10, 0), Vec3(10, 10, 0));
  (void)top;
  CHECK_FALSE(search.plausible(
      PcSet({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kEF, top_edge, slab_under}})));
  // A vertical edge of the cube spans heights 0..10; the wall face spans 0..60 over the slab.
  const int vertical_edge = edge_of(p.A, Vec3(0, 0, 0), Vec3(0, 10, 0));
  CHECK(search.plausible(
      PcSet({Pc{PcType::kFF, bottom, slab}, Pc{PcType::kEF, vertical_edge, wall}})));
}
