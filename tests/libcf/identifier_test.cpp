#include <cf/identifier.hpp>

#include "fixtures.hpp"
#include "runtime_models.hpp"

#include <catch2/catch.hpp>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <thread>

// Counts every global allocation of this program, to prove that steps allocate nothing.
// GCC pairs the inlined std::allocator calls with these replacements and warns that free()
// meets operator new; both are replaced together here, so the pairing is right.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 11
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
namespace {
std::atomic<long> g_news{0};
}
void* operator new(std::size_t n) {
  g_news.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace {

using cf::CfId;
using cf::IdStatus;
using cf::Pc;
using cf::PcType;
using cf::Vec3;
namespace tm = cf::testmodels;

cf::Pose pose(const Eigen::Matrix3d& R, const Vec3& t) {
  cf::Pose p;
  p.R_BA = R;
  p.t_BA = t;
  return p;
}

using cf::test::edge_between;

cf::CfRecord record(std::vector<Pc> pcs) {
  cf::CfRecord r;
  r.pcs = cf::PcSet(pcs);
  return r;
}

// Cube (A) on the L-block (B), a hand-built graph:
//   0 {f-f 2:4}               cube flat on the slab top
//   1 {e-f e04:4}             on the edge x = y = -15 (A), after a 45-degree turn about z
//   2 {v-f 4:4}               on the end vertex (-15,-15,15) of that edge
//   3 {f-f 2:4, f-f 5:5}      in the corner: slab top and wall side
//   4 {v-f 0:4}               on the corner vertex 0
// Transitions (both ways): 0-1 change, 1-2 change, 1-4 change, 0-3 gain/lose.
struct Fixture {
  cf::Polyhedron a = tm::cube(), b = tm::l_block();
  int e04 = edge_between(a, 0, 4);
  cf::CfGraph graph;
  Fixture() {
    std::vector<cf::CfRecord> cfs = {record({{PcType::kFF, 2, 4}}), record({{PcType::kEF, e04, 4}}),
                                     record({{PcType::kVF, 4, 4}}),
                                     record({{PcType::kFF, 2, 4}, {PcType::kFF, 5, 5}}),
                                     record({{PcType::kVF, 0, 4}})};
    using K = cf::TransitionKind;
    std::vector<cf::Transition> tr = {
        {CfId(0), CfId(1), K::kChange}, {CfId(1), CfId(0), K::kChange},
        {CfId(1), CfId(2), K::kChange}, {CfId(2), CfId(1), K::kChange},
        {CfId(0), CfId(3), K::kGain},   {CfId(3), CfId(0), K::kLose},
        {CfId(1), CfId(4), K::kChange}, {CfId(4), CfId(1), K::kChange}};
    graph = cf::CfGraph::from_parts(a, b, cfs, tr);
  }
};

const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
const double kEdgeDrop = 15 * std::sqrt(2.0);  // centre height over the lowest edge at 45 deg

cf::Pose flat() { return pose(I, {70, 35.3, 40}); }
cf::Pose on_edge() {
  return pose(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()).toRotationMatrix(),
              {70, 20 + kEdgeDrop + 0.2, 40});
}
// On the same edge, tilted so that its end at z = -15 (vertex 0) is lower (paper Fig. 3).
// The e-f's angular tolerance is atan(1 mm / 30 mm) = 0.0333 rad; it dominates the v-f of
// vertex 0 up to a quarter of that (DetectionParams::dominance_fit).
cf::Pose tilted_edge(double angle = 0.005) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(-angle, Vec3::UnitX()).toRotationMatrix() *
                            Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ()).toRotationMatrix();
  return pose(R, {70, 20 + kEdgeDrop + 0.2, 40});
}
cf::Pose corner() { return pose(I, {35.2, 35.4, 40}); }
cf::Pose far() { return pose(I, {70, 80, 40}); }
cf::Pose on_vertex0() {
  const Eigen::Matrix3d R =
      Eigen::Quaterniond::FromTwoVectors(Vec3(-1, -1, -1).normalized(), Vec3(0, -1, 0))
          .toRotationMatrix();
  return pose(R, Vec3(70, 20.4, 40) - R * Vec3(-15, -15, -15));
}
cf::Pose on_vertex6() {  // vertex 6 (15,15,15) down: not in the graph
  const Eigen::Matrix3d R =
      Eigen::Quaterniond::FromTwoVectors(Vec3(1, 1, 1).normalized(), Vec3(0, -1, 0))
          .toRotationMatrix();
  return pose(R, Vec3(70, 20.4, 40) - R * Vec3(15, 15, 15));
}

}  // namespace

