// The device safety layer and the servo loop of examples/haptic_loop (safety.hpp,
// servo_loop.hpp): the workspace map, the stiffness a device renders stably, the wrench
// guard (limits, force-only, ramp, watchdog), and the loop driven by a simulated 6-DOF hand
// pressing the cube onto the L-block's floor while turning it: limits and ramp held on every
// tick, a late tick zeroed, an exception ending the loop with a zero wrench.

#include "servo_loop.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

using cf::Vec3;
using haptic_loop::DeviceLimits;
using haptic_loop::Workspace;

cf::Mat3 turn_y(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }

// Every wrench written, and the hand's 6-DOF script: down onto the L-block's floor (the cube
// touches it with its centre at y = 35 mm) and 10 mm past it, turning about y as it goes.
// Ticks are not paced (the loop runs as fast as it can) except where a test sleeps.
class ScriptedHand final : public haptic_loop::Device {
 public:
  int sleep_at = -1;       // the call of wait_next_tick that sleeps 3.5 ms first
  int throw_at = -1;       // the read_pose call that throws
  std::vector<Vec3> F, M;  // written, device axes

  cf::Pose read_pose() override {
    if (reads_++ == throw_at) throw std::runtime_error("device unplugged");
    const double t = 0.001 * static_cast<double>(reads_ - 1);
    cf::Pose p;
    p.t_BA = Vec3(70, 45 - 20 * std::min(t / 0.2, 1.0), 40);
    p.R_BA = turn_y(0.3 * t);
    return p;
  }
  void write_wrench(const Vec3& f, const Vec3& m) override {
    F.push_back(f);
    M.push_back(m);
  }
  bool wait_next_tick() override {
    if (waits_++ == sleep_at) std::this_thread::sleep_for(std::chrono::microseconds(3500));
    return true;
  }

 private:
  int reads_ = 0, waits_ = 0;
};

}  // namespace

TEST_CASE("the workspace maps the device's pose into the scene and the wrench back",
          "[haptic_loop]") {
  Workspace w;
  w.scale = 2;
  w.R_WD = turn_y(M_PI / 2);  // device x is scene -z
  w.p_W_origin = Vec3(100, 0, 0);
  cf::Pose X_DH;
  X_DH.t_BA = Vec3(10, 5, 0);
  const cf::Pose X_WH = w.to_scene(X_DH);
  CHECK((X_WH.t_BA - Vec3(100, 10, -20)).norm() < 1e-12);  // (20, 10, 0) turned, then offset
  CHECK((X_WH.R_BA - w.R_WD).norm() < 1e-15);
  // Forces keep their size; moments' arms are half as long at the device.
  CHECK((w.force_to_device(Vec3(0, 0, -3)) - Vec3(3, 0, 0)).norm() < 1e-12);
  CHECK((w.torque_to_device(Vec3(0, 0, -100)) - Vec3(50, 0, 0)).norm() < 1e-12);
}

TEST_CASE("the stiffnesses are lowered to what the device renders stably at the scale",
          "[haptic_loop]") {
  DeviceLimits d;
  d.max_stiffness_N_per_mm = 1.0;
  Workspace w;
  w.scale = 4;  // 1 mm of the hand is 4 mm in the scene: a scene stiffness K feels as 4 K
  const cf::Params p = haptic_loop::stable_params(cf::Params{}, d, w);
  CHECK(p.contact_stiffness_N_per_mm == 0.25);
  CHECK(p.proxy.coupling_stiffness_N_per_mm == 0.25);
  CHECK(p.kp_N_per_mm == 0.25);
  w.scale = 0.1;  // a stiffness the device can take is kept
  CHECK(haptic_loop::stable_params(cf::Params{}, d, w).contact_stiffness_N_per_mm == 2.3);
}

