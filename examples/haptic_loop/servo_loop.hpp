#pragma once
// The servo loop, on any Device (device.hpp): read the pose, map it into the scene, step the
// renderer, guard the wrench (safety.hpp), write it, wait for the next tick. An exception
// anywhere in a tick writes a zero wrench and ends the loop cleanly, with the reason. The
// loop measures its own lateness against its start and period, whatever the device.
// Allocates nothing per tick; on_tick(i, result, written, late_s, step_s) records what it
// needs (step_s: the renderer's time for the tick).

#include "device.hpp"
#include "safety.hpp"

#include <cf/renderer.hpp>

#include <pthread.h>
#include <sched.h>

#include <chrono>
#include <cstring>
#include <exception>
#include <string>

namespace haptic_loop {

struct LoopStatus {
  long long ticks = 0;      ///< ticks stepped
  long long saturated = 0;  ///< ticks whose wrench was cut to the device's limits
  long long zeroed = 0;     ///< ticks that wrote zero (the watchdog, or a wrench not finite)
  bool failed = false;      ///< an exception ended the loop (a zero wrench was written)
  std::string error;        ///< its message
};

/// Asks for real-time scheduling (SCHED_FIFO) of the calling thread. Empty when granted,
/// else why not and what to do (the loop then runs at normal priority).
inline std::string request_realtime(int priority = 80) {
  sched_param sp{};
  sp.sched_priority = priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (rc == 0) return "";
  return std::string("real-time priority not granted (") + std::strerror(rc) +
         "): give the program CAP_SYS_NICE or an rtprio limit (/etc/security/limits.conf); "
         "the servo loop runs at normal priority";
}

template <class OnTick>
LoopStatus run_servo(Device& device, const cf::CfModel& model, cf::CfState& state,
                     const DeviceLimits& limits, const Workspace& workspace, double period_s,
                     long long max_ticks, OnTick&& on_tick) {
  using Clock = std::chrono::steady_clock;
  LoopStatus s;
  Clock::time_point start;
  try {
    while (s.ticks < max_ticks && device.wait_next_tick()) {
      const Clock::time_point now = Clock::now();
      if (s.ticks == 0) start = now;
      const double t_s = static_cast<double>(s.ticks) * period_s;
      const double late_s =
          std::chrono::duration<double>(now - start).count() - t_s;  // behind the schedule
      const cf::Pose X_WD = workspace.to_scene(device.read_pose());
      const Clock::time_point a = Clock::now();
      const cf::HapticResult& out = cf::step(model, state, X_WD, t_s);
      const double step_s = std::chrono::duration<double>(Clock::now() - a).count();
      const DeviceWrench w =
          guard_wrench(out.F_W, out.M_W, t_s, late_s / period_s, limits, workspace);
      device.write_wrench(w.F_N, w.M_Nmm);
      s.saturated += w.saturated ? 1 : 0;
      s.zeroed += w.zeroed ? 1 : 0;
      on_tick(s.ticks, out, w, late_s, step_s);
      ++s.ticks;
    }
  } catch (const std::exception& e) {
    s.failed = true;
    s.error = e.what();
  } catch (...) {
    s.failed = true;
    s.error = "unknown exception";
  }
  if (s.failed) {
    try {
      device.write_wrench(cf::Vec3::Zero(), cf::Vec3::Zero());
    } catch (...) {  // nothing more can be done for the device; the loop reports the first
    }
  }
  return s;
}

}  // namespace haptic_loop