TEST_CASE("identification prefers the previous CF, then a neighbour, else the best fit",
          "[identifier]") {
  Fixture fx;
  cf::CfIdentifier id(fx.graph);

  const cf::Identification& r = id.step(flat());
  CHECK(r.status == IdStatus::kMatchedByFit);
  CHECK(r.cf == CfId(0));
  REQUIRE(r.num_cf_pcs == 1);
  CHECK(r.cf_pcs[0].pc == Pc{PcType::kFF, 2, 4});
  CHECK(r.cf_pcs[0].distance == Approx(0.3).margin(1e-9));
  CHECK(r.contacts.size() == 9);
  CHECK_FALSE(r.partial_cover);

  CHECK(id.step(flat()).status == IdStatus::kMatchedPrevious);
  CHECK(id.previous() == CfId(0));

  // Into the corner: the wall's plane is gained.
  CHECK(id.step(corner()).status == IdStatus::kMatchedNeighbour);
  CHECK(id.last().cf == CfId(3));
  CHECK(id.last().num_cf_pcs == 2);
  CHECK(id.step(flat()).status == IdStatus::kMatchedNeighbour);  // lose
  CHECK(id.last().cf == CfId(0));

  CHECK(id.step(far()).status == IdStatus::kNoContact);
  CHECK_FALSE(id.last().has_cf());
  CHECK_FALSE(id.previous().valid());
}

TEST_CASE(
    "a contact farther than the CF's own is apart until it touches; the CF is kept while it leaves",
    "[identifier]") {
  Fixture fx;
  cf::CfIdentifier id(fx.graph);
  // The cube on the slab (its bottom at y = t.y - 15) beside the wall (its side at
  // x = t.x - 15); the slab's top is y = 20, the wall's side x = 20.
  auto at = [](double floor_d, double wall_d) { return pose(I, {35 + wall_d, 35 + floor_d, 40}); };
  // Pressed on the floor (-0.1 mm), the wall 0.3 mm away: the floor alone, the wall apart.
  const cf::Identification& r = id.step(at(-0.1, 0.3));
  CHECK(r.status == IdStatus::kMatchedByFit);
  CHECK(r.cf == CfId(0));
  CHECK(r.partial_cover);
  CHECK(r.contacts.num_planes() == 2);
  // The wall's contact is reported as approaching: the face pair, 0.3 mm away, its normal
  // (into A) along +x.
  REQUIRE(r.num_approaching == 1);
  CHECK(r.approaching[0].pc.type == PcType::kFF);
  CHECK(r.approaching[0].distance == Approx(0.3).margin(1e-9));
  CHECK(r.approaching[0].R_WT.col(1).x() == Approx(1).margin(1e-12));
  // Approaching: still apart at 0.01 mm (witnesses keep non-contacts at least that far).
  CHECK(id.step(at(-0.1, 0.01)).status == IdStatus::kMatchedPrevious);
  CHECK(id.last().num_approaching == 1);
  // Touching (within touch_distance_mm = 0.001 mm): gained, no longer approaching.
  CHECK(id.step(at(-0.1, 0.0005)).status == IdStatus::kMatchedNeighbour);
  CHECK(id.last().cf == CfId(3));
  CHECK_FALSE(id.last().partial_cover);
  CHECK(id.last().num_approaching == 0);
  // Leaving: the CF is kept while the wall's contact is within epsilon.
  CHECK(id.step(at(-0.1, 0.5)).status == IdStatus::kMatchedPrevious);
  CHECK(id.last().cf == CfId(3));
  CHECK(id.step(at(-0.1, 1.2)).status == IdStatus::kMatchedNeighbour);  // beyond epsilon: lose
  CHECK(id.last().cf == CfId(0));
  // Without history the nearest contacts decide: a CF cannot leave out a contact nearer
  // than its own PCs.
  id.reset();
  CHECK(id.step(at(-0.1, 0.5)).cf == CfId(0));
  id.reset();
  CHECK(id.step(at(0, 0.01)).cf == CfId(0));  // a witness of CF 0 with a near pair 0.01 mm away
  id.reset();
  CHECK(id.step(at(0.4, 0.2)).cf == CfId(3));  // the floor alone would leave out the nearer wall
  id.reset();
  CHECK(id.step(at(0.3, 0.3)).cf == CfId(3));  // equally near: both
  // touch_distance_mm is a parameter.
  cf::Params p;
  p.identification.touch_distance_mm = 0.5;
  cf::CfIdentifier wide(fx.graph, p);
  CHECK(wide.step(at(-0.1, 0.3)).cf == CfId(3));
  p.identification.touch_distance_mm = -1;
  CHECK_THROWS_WITH(
      cf::CfIdentifier(fx.graph, p),
      Catch::Contains("identification.touch_distance_mm = -1 is outside [0, 1000000] mm"));
}