TEST_CASE(
    "the guard saturates, drops torque on a force-only device, ramps in and zeroes late "
    "ticks",
    "[haptic_loop]") {
  DeviceLimits d;
  d.max_force_N = 3.3;
  d.max_torque_Nmm = 0;  // force only
  d.ramp_s = 0.5;
  const Workspace w;
  const Vec3 F(0, 8, 6), M(100, 0, 0);  // 10 N
  haptic_loop::DeviceWrench out = haptic_loop::guard_wrench(F, M, 1.0, 0, d, w);
  CHECK(out.saturated);
  CHECK((out.F_N - 0.33 * F).norm() < 1e-12);  // 3.3 N along F
  CHECK(out.M_Nmm == Vec3::Zero());
  d.max_torque_Nmm = 40;
  out = haptic_loop::guard_wrench(F, M, 1.0, 0, d, w);
  CHECK((out.M_Nmm - Vec3(40, 0, 0)).norm() < 1e-12);
  // Ramp: nothing at the start, half way at half the ramp time.
  CHECK(haptic_loop::guard_wrench(F, M, 0.0, 0, d, w).F_N == Vec3::Zero());
  out = haptic_loop::guard_wrench(0.1 * F, Vec3::Zero(), 0.25, 0, d, w);
  CHECK((out.F_N - 0.05 * F).norm() < 1e-12);
  CHECK(!out.saturated);
  // Watchdog: more than two periods late, or a wrench that is not finite, writes zero.
  CHECK(!haptic_loop::guard_wrench(F, M, 1.0, 2.0, d, w).zeroed);
  out = haptic_loop::guard_wrench(F, M, 1.0, 2.01, d, w);
  CHECK(out.zeroed);
  CHECK(out.F_N == Vec3::Zero());
  CHECK(haptic_loop::guard_wrench(Vec3(std::nan(""), 0, 0), M, 1.0, 0, d, w).zeroed);
}

TEST_CASE(
    "the servo loop holds the limits and the ramp on every tick of a 6-DOF hand, zeroes a "
    "late tick and stops cleanly on an exception",
    "[haptic_loop]") {
  const cf::CfGraph g =
      cf::CfGraph::load(std::string(CF_SOURCE_DIR) + "/data/graphs/cube_l_block.json");
  DeviceLimits d;
  d.max_force_N = 3.3;
  d.max_torque_Nmm = 50;
  d.ramp_s = 0.05;
  const Workspace w;
  const cf::CfModel model(g, haptic_loop::stable_params(cf::Params{}, d, w));
  cf::CfState state(model);
  ScriptedHand hand;
  hand.sleep_at = 1;    // tick 1 wakes 2.5 periods late or more
  hand.throw_at = 400;  // 0.4 s: pressed 10 mm into the floor
  std::vector<double> t, rendered;
  std::vector<int> cf_id;
  const haptic_loop::LoopStatus s =
      haptic_loop::run_servo(hand, model, state, d, w, 0.001, 1000,
                             [&](long long, const cf::HapticResult& out,
                                 const haptic_loop::DeviceWrench&, double, double) {
                               t.push_back(out.t_s);
                               rendered.push_back(out.F_W.norm());
                               cf_id.push_back(out.cf.value());
                             });
  REQUIRE(s.failed);
  CHECK(s.error == "device unplugged");
  CHECK(s.ticks == 400);
  REQUIRE(hand.F.size() == 401);  // every tick's, then the zero wrench of the guard
  CHECK(hand.F.back() == Vec3::Zero());
  CHECK(hand.M.back() == Vec3::Zero());
  CHECK(s.zeroed >= 1);
  CHECK(hand.F[1] == Vec3::Zero());  // the late tick
  CHECK(s.saturated > 0);            // pressed 10 mm in: far more than 3.3 N rendered
  CHECK(cf_id[399] >= 0);            // and in contact
  for (std::size_t i = 0; i < hand.F.size(); ++i) {
    INFO("tick " << i);
    CHECK(hand.F[i].norm() <= 3.3 * (1 + 1e-12));
    CHECK(hand.M[i].norm() <= 50 * (1 + 1e-12));
    // Ramped in over 0.05 s: at most that share of the rendered force.
    if (i < 400) CHECK(hand.F[i].norm() <= std::min(1.0, t[i] / 0.05) * rendered[i] + 1e-9);
  }
}
