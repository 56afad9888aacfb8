#pragma once
// The seam between the servo loop and a haptic device: three calls per tick. A real device
// class implements it over its SDK; SimulatedHand (simulated_hand.hpp) is the one here.
//   CHAI3D:            read_pose: cGenericHapticDevice::getPosition/getRotation;
//                      write_wrench: setForceAndTorque; wait: the servo thread's own timer.
//   OpenHaptics (HD):  read_pose: hdGetDoublev(HD_CURRENT_TRANSFORM) inside a scheduler
//                      callback; write_wrench: hdSetDoublev(HD_CURRENT_FORCE/TORQUE);
//                      wait: hdScheduleSynchronous's servo tick.
//   Force Dimension:   read_pose: dhdGetPositionAndOrientationFrame; write_wrench:
//                      dhdSetForceAndTorque; wait: the loop's timer.
// Units are the library's: mm and N, N mm. Poses and wrenches are in the device's own frame;
// safety.hpp's Workspace maps them to and from the scene (B's frame).

#include <cf/types.hpp>

namespace haptic_loop {

class Device {
 public:
  virtual ~Device() = default;
  /// The device pose now: where the operator's hand holds the handle (mm, the device's frame).
  virtual cf::Pose read_pose() = 0;
  /// The wrench for the operator's hand: force (N) and moment about the grip point (N mm),
  /// the device's axes, within its limits (safety.hpp).
  virtual void write_wrench(const cf::Vec3& F_W, const cf::Vec3& M_W) = 0;
  /// Blocks until the next servo tick is due; false when the device stops the loop.
  virtual bool wait_next_tick() = 0;
};

}  // namespace haptic_loop