TEST_CASE("the ambiguity of paper Fig. 3: the undominated reading wins, else history",
          "[identifier]") {
  Fixture fx;
  cf::CfIdentifier id(fx.graph);
  // The edge tilted by 0.005 rad (0.15 of the angular tolerance): e-f, with the v-f of its
  // lower end vertex 0 as a dominated alternative. From nothing: e-f.
  const cf::Identification& r = id.step(tilted_edge());
  CHECK(r.status == IdStatus::kMatchedByFit);
  CHECK(r.cf == CfId(1));
  bool vf0 = false;
  for (const cf::ContactPc& c : r.contacts) vf0 |= c.pc == Pc{PcType::kVF, 0, 4} && c.dominated;
  CHECK(vf0);
  // Standing on vertex 0 first (CF 4), then tilting down onto the edge: the e-f is a
  // neighbour (change) and is not dominated, so it takes over.
  id.reset();
  CHECK(id.step(on_vertex0()).cf == CfId(4));
  CHECK(id.step(tilted_edge()).status == IdStatus::kMatchedNeighbour);
  CHECK(id.last().cf == CfId(1));
  CHECK(id.step(on_edge()).status == IdStatus::kMatchedPrevious);

  // Tilted by 0.015 rad (0.45 of the tolerance; about the centre, so vertex 0 is 0.02 mm
  // into the slab and vertex 4 0.43 mm above it): both readings stand, none dominated. From
  // nothing the v-f fits better (misfit 0.02 against 0.47); from the edge the e-f is kept,
  // from the vertex the v-f.
  id.reset();
  const cf::Identification& half = id.step(tilted_edge(0.015));
  CHECK(half.cf == CfId(4));
  bool undominated = true;
  for (const cf::ContactPc& c : half.contacts) undominated = undominated && !c.dominated;
  CHECK(undominated);
  CHECK(half.contacts.size() == 3);  // e-f, v-f of vertices 0 and 4
  id.step(on_edge());
  CHECK(id.step(tilted_edge(0.015)).status == IdStatus::kMatchedPrevious);
  CHECK(id.last().cf == CfId(1));
  id.step(on_vertex0());
  CHECK(id.step(tilted_edge(0.015)).status == IdStatus::kMatchedPrevious);
  CHECK(id.last().cf == CfId(4));
}

TEST_CASE("contacts outside the graph and jumps are reported, not hidden", "[identifier]") {
  Fixture fx;
  cf::CfIdentifier id(fx.graph);
  const cf::Identification& r = id.step(on_vertex6());
  CHECK(r.status == IdStatus::kOutsideGraph);
  CHECK_FALSE(r.has_cf());
  REQUIRE(r.contacts.size() == 1);
  CHECK(r.contacts[0].pc == Pc{PcType::kVF, 6, 4});

  id.step(on_vertex0());
  CHECK(id.last().status == IdStatus::kMatchedByFit);
  CHECK(id.last().cf == CfId(4));
  // From the corner vertex straight to the L's corner: CF 3 fits, but is no neighbour.
  CHECK(id.step(corner()).status == IdStatus::kNonNeighbourJump);
  CHECK(id.last().cf == CfId(3));
  CHECK(std::string(cf::to_string(IdStatus::kNonNeighbourJump)) == "non-neighbour-jump");
}

TEST_CASE("identification steps allocate nothing", "[identifier]") {
  Fixture fx;
  cf::CfIdentifier id(fx.graph);
  const cf::Pose poses[] = {flat(), corner(),     on_edge(),   tilted_edge(),
                            far(),  on_vertex0(), on_vertex6()};
  id.step(flat());  // warm up (nothing is lazily allocated, but be fair)
  const long before = g_news.load();
  for (int k = 0; k < 50; ++k)
    for (const cf::Pose& p : poses) id.step(p);
  CHECK(g_news.load() - before == 0);
}

TEST_CASE("one identifier per thread over one shared graph", "[identifier]") {
  Fixture fx;
  const cf::Pose poses[] = {flat(), corner(), on_edge(), tilted_edge(), far(), on_vertex0()};
  std::vector<int> expect;
  {
    cf::CfIdentifier id(fx.graph);
    for (int k = 0; k < 20; ++k)
      for (const cf::Pose& p : poses) expect.push_back(id.step(p).cf.value());
  }
  std::vector<int> got[2];
  auto run = [&](int t) {
    cf::CfIdentifier id(fx.graph);
    for (int k = 0; k < 20; ++k)
      for (const cf::Pose& p : poses) got[t].push_back(id.step(p).cf.value());
  };
  std::thread t0(run, 0), t1(run, 1);
  t0.join();
  t1.join();
  CHECK(got[0] == expect);
  CHECK(got[1] == expect);
}
