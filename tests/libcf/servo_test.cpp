// The servo tick as stages over a shared CfModel and per-thread CfStates (cf/servo.hpp):
// the stages chained by hand are the renderer's step, one model serves several threads with
// results identical to one renderer's, a state refuses another model, and the previous CF
// advances in classify_motion alone.

#include <cf/renderer.hpp>
#include <cf/servo.hpp>

#include "trajectories.hpp"

#include <catch2/catch.hpp>

#include <set>
#include <string>
#include <thread>
#include <vector>

namespace {

const cf::CfGraph& cube_l_graph() {
  static const cf::CfGraph g =
      cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json");
  return g;
}
const std::vector<cf::testdata::Tick>& ticks() {
  static const std::vector<cf::testdata::Tick> t = cf::testdata::cube_lblock_ticks(CF_SOURCE_DIR);
  return t;
}

// What one tick rendered, compared exactly: the same code on the same inputs.
struct Rendered {
  int cf = -1;
  cf::RenderStatus status = cf::RenderStatus::kNoContact;
  cf::MotionType motion = cf::MotionType::kNone;
  cf::Vec3 F_W = cf::Vec3::Zero(), M_W = cf::Vec3::Zero();
  bool operator==(const Rendered& o) const {
    return cf == o.cf && status == o.status && motion == o.motion && F_W == o.F_W && M_W == o.M_W;
  }
};
Rendered rendered(const cf::HapticResult& r) {
  Rendered x;
  x.cf = r.cf.value();
  x.status = r.status;
  x.motion = r.motion;
  x.F_W = r.F_W;
  x.M_W = r.M_W;
  return x;
}

std::vector<Rendered> replay(const cf::CfModel& model) {
  cf::CfState state(model);
  std::vector<Rendered> out;
  for (const cf::testdata::Tick& k : ticks())
    out.push_back(rendered(cf::step(model, state, k.X_WA, k.t_s)));
  return out;
}

}  // namespace

TEST_CASE("the four stages chained by hand are the renderer's servo step", "[servo]") {
  const cf::CfGraph& g = cube_l_graph();
  REQUIRE(ticks().size() == 7405);
  cf::HapticRenderer renderer(g);
  const cf::CfModel model(g);
  cf::CfState state(model);
  std::set<cf::MotionType> motions;
  std::set<cf::RenderStatus> statuses;
  int differing = 0;
  for (const cf::testdata::Tick& k : ticks()) {
    const cf::ContactSet& contacts = cf::detect(model, state, k.X_WA);
    const cf::Identification& id = cf::identify(model, state, contacts);
    const cf::PriorMotion motion = cf::classify_motion(model, state, id);
    const cf::HapticResult& staged = cf::compute_force(model, state, k.X_WA, k.t_s, id, motion);
    const cf::HapticResult& whole = renderer.step(k.X_WA, k.t_s);
    if (!(rendered(staged) == rendered(whole))) ++differing;
    CHECK(state.previous() == renderer.state().previous());
    motions.insert(whole.motion);
    statuses.insert(whole.status);
  }
  CHECK(differing == 0);
  // The trajectory exercises the stages: first contact, kept CFs, gains, losses, no contact.
  for (cf::MotionType t : {cf::MotionType::kMT1, cf::MotionType::kMT2a, cf::MotionType::kMT4,
                           cf::MotionType::kMT5, cf::MotionType::kNone})
    CHECK(motions.count(t) == 1);
  CHECK(statuses.count(cf::RenderStatus::kOk) == 1);
  CHECK(statuses.count(cf::RenderStatus::kNoContact) == 1);
}

TEST_CASE("one CfModel serves several threads, each with its own CfState", "[servo]") {
  const cf::CfGraph& g = cube_l_graph();
  std::vector<Rendered> alone;
  {
    cf::HapticRenderer r(g);
    for (const cf::testdata::Tick& k : ticks()) alone.push_back(rendered(r.step(k.X_WA, k.t_s)));
  }
  const cf::CfModel shared(g);
  std::vector<Rendered> first, second;
  std::thread a([&] { first = replay(shared); });
  std::thread b([&] { second = replay(shared); });
  a.join();
  b.join();
  CHECK(first == alone);
  CHECK(second == alone);
  // A renderer on the shared model is the same object as one that built its own.
  cf::HapticRenderer on_shared(shared);
  CHECK(&on_shared.model() == &shared);
  CHECK(&on_shared.graph() == &g);
  std::vector<Rendered> third;
  for (const cf::testdata::Tick& k : ticks())
    third.push_back(rendered(on_shared.step(k.X_WA, k.t_s)));
  CHECK(third == alone);
}

