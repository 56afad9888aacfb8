#pragma once
// A simulated operator for the servo loop: a device handle of mass m_d (kg) held by a hand
// that is a spring and damper (human-like: 1 N/mm, 0.02 N s/mm) pulling it towards a
// scripted target, and pushed by the wrench the loop writes. Its ticks come from a real
// clock at the servo rate (sleep_until), so the loop's timing is measured as on a device.
// Translation only: the hand keeps A's attitude.

#include "device.hpp"

#include <chrono>
#include <functional>
#include <thread>

namespace haptic_loop {

class SimulatedHand final : public Device {
 public:
  /// @param script  the hand's target at time t (s): where it would put the grip point.
  SimulatedHand(double rate_hz, double duration_s, std::function<cf::Vec3(double)> script)
      : period_(std::chrono::nanoseconds(static_cast<long long>(1e9 / rate_hz))),
        dt_s_(1.0 / rate_hz),
        ticks_(static_cast<long long>(duration_s * rate_hz)),
        script_(std::move(script)),
        x_mm_(script_(0)) {}

  cf::Pose read_pose() override {
    cf::Pose p;
    p.t_BA = x_mm_;
    return p;
  }

  void write_wrench(const cf::Vec3& F_W, const cf::Vec3&) override {
    // The handle's dynamics over one tick (semi-implicit Euler): the hand's spring and damper
    // towards its target, plus the rendered force. mm, s, kg: a = F / m in N / kg = m/s^2.
    const cf::Vec3 target = script_(t_s());
    const cf::Vec3 F_hand =
        kHandStiffness_N_per_mm * (target - x_mm_) - kHandDamping_N_s_per_mm * v_mm_s_;
    const cf::Vec3 a_mm_s2 = 1000.0 * (F_hand + F_W) / kHandleMass_kg;
    v_mm_s_ += a_mm_s2 * dt_s_;
    x_mm_ += v_mm_s_ * dt_s_;
  }

  bool wait_next_tick() override {
    if (tick_ == 0) next_ = std::chrono::steady_clock::now();
    if (tick_ >= ticks_) return false;
    next_ += period_;
    std::this_thread::sleep_until(next_);
    late_ = std::chrono::steady_clock::now() - next_;
    ++tick_;
    return true;
  }

  double t_s() const { return static_cast<double>(tick_) * dt_s_; }
  /// How late the last tick woke up after it was due.
  std::chrono::nanoseconds late() const {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(late_);
  }

  static constexpr double kHandStiffness_N_per_mm = 1.0;
  static constexpr double kHandDamping_N_s_per_mm = 0.02;
  static constexpr double kHandleMass_kg = 0.1;

 private:
  std::chrono::nanoseconds period_;
  double dt_s_;
  long long ticks_, tick_ = 0;
  std::function<cf::Vec3(double)> script_;
  cf::Vec3 x_mm_, v_mm_s_ = cf::Vec3::Zero();
  std::chrono::steady_clock::time_point next_;
  std::chrono::steady_clock::duration late_{};
};

}  // namespace haptic_loop
