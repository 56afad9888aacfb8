// The verify layer (tools/cfgen/verify/verifier.hpp) on hand-made poses with known answers: a
// 10 mm cube A on a 40 x 40 x 10 mm slab B, placed by hand. What a witness is, the PCs that
// hold at a pose, the contact plane, the margin and the freedoms, and the reasons a pose is
// refused.

#include "cfgen/verify/verifier.hpp"
#include "analysed_pair.hpp"
#include "fixtures.hpp"

#include <catch2/catch.hpp>

#include <cmath>
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
