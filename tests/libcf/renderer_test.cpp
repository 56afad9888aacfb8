// HapticRenderer: status and motion bookkeeping over a small graph, the full servo step on
// the paper's cube and L-block, and no heap allocation inside step().

#include <cf/detector.hpp>
#include <cf/renderer.hpp>

#include "fixtures.hpp"
#include "runtime_models.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <new>
#include <set>

// Counts every allocation of this process (the test is single-threaded). malloc/free pair
// up here; GCC cannot see that through the replaced operators.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
static std::atomic<long> g_allocations{0};
void* operator new(std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  ++g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace {

constexpr double kTol = 1e-9;

using cf::test::from_loops;

// data/models/cube.off (30 mm, centred on its origin) and data/models/l_block.off: face 4
// of the L-block is the floor (y = 20), face 5 the inner wall (x = 20).
using cf::testmodels::cube;
using cf::testmodels::l_block;

const cf::Pc kFloor{cf::PcType::kFF, 2, 4};  // cube bottom on the floor
const cf::Pc kWall{cf::PcType::kFF, 5, 5};   // cube -x face on the inner wall

cf::Pose at(double x, double y, double z) {
  cf::Pose p;
  p.t_BA = {x, y, z};
  return p;
}

// Floor, wall and corner CFs with their gain/lose transitions.
cf::CfGraph corner_graph() {
  std::vector<cf::CfRecord> cfs(3);
  cfs[0].pcs = cf::PcSet({kFloor});
  cfs[0].witness = at(70, 35, 40);
  cfs[1].pcs = cf::PcSet({kWall});
  cfs[1].witness = at(35, 60, 40);
  cfs[2].pcs = cf::PcSet({kFloor, kWall});
  cfs[2].witness = at(35, 35, 40);
  std::vector<cf::Transition> tr = {{cf::CfId(0), cf::CfId(2), cf::TransitionKind::kGain},
                                    {cf::CfId(2), cf::CfId(0), cf::TransitionKind::kLose},
                                    {cf::CfId(1), cf::CfId(2), cf::TransitionKind::kGain},
                                    {cf::CfId(2), cf::CfId(1), cf::TransitionKind::kLose}};
  return cf::CfGraph::from_parts(cube(), l_block(), std::move(cfs), std::move(tr));
}

cf::ContactPc floor_pc(const cf::Pose& p) {
  cf::ContactPc c;
  c.pc = kFloor;
  c.p_W = p.apply({0, -15, 0});
  c.distance = c.p_W.y() - 20;
  c.origin_W = c.p_W - cf::Vec3(0, c.distance, 0);
  c.R_WT.col(0) = cf::Vec3(1, 0, 0);
  c.R_WT.col(1) = cf::Vec3(0, 1, 0);
  c.R_WT.col(2) = cf::Vec3(0, 0, 1);
  return c;
}
cf::ContactPc wall_pc(const cf::Pose& p) {
  cf::ContactPc c;
  c.pc = kWall;
  c.p_W = p.apply({-15, 0, 0});
  c.distance = c.p_W.x() - 20;
  c.origin_W = c.p_W - cf::Vec3(c.distance, 0, 0);
  c.R_WT.col(0) = cf::Vec3(0, 0, 1);
  c.R_WT.col(1) = cf::Vec3(1, 0, 0);
  c.R_WT.col(2) = cf::Vec3(0, 1, 0);
  return c;
}

// An identification result as an application could fill it: the CF (-1: none) and its PCs,
// and every detected contact. The status is what CfIdentifier would say of it.
std::unique_ptr<cf::Identification> identification(int cf, const std::vector<cf::ContactPc>& cf_pcs,
                                                   const std::vector<cf::ContactPc>& detected) {
  auto id = std::make_unique<cf::Identification>();
  id->cf = cf::CfId(cf);
  id->status = cf >= 0            ? cf::IdStatus::kMatchedByFit
               : detected.empty() ? cf::IdStatus::kNoContact
                                  : cf::IdStatus::kOutsideGraph;
  for (const cf::ContactPc& c : cf_pcs) {
    id->cf_pcs[static_cast<std::size_t>(id->num_cf_pcs++)] = c;
    id->pcs.insert(c.pc);
  }
  for (const cf::ContactPc& c : detected) id->contacts.push(c);
  return id;
}

}  // namespace

TEST_CASE("renderer bookkeeping: CF, motion and status over given identifications", "[renderer]") {
  const cf::CfGraph g = corner_graph();
  cf::HapticRenderer r(g);
  double t = 0;
  auto tick = [&](const cf::Pose& p, int cf,
                  std::vector<cf::ContactPc> pcs) -> const cf::HapticResult& {
    t += 0.001;
    return r.step_identified(p, t, *identification(cf, pcs, pcs));
  };
  const cf::HapticResult& a = tick(at(70, 40, 40), -1, {});
  CHECK(a.status == cf::RenderStatus::kNoContact);
  CHECK(a.motion == cf::MotionType::kNone);
  CHECK((a.F_W - cf::Vec3(0, -4.9, 0)).norm() < kTol);

  const cf::HapticResult& b = tick(at(70, 35.5, 40), 0, {floor_pc(at(70, 35.5, 40))});
  CHECK(b.status == cf::RenderStatus::kOk);
  CHECK(b.motion == cf::MotionType::kMT1);
  CHECK(b.cf == cf::CfId(0));
  CHECK(b.force->pcs[0].F_cy == Approx(1.15).margin(kTol));

  CHECK(tick(at(70, 35.5, 40), 0, {floor_pc(at(70, 35.5, 40))}).motion == cf::MotionType::kMT2a);

  const cf::Pose c = at(35.4, 35.5, 40);
  const cf::HapticResult& gain = tick(c, 2, {wall_pc(c), floor_pc(c)});  // any order
  CHECK(gain.motion == cf::MotionType::kMT4);
  CHECK(gain.status == cf::RenderStatus::kOk);
  CHECK(gain.pcs.size() == 2);
  CHECK(gain.force->pcs[1].pc == kWall);
  CHECK(gain.force->pcs[1].gained);

  const cf::HapticResult& lose = tick(at(36.0, 35.5, 40), 0, {floor_pc(at(36.0, 35.5, 40))});
  CHECK(lose.motion == cf::MotionType::kMT5);

  // CF 0 -> CF 1 is not a transition of the graph: rendered conservatively and flagged.
  const cf::HapticResult& jump = tick(at(35.5, 60, 40), 1, {wall_pc(at(35.5, 60, 40))});
  CHECK(jump.status == cf::RenderStatus::kUnlistedTransition);
  CHECK(jump.motion == cf::MotionType::kNone);
  CHECK(jump.force->conservative);
  CHECK(jump.force->pcs[0].regime == cf::Regime::kKinetic);

  // Contacts that no CF fits.
  std::vector<cf::ContactPc> odd = {floor_pc(at(35.5, 35.5, 40))};
  t += 0.001;
  const cf::HapticResult& nf =
      r.step_identified(at(35.5, 35.5, 40), t, *identification(-1, {}, odd));
  CHECK(nf.status == cf::RenderStatus::kNoFittingCf);
  CHECK(std::string(nf.identification) == "outside-graph");
  CHECK(nf.cf == cf::CfId());
  CHECK(nf.force->num_pcs == 1);
  CHECK(std::string(cf::to_string(nf.status)) == "no_fitting_cf");
}

TEST_CASE("full servo step: the cube lands on the L-block floor and slides into the corner",
          "[renderer]") {
  const cf::CfGraph g = corner_graph();
  cf::HapticRenderer r(g);
  double t = 0;
  // Descend from 5 mm above the floor to a 0.5 mm overlap of the threshold band, 10 um/tick.
  cf::Pose p = at(70, 40, 40);
  const cf::HapticResult* res = nullptr;
  bool saw_mt1 = false;
  for (int i = 0; i <= 450; ++i) {
    p.t_BA.y() = 40 - 0.01 * i;
    res = &r.step(p, t += 0.001);
    saw_mt1 = saw_mt1 || res->motion == cf::MotionType::kMT1;
  }
  CHECK(saw_mt1);
  REQUIRE(res->cf == cf::CfId(0));
  CHECK(res->motion == cf::MotionType::kMT2a);
  CHECK(res->force->pcs[0].distance == Approx(0.5).margin(1e-9));
  CHECK(res->F_W.y() == Approx(1.15 - 4.9).margin(1e-9));
  // Slide towards the wall, 20 um per tick, until the -x face is within 0.5 mm of it.
  bool saw_kinetic = false, saw_gain = false;
  while (p.t_BA.x() > 35.5 + 1e-9) {
    p.t_BA.x() -= 0.02;
    res = &r.step(p, t += 0.001);
    for (int k = 0; k < res->force->num_pcs; ++k)
      saw_kinetic = saw_kinetic || res->force->pcs[k].regime == cf::Regime::kKinetic;
    saw_gain = saw_gain || res->motion == cf::MotionType::kMT4;
  }
  CHECK(saw_kinetic);
  CHECK(saw_gain);
  CHECK(res->cf == cf::CfId(2));
  CHECK(res->status == cf::RenderStatus::kOk);
}

TEST_CASE("one parameter tree: epsilon, detection and identification reach the renderer's stages",
          "[renderer]") {
  const cf::CfGraph g = corner_graph();
  cf::Params P;
  P.epsilon_mm = 0.3;  // one epsilon: the detector's band and eq. (1)
  cf::HapticRenderer r(g, P);
  cf::Pose p = at(70, 35.5, 40);  // the cube's bottom face 0.5 mm above the floor
  CHECK(r.step(p, 0.001).status == cf::RenderStatus::kNoContact);
  p.t_BA.y() = 35.2;
  const cf::HapticResult& res = r.step(p, 0.002);
  REQUIRE(res.cf == cf::CfId(0));
  CHECK(res.F_W.y() == Approx(P.contact_stiffness_N_per_mm * (0.3 - 0.2) - 4.9).margin(1e-9));
  // All pairs instead of the hierarchies: the same wrench.
  cf::Params brute = P;
  brute.detection.use_bvh = false;
  cf::HapticRenderer rb(g, brute);
  rb.step(at(70, 35.5, 40), 0.001);
  CHECK(rb.step(p, 0.002).F_W == res.F_W);
  // Out-of-range values of the subtrees are refused by the stage that reads them.
  cf::Params bad = P;
  bad.detection.reuse_margin_mm = -1;
  CHECK_THROWS_WITH(
      cf::HapticRenderer(g, bad),
      Catch::Contains("parameter detection.reuse_margin_mm = -1 is outside [0, 1000000] mm"));
  bad = P;
  bad.identification.max_combinations = 0;
  CHECK_THROWS_WITH(
      cf::HapticRenderer(g, bad),
      Catch::Contains("cf::Params: parameter identification.max_combinations = 0 is below 1"));
}

TEST_CASE("a second plane's contact pushes from epsilon on, without a step at its gain",
          "[renderer]") {
  // The cube resting 0.5 mm into the floor's band slides towards the wall, 10 um per tick,
  // from 3 mm away to 0.2 mm into it. The wall's normal force (of its PC, or of its contact
  // while approaching) must follow eq. (1) tick by tick: at most K * 10 um of change per
  // tick. Without approaching contacts it steps at the gain, which comes when the wall is as
  // near as the CF's own PC (docs/runtime.md, Identification).
  const cf::CfGraph g = corner_graph();
  // Past the wall's surface the proxy (on by default) holds A at it, and the load is eq.
  // (1)'s K epsilon plus the constraint's, which keeps eq. (1)'s slope (docs/spec.md, section 6b).
  auto wall_push = [](const cf::HapticResult& res) {
    double f = 0;
    for (int k = 0; k < res.force->num_pcs + res.force->num_approaching; ++k) {
      const cf::PcForce& pf = res.force->pcs[k];
      if (pf.R_WT.col(1).x() > 0.99)
        f += pf.F_cy +
             (k < res.force->num_pcs ? res.constraint_load_N[static_cast<std::size_t>(k)] : 0.0);
    }
    return f;
  };
  for (const bool approaching : {true, false}) {
    cf::Params P;
    P.render_approaching = approaching;
    cf::HapticRenderer r(g, P);
    double t = 0, prev = 0, max_step = 0, first_push_gap = -1;
    bool gained = false;
    for (int i = 0; i <= 320; ++i) {
      const double gap = 3.0 - 0.01 * i;  // mm between the cube's -x face and the wall
      const cf::HapticResult& res = r.step(at(35 + gap, 35.5, 40), t += 0.001);
      const double f = wall_push(res);
      if (i > 0) max_step = std::max(max_step, std::abs(f - prev));
      if (f > 0 && first_push_gap < 0) first_push_gap = gap;
      gained = gained || res.cf == cf::CfId(2);
      prev = f;
    }
    CHECK(gained);
    CHECK(prev == Approx(2.3 * 1.2).margin(1e-6));  // 0.2 mm deep: K (epsilon - d)
    if (approaching) {
      CHECK(first_push_gap < 1.0);
      CHECK(first_push_gap > 0.98);
      // + the proxy's constraint loads, Gauss-Seidel's (it stops when a sweep moves the proxy
      // by less than 1e-5 mm: K times that per corner).
      CHECK(max_step <= 2.3 * 0.01 + 1e-4);
    } else {
      // Gained when as near as the floor's PC (0.5 mm, + touch_distance_mm): K (1 - 0.501).
      CHECK(max_step > 1.1);
    }
  }
}

TEST_CASE("the servo step allocates nothing", "[renderer]") {
  const cf::CfGraph g = corner_graph();
  cf::HapticRenderer r(g);
  cf::Pose p = at(70, 40, 40);
  double t = 0;
  r.step(p, t += 0.001);  // warm-up outside the count
  const auto given = identification(0, {floor_pc(at(70, 35.5, 40))}, {floor_pc(at(70, 35.5, 40))});
  const long before = g_allocations.load();
  for (int i = 0; i < 3000; ++i) {
    if (i < 450)
      p.t_BA.y() -= 0.01;  // land
    else if (p.t_BA.x() > 35.6)
      p.t_BA.x() -= 0.02;  // slide into the corner
    else
      p.t_BA.y() += 0.01;  // lift off the floor
    r.step(p, t += 0.001);
  }
  r.step_identified(at(70, 35.5, 40), t += 0.001, *given);
  CHECK(g_allocations.load() - before == 0);
}

namespace {

// data/models/corner_block.off: floor top y = 20 over x, z in [20, 120], inner walls x = 20
// and z = 20 up to y = 80.
cf::Polyhedron corner_block() {
  return from_loops("corner_block",
                    {{0, 0, 0},
                     {120, 0, 0},
                     {120, 0, 120},
                     {0, 0, 120},
                     {0, 80, 0},
                     {120, 80, 0},
                     {120, 80, 20},
                     {20, 80, 20},
                     {20, 80, 120},
                     {0, 80, 120},
                     {20, 20, 20},
                     {120, 20, 20},
                     {120, 20, 120},
                     {20, 20, 120}},
                    {{0, 1, 2, 3},
                     {9, 8, 7, 6, 5, 4},
                     {13, 12, 11, 10},
                     {0, 3, 9, 4},
                     {0, 4, 5, 1},
                     {1, 5, 6, 11, 12, 2},
                     {3, 2, 12, 13, 8, 9},
                     {10, 7, 8, 13},
                     {10, 11, 6, 7}});
}

// Places A (rotation R) so that its lowest vertex is `gap` above y = 20 and, when walls
// are given, its extreme vertices `gap` off the planes x = 20 and z = 20.
cf::Pose seat(const cf::Mat3& R, bool wall_x, bool wall_z, double x, double z, double gap = 0.5) {
  const cf::Polyhedron A = cube();
  cf::Vec3 lo = cf::Vec3::Constant(1e9);
  for (const cf::Vertex& v : A.vertices()) lo = lo.cwiseMin(R * v.p);
  cf::Pose p;
  p.R_BA = R;
  p.t_BA = {wall_x ? 20 + gap - lo.x() : x, 20 + gap - lo.y(), wall_z ? 20 + gap - lo.z() : z};
  return p;
}

// Runs poses through a renderer whose graph is made from what the detector finds at them:
// every distinct set of best-fitting non-dominated contacts (one per contact plane) is a
// CF, consecutive sets are joined by gain / lose / change transitions. Returns the last
// result.
struct Scenario {
  std::unique_ptr<cf::CfGraph> graph;
  std::unique_ptr<cf::HapticRenderer> renderer;
  const cf::HapticResult* last = nullptr;
};
Scenario run_scenario(const cf::Polyhedron& B, const std::vector<cf::Pose>& poses,
                      cf::MotionType stop_at = cf::MotionType::kNone) {
  const cf::Polyhedron A = cube();
  cf::ContactDetector det(A, B);
  auto set = std::make_unique<cf::ContactSet>();
  std::vector<cf::CfRecord> cfs;
  std::vector<cf::Transition> tr;
  int prev = -1;
  for (const cf::Pose& p : poses) {
    det.detect(p, *set);
    std::vector<int> best(static_cast<std::size_t>(set->num_planes()), -1);
    for (int i = 0; i < set->size(); ++i) {
      const cf::ContactPc& c = (*set)[i];
      if (c.dominated || c.plane < 0) continue;
      int& b = best[static_cast<std::size_t>(c.plane)];
      if (b < 0 || c.misfit < (*set)[b].misfit) b = i;
    }
    cf::PcSet pcs;
    for (int b : best)
      if (b >= 0) pcs.insert((*set)[b].pc);
    if (pcs.empty()) {
      prev = -1;
      continue;
    }
    int id = -1;
    for (std::size_t k = 0; k < cfs.size(); ++k)
      if (cfs[k].pcs == pcs) id = static_cast<int>(k);
    if (id < 0) {
      id = static_cast<int>(cfs.size());
      cf::CfRecord rec;
      rec.pcs = pcs;
      rec.witness = p;
      cfs.push_back(rec);
    }
    if (prev >= 0 && prev != id) {
      const cf::PcSet& a = cfs[static_cast<std::size_t>(prev)].pcs;
      const cf::TransitionKind k = pcs.size() > a.size()   ? cf::TransitionKind::kGain
                                   : pcs.size() < a.size() ? cf::TransitionKind::kLose
                                                           : cf::TransitionKind::kChange;
      bool have = false;
      for (const auto& t : tr) have = have || (t.from == cf::CfId(prev) && t.to == cf::CfId(id));
      if (!have) tr.push_back({cf::CfId(prev), cf::CfId(id), k});
    }
    prev = id;
  }
  Scenario s;
  s.graph =
      std::make_unique<cf::CfGraph>(cf::CfGraph::from_parts(A, B, std::move(cfs), std::move(tr)));
  s.renderer = std::make_unique<cf::HapticRenderer>(*s.graph);
  double t = 0;
  for (const cf::Pose& p : poses) {
    s.last = &s.renderer->step(p, t += 0.001);
    if (stop_at != cf::MotionType::kNone && s.last->motion == stop_at) break;
  }
  return s;
}

std::string types(const cf::HapticResult& r) {
  std::vector<std::string> v;
  for (const cf::Pc& pc : r.pcs) v.push_back(cf::to_string(pc.type));
  std::sort(v.begin(), v.end());
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : " ") + x;
  return s;
}

void print_row(const char* name, const cf::HapticResult& r) {
  if (std::getenv("CF_PRINT_PAPER_ROWS") == nullptr) return;
  std::printf(
      "%-28s %-14s %-6s F = %9.5f %9.5f %9.5f   M = %10.5f %10.5f %10.5f   Fc = %8.5f %8.5f %8.5f  "
      "[",
      name, types(r).c_str(), cf::to_string(r.motion), r.F_W.x(), r.F_W.y(), r.F_W.z(), r.M_W.x(),
      r.M_W.y(), r.M_W.z(), r.force->F_contact_W.x(), r.force->F_contact_W.y(),
      r.force->F_contact_W.z());
  for (int k = 0; k < r.force->num_pcs; ++k)
    std::printf("%s%s", k ? " " : "", cf::to_string(r.force->pcs[k].regime));
  std::printf("]\n");
}

cf::Mat3 rot(double ax, double ay, double az) {
  return (Eigen::AngleAxisd(ay, cf::Vec3::UnitY()) * Eigen::AngleAxisd(ax, cf::Vec3::UnitX()) *
          Eigen::AngleAxisd(az, cf::Vec3::UnitZ()))
      .toRotationMatrix();
}

}  // namespace

