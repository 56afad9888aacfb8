// The decide layer (tools/cfgen/decide/task.hpp, witness.hpp) on hand-made candidate sets with
// known answers: a 10 mm cube A against a 40 x 40 x 10 mm slab B. One set in, a result and
// its evidence out: a witness that the verifier accepts, or a proof of invalidity.

#include "analysed_pair.hpp"
#include "cfgen/decide/task.hpp"
#include "fixtures.hpp"
#include "oracle_pair.hpp"
#include "shapes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

namespace {

using cf::Pc;
using cf::PcSet;
using cf::PcType;

constexpr int kBottom = 0, kTop = 1;  // faces of cf::test::box

}  // namespace

TEST_CASE("decide: a face on a face is found, with a witness the verifier accepts", "[decide]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::WitnessSearch search(p.ai, p.bi, {});
  cf::gen::Task t;
  t.pcs = PcSet({Pc{PcType::kFF, kBottom, kTop}});
  const cf::gen::TaskResult r = cf::gen::decide(search, t);
  REQUIRE(r.witness.found);
  CHECK(search.verify(t.pcs, r.witness.pose) >= search.params().min_clearance);
  // A's bottom face lies in B's top plane, z = 10 (mm).
  for (int k = 0; k < 4; ++k)
    CHECK(r.witness.pose.apply(p.A.vertices()[static_cast<std::size_t>(k)].p).z() ==
          Approx(10).margin(1e-9));
  // A vertex of A on B's top face, and an edge of A on it: found too.
  t.pcs = PcSet({Pc{PcType::kVF, 0, kTop}});
  CHECK(cf::gen::decide(search, t).witness.found);
  t.pcs = PcSet({Pc{PcType::kEF, 0, kTop}});
  CHECK(cf::gen::decide(search, t).witness.found);
  CHECK_FALSE(search.refuted(t.pcs));  // a set with a witness is never refuted
}

TEST_CASE("decide: kVerify answers whether a pose is a witness, with its clearance", "[decide]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::WitnessSearch search(p.ai, p.bi, {});
  cf::gen::Task find;
  find.pcs = PcSet({Pc{PcType::kFF, kBottom, kTop}});
  const cf::gen::Witness w = cf::gen::decide(search, find).witness;
  REQUIRE(w.found);
  cf::gen::Task t;
  t.kind = cf::gen::Task::Kind::kVerify;
  t.pcs = find.pcs;
  t.pose = w.pose;
  const cf::gen::TaskResult r = cf::gen::decide(search, t);
  CHECK(r.witness.found);
  CHECK(r.witness.clearance == search.verify(t.pcs, t.pose));
  CHECK(r.witness.pose.t_BA == w.pose.t_BA);
  // 1 mm above the slab, A's bottom face does not touch B's top face: not a witness.
  t.pose.t_BA.z() += 1;
  CHECK_FALSE(cf::gen::decide(search, t).witness.found);
}

TEST_CASE(
    "decide: sets that cannot hold are not found, and those a necessary condition rules out are "
    "refuted",
    "[decide]") {
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"), cf::test::box(40, 40, 10, "B"));
  const cf::gen::WitnessSearch search(p.ai, p.bi, {});
  // Two faces of A on one face of B: one contact plane twice.
  const PcSet one_plane({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kFF, kTop, kTop}});
  CHECK_FALSE(search.plausible(one_plane));
  CHECK(search.refuted(one_plane));
  cf::gen::Task t;
  t.pcs = one_plane;
  CHECK_FALSE(cf::gen::decide(search, t).witness.found);
  // A's bottom on B's top and A's top on B's bottom: A above B and below it at once.
  t.pcs = PcSet({Pc{PcType::kFF, kBottom, kTop}, Pc{PcType::kFF, kTop, kBottom}});
  CHECK_FALSE(cf::gen::decide(search, t).witness.found);
  // One vertex of A in two PCs: a point lies in one open element.
  const PcSet one_vertex({Pc{PcType::kVF, 0, kTop}, Pc{PcType::kVF, 0, 2}});
  CHECK_FALSE(search.plausible(one_vertex));
  CHECK(search.refuted(one_vertex));
}

TEST_CASE("decide: a face forced onto a second wall is read where the search was blocked",
          "[decide]") {
  // A 10 mm cube in a slot exactly 10 mm wide (walls x = 20, normal +x, and x = 30, normal -x):
  // a face on one wall puts the opposite face on the other, so the single PC has no witness,
  // and the failed search reports the pair of PCs it met wherever it placed the contact.
  cf::test::AnalysedPair p(cf::test::box(10, 10, 10, "A"),
                           cf::test::from_oracle(oracle::make_u_channel(10, 20, 20, 40, 40), "U"));
  const cf::gen::WitnessSearch search(p.ai, p.bi, {});
  auto face_with = [](const cf::Polyhedron& m, const cf::Vec3& n, double d) {
    for (std::size_t f = 0; f < m.num_faces(); ++f)
      if ((m.faces()[f].normal - n).norm() < 1e-9 && std::abs(m.faces()[f].offset - d) < 1e-9)
        return static_cast<int>(f);
    return -1;
  };
  const int left = face_with(p.B, cf::Vec3::UnitX(), 20);
  const int right = face_with(p.B, -cf::Vec3::UnitX(), -30);
  const int a_left = face_with(p.A, -cf::Vec3::UnitX(), 0);  // box spans [0, 10]^3
  const int a_right = face_with(p.A, cf::Vec3::UnitX(), 10);
  REQUIRE(left >= 0);
  REQUIRE(right >= 0);
  REQUIRE(a_left >= 0);
  REQUIRE(a_right >= 0);
  cf::gen::Task t;
  t.pcs = PcSet({Pc{PcType::kFF, a_left, left}});
  const cf::gen::TaskResult r = cf::gen::decide(search, t);
  CHECK_FALSE(r.witness.found);
  CHECK_FALSE(search.refuted(t.pcs));  // open: it holds, only never alone
  const PcSet both({Pc{PcType::kFF, a_left, left}, Pc{PcType::kFF, a_right, right}});
  REQUIRE_FALSE(r.met.empty());
  for (const cf::gen::Discovery& d : r.met) {
    INFO("met {" << cf::to_string(d.pcs) << "}");
    CHECK(d.pcs.contains(t.pcs[0]));
    CHECK(d.pcs.size() > 1);
  }
  const bool pair_met = std::any_of(r.met.begin(), r.met.end(),
                                    [&](const cf::gen::Discovery& d) { return d.pcs == both; });
  CHECK(pair_met);
  // The pose it was met at is a witness of the pair, up to refining the translation.
  for (const cf::gen::Discovery& d : r.met)
    if (d.pcs == both) CHECK(search.refine(both, d.pose).found);
}
