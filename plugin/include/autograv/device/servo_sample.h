#pragma once

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"

namespace autograv {

/// What the servo loop read from the device this tick.
struct ServoSample {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();        ///< Unit: [m]
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();  ///< Unit: [m/s]
  /// False when a read failed or returned a non-finite value; the other fields are then unusable.
  bool valid = false;
};

/// Reads position and velocity; `valid` is false on a failed read or NaN/Inf.
/// Real-time safe when the device's getters are.
inline ServoSample readServoSample(HapticDevice& device) noexcept {
  ServoSample sample;
  const bool read =
      device.getPosition(sample.position_m) && device.getLinearVelocity(sample.velocity_m_per_s);
  sample.valid = read && sample.position_m.allFinite() && sample.velocity_m_per_s.allFinite();
  return sample;
}

/// Scales `force_n` down to `max_force_n` keeping its direction; returns true when it did.
/// Real-time safe.
inline bool clampForce(Eigen::Vector3d& force_n, double max_force_n) noexcept {
  const double norm = force_n.norm();
  if (norm <= max_force_n) return false;
  force_n *= max_force_n / norm;
  return true;
}

}  // namespace autograv
