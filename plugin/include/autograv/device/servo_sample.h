#pragma once

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"

namespace autograv {

/// How long a servo loop rides over invalid readings, holding the last force, before it counts
/// the device as gone: a dropped USB frame, not a dead device. Unit: [s]
inline constexpr double kMaxInvalidReadings_s = 0.02;
/// Rounding slack when servo time summed in nominal periods is compared with a duration.
/// Unit: [nominal servo periods]
inline constexpr double kServoTimeSlackPeriods = 1e-6;

/// What the servo loop read from the device this tick.
struct ServoSample {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();        ///< Unit: [m]
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();  ///< Unit: [m/s]
  /// False when a read failed or returned a non-finite value; the other fields are then unusable.
  bool valid = false;
  /// Servo time since the previous sample, from the loop's ServoClock: what the estimators
  /// integrate over, so that a late, jittery or free-running loop measures the same seconds as an
  /// exact one. Zero, negative or NaN: unknown, taken as one nominal servo period. Last, so that
  /// {position, velocity, valid} still reads as before. Unit: [s]
  double interval_s = 0.0;
};

/// The sample's interval in nominal servo periods: interval_s / nominal_period_s, or exactly 1
/// when the interval is unknown (and for an exact loop, where interval_s is the period itself).
/// Real-time safe.
inline double servoPeriodsOf(const ServoSample& sample, double nominal_period_s) noexcept {
  const double interval_s = sample.interval_s;
  if (!(interval_s > 0.0) || !(interval_s < 1e300)) return 1.0;
  return interval_s / nominal_period_s;
}

/// Reads position and velocity; `valid` is false on a failed read or NaN/Inf.
/// Real-time safe when the device's getters are.
/// `interval_s` is the servo time since the previous read (0: unknown, one nominal period).
inline ServoSample readServoSample(HapticDevice& device, double interval_s = 0.0) noexcept {
  ServoSample sample;
  sample.interval_s = interval_s;
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
