#pragma once

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"

namespace autograv {

/// A 3-DoF impedance haptic device, as CHAI3D's cGenericHapticDevice presents one: the same method
/// names and the same "true means success" return values, with Eigen types and SI units.
///
/// Frame (CHAI3D's): x toward the operator, y to the right, z up; gravity points along -z.
/// Everything the estimator knows about a device comes through this interface, exactly as a real
/// driver would give it: measured (quantized, noisy) positions and estimated velocities.
///
/// Real-time contract: getPosition, getLinearVelocity, getUserSwitch and setForce are called from
/// the servo loop (1 kHz or faster) and must not allocate, lock or throw in implementations that
/// claim real-time safety. open, close and calibrate are not real-time safe.
class HapticDevice {
 public:
  virtual ~HapticDevice() = default;

  /// Opens the connection to the device. Not real-time safe.
  virtual bool open() = 0;
  /// Closes the connection; sends zero force first. Not real-time safe.
  virtual bool close() = 0;
  /// Runs the device's own encoder homing. `force` redoes it even if already done.
  /// Returns false when the device is not calibrated and cannot calibrate itself.
  /// Not real-time safe.
  virtual bool calibrate(bool force = false) = 0;

  /// Latest measured end-effector position. Unit: [m]
  virtual bool getPosition(Eigen::Vector3d& position_m) = 0;
  /// Latest estimated end-effector velocity. Unit: [m/s]
  virtual bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) = 0;
  /// State of user switch `index` (0 = the stylus button).
  virtual bool getUserSwitch(int index, bool& pressed) = 0;
  /// Commands a force on the end-effector. Unit: [N]
  virtual bool setForce(const Eigen::Vector3d& force_n) = 0;

  /// What the device says about itself. Valid after open().
  virtual const DeviceSpecifications& specifications() const = 0;
};

}  // namespace autograv