TEST_CASE("a CfState is refused by a model it was not made for", "[servo]") {
  const cf::CfGraph& g = cube_l_graph();
  const cf::CfModel m1(g), m2(g);
  cf::CfState s(m1);
  const cf::Pose& X_WA = ticks().front().X_WA;
  CHECK_THROWS_WITH(cf::detect(m2, s, X_WA),
                    "cf::detect: the CfState was made for another CfModel");
  CHECK_THROWS_WITH(cf::step(m2, s, X_WA, 0.0),
                    "cf::move_proxy: the CfState was made for another CfModel");
  const cf::Identification id;
  CHECK_THROWS_WITH(cf::identify(m2, s, id.contacts),
                    "cf::identify: the CfState was made for another CfModel");
  CHECK_THROWS_WITH(cf::classify_motion(m2, s, id),
                    "cf::classify_motion: the CfState was made for another CfModel");
  CHECK_THROWS_WITH(cf::compute_force(m2, s, X_WA, 0.0, id, cf::PriorMotion()),
                    "cf::compute_force: the CfState was made for another CfModel");
  CHECK_NOTHROW(cf::step(m1, s, X_WA, 0.0));
}

TEST_CASE("identify reads the contacts it is given; the previous CF advances in classify_motion",
          "[servo]") {
  const cf::CfGraph& g = cube_l_graph();
  const cf::CfModel model(g);
  cf::CfState state(model), other(model);
  // The first tick of the bundled trajectories with a CF: the cube's first touch.
  const cf::testdata::Tick* touch = nullptr;
  {
    cf::CfState probe(model);
    for (const cf::testdata::Tick& k : ticks()) {
      if (cf::step(model, probe, k.X_WA, k.t_s).cf.valid()) {
        touch = &k;
        break;
      }
    }
  }
  REQUIRE(touch != nullptr);
  // An application's own copy of the contacts identifies as the state's own.
  const cf::ContactSet copy = cf::detect(model, other, touch->X_WA);
  REQUIRE_FALSE(copy.empty());
  const cf::Identification& mine = cf::identify(model, state, copy);
  const cf::Identification& theirs =
      cf::identify(model, other, cf::detect(model, other, touch->X_WA));
  REQUIRE(mine.has_cf());
  CHECK(mine.cf == theirs.cf);
  CHECK(mine.pcs == theirs.pcs);
  CHECK(state.contacts().size() == copy.size());
  // identify prefers the previous CF but does not move it.
  CHECK_FALSE(state.previous().valid());
  const cf::PriorMotion first = cf::classify_motion(model, state, mine);
  CHECK(first.type == cf::MotionType::kMT1);
  CHECK(first.transition_in_graph);
  CHECK(state.previous() == mine.cf);
  // The same CF again: kept (MT2, its case left to compute_force).
  const cf::PriorMotion again = cf::classify_motion(model, state, cf::identify(model, state, copy));
  CHECK(again.type == cf::MotionType::kMT2a);
  CHECK(state.previous() == mine.cf);
  // Contacts that fit no CF keep the previous CF; a tick without contact clears it.
  cf::Identification unfit;
  unfit.status = cf::IdStatus::kOutsideGraph;
  unfit.contacts = copy;
  CHECK(cf::classify_motion(model, state, unfit).type == cf::MotionType::kNone);
  CHECK(state.previous() == mine.cf);
  const cf::Identification nothing;
  CHECK(cf::classify_motion(model, state, nothing).type == cf::MotionType::kNone);
  CHECK_FALSE(state.previous().valid());
  // reset() forgets it too.
  cf::classify_motion(model, state, mine);
  REQUIRE(state.previous().valid());
  state.reset();
  CHECK_FALSE(state.previous().valid());
}
