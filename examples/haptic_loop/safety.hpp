#pragma once
// What stands between the renderer and a real device (examples/haptic_loop/README.md):
//   - the workspace map: the device's pose (its own frame, mm) to the scene's, with a
//     scale, a rotation and an offset, and the wrench back to the device's frame;
//   - the stiffness the device can render stably once the workspace is scaled;
//   - the wrench guard: forces ramped in over a stated time at start, saturated at the
//     device's force and torque limits (direction kept), torque dropped on a force-only
//     (3-DOF) device, and zero on a tick woken more than watchdog_periods late.
// Header only, no allocation: the servo thread calls it every tick.

#include <cf/params.hpp>
#include <cf/types.hpp>

#include <algorithm>

namespace haptic_loop {

/// What the device can do (from its data sheet).
struct DeviceLimits {
  double max_force_N = 3.3;  ///< N, continuous force at the handle (3D Systems Touch: 3.3)
  /// N mm, torque at the handle; 0 for a force-only (3-DOF) device: the moment is dropped.
  double max_torque_Nmm = 0;
  /// N/mm: the largest stiffness the device renders stably at its servo rate (Touch: about
  /// 1 N/mm; Force Dimension omega.6: 14.5 N/mm).
  double max_stiffness_N_per_mm = 1.0;
  double ramp_s = 0.5;            ///< s: forces rise linearly from 0 over this at start
  double watchdog_periods = 2.0;  ///< a tick woken more periods late than this writes zero
};

/// The device's workspace in the scene: p_scene = R_WD (scale p_device) + p_W_origin, the
/// handle's attitude turned by R_WD too. scale > 1 lets a small device reach a large scene.
struct Workspace {
  double scale = 1;  ///< scene mm per device mm (> 0)
  cf::Mat3 R_WD = cf::Mat3::Identity();
  cf::Vec3 p_W_origin = cf::Vec3::Zero();  ///< mm: where the device's origin is in the scene

  /// The scene pose of the handle (A's pose for the renderer) from the device's reading.
  cf::Pose to_scene(const cf::Pose& X_DH) const {
    cf::Pose X_WH;
    X_WH.R_BA = R_WD * X_DH.R_BA;
    X_WH.t_BA = R_WD * (scale * X_DH.t_BA) + p_W_origin;
    return X_WH;
  }
  /// A scene force (N) in the device's axes: forces do not scale.
  cf::Vec3 force_to_device(const cf::Vec3& F_W) const { return R_WD.transpose() * F_W; }
  /// A scene moment (N mm) in the device's axes: its arms are `scale` times shorter there.
  cf::Vec3 torque_to_device(const cf::Vec3& M_W) const { return R_WD.transpose() * M_W / scale; }
};

/// The renderer's stiffnesses lowered to what the device renders stably: a device motion d
/// is a scene motion scale d, so a scene stiffness K is felt as K scale at the handle.
/// Returns `p` with stiffness_N_per_mm and proxy.coupling_stiffness_N_per_mm at most
/// max_stiffness_N_per_mm / scale (kp_N_per_mm, the friction spring, too).
inline cf::Params stable_params(cf::Params p, const DeviceLimits& d, const Workspace& w) {
  const double k = d.max_stiffness_N_per_mm / w.scale;
  p.contact_stiffness_N_per_mm = std::min(p.contact_stiffness_N_per_mm, k);
  p.proxy.coupling_stiffness_N_per_mm = std::min(p.proxy.coupling_stiffness_N_per_mm, k);
  p.kp_N_per_mm = std::min(p.kp_N_per_mm, k);
  return p;
}

/// The wrench written to the device, in its axes.
struct DeviceWrench {
  cf::Vec3 F_N = cf::Vec3::Zero();
  cf::Vec3 M_Nmm = cf::Vec3::Zero();
  bool saturated = false;  ///< the force or torque was cut to its limit this tick
  bool zeroed = false;     ///< zero: the tick woke too late, or the wrench was not finite
};

/// `v` shortened to length `limit` when longer (direction kept).
inline cf::Vec3 saturate(const cf::Vec3& v, double limit, bool* cut) {
  const double n = v.norm();
  if (!(n > limit)) return v;
  *cut = true;
  return v * (limit / n);
}

/// The scene wrench F_W (N), M_W (N mm) at time t_s since the loop started, with the tick
/// woken late_periods servo periods late, as the device may take it.
inline DeviceWrench guard_wrench(const cf::Vec3& F_W, const cf::Vec3& M_W, double t_s,
                                 double late_periods, const DeviceLimits& d, const Workspace& w) {
  DeviceWrench out;
  if (late_periods > d.watchdog_periods || !F_W.allFinite() || !M_W.allFinite()) {
    out.zeroed = true;
    return out;
  }
  const double ramp = d.ramp_s > 0 ? std::clamp(t_s / d.ramp_s, 0.0, 1.0) : 1.0;
  out.F_N = saturate(ramp * w.force_to_device(F_W), d.max_force_N, &out.saturated);
  if (d.max_torque_Nmm > 0)
    out.M_Nmm = saturate(ramp * w.torque_to_device(M_W), d.max_torque_Nmm, &out.saturated);
  return out;
}

}  // namespace haptic_loop