TEST_CASE("the paper's force table rows as scripted cases (docs/force-model.md)",
          "[renderer][paper]") {
  SECTION("row 1: {e-f, v-f} by MT4 against the L-block") {
    // An edge of the tilted, turned cube rests on the floor; it moves towards the inner wall
    // 0.1 mm per tick until a vertex touches it.
    const cf::Mat3 R = rot(0.3, 0.4, 0.0);
    std::vector<cf::Pose> poses;
    for (int i = 0; i <= 30; ++i) poses.push_back(seat(R, false, false, 0, 40));
    const double x_touch = seat(R, true, false, 0, 40).t_BA.x();
    for (int i = 0; i < 30; ++i)
      poses[static_cast<std::size_t>(i)].t_BA.x() = x_touch + 0.1 * (29 - i) + 0.6;
    poses.back().t_BA.x() = x_touch;
    const Scenario s = run_scenario(l_block(), poses, cf::MotionType::kMT4);
    print_row("row 1 (L-block)", *s.last);
    CHECK(types(*s.last) == "e-f v-f");
    CHECK(s.last->motion == cf::MotionType::kMT4);
  }
  SECTION("row 2: three f-f in the corner block's seat") {
    const cf::Mat3 R = cf::Mat3::Identity();
    std::vector<cf::Pose> poses;
    for (int i = 0; i < 5; ++i) poses.push_back(seat(R, true, true, 0, 0));
    for (int i = 1; i <= 5; ++i) {  // pressed diagonally into the seat, 0.02 mm per tick
      cf::Pose p = seat(R, true, true, 0, 0);
      p.t_BA -= cf::Vec3(0.02, 0.02, 0.02) * i;
      poses.push_back(p);
    }
    const Scenario s = run_scenario(corner_block(), poses);
    print_row("row 2 (corner, pressed)", *s.last);
    CHECK(types(*s.last) == "f-f f-f f-f");
    for (int k = 0; k < 3; ++k) CHECK(s.last->force->pcs[k].regime == cf::Regime::kStick);
    CHECK(s.last->motion == cf::MotionType::kMT2a);  // the paper prints MT2.b: see the docs
  }
  SECTION("row 3: {e-f, e-f, f-f} at rest in the corner block") {
    const cf::Mat3 R = rot(0.0, M_PI / 4, 0.0);  // vertical edges against both walls
    std::vector<cf::Pose> poses(5, seat(R, true, true, 0, 0));
    const Scenario s = run_scenario(corner_block(), poses);
    print_row("row 3 (corner, resting)", *s.last);
    CHECK(types(*s.last) == "e-f e-f f-f");
    CHECK(s.last->motion == cf::MotionType::kMT2a);
  }
  SECTION("row 4: {v-f, v-f, v-f} by MT3 in the corner block") {
    // An edge on the floor and vertices on both walls; then the cube tips about a
    // horizontal axis so that the edge on the floor becomes a vertex.
    const cf::Mat3 R0 = rot(0.25, 0.5, 0.0);
    std::vector<cf::Pose> poses(5, seat(R0, true, true, 0, 0));
    for (int i = 1; i <= 3; ++i)
      poses.push_back(
          seat(Eigen::AngleAxisd(0.02 * i, cf::Vec3(1, 0, 1).normalized()) * R0, true, true, 0, 0));
    const Scenario s = run_scenario(corner_block(), poses, cf::MotionType::kMT3);
    print_row("row 4 (corner, tipping)", *s.last);
    CHECK(types(*s.last) == "v-f v-f v-f");
    CHECK(s.last->motion == cf::MotionType::kMT3);
  }
}
