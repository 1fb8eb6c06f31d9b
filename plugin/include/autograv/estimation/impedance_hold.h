#pragma once

#include <Eigen/Core>
#include <algorithm>

#include "autograv/device/servo_sample.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv {

/// The apparent mass of eq. (11), M = max(|G|, floor) / g: constraint (6) needs |G| > 0, so an
/// estimate below `min_gravity_n` counts as that floor. Units: [N] in, [kg] out. Real-time safe.
inline double apparentMass_kg(const Eigen::Vector3d& gravity_n, double min_gravity_n) noexcept {
  return std::max(gravity_n.norm(), min_gravity_n) / kStandardGravity;
}

/// The paper's impedance hold, eq. (10) with the gains of eq. (11): the closed loop
/// Xdd = beta (X_D - X) - alpha Xd around the apparent mass M = |G| / g, so K_P = beta M and
/// K_D = alpha M. Every part of the library that holds or carries the end-effector with the
/// paper's gains (the estimator, the calibrator's moves, the wizard, the real-time demo) forms
/// its force here, so the law is written once.
///
/// Constraint (6) needs |G| > 0: the apparent mass has an explicit floor, passed by each user
/// (0.01 N for the estimator, the calibrator and the wizard; the real-time demo's handover keeps
/// its own 0.02 N): each part keeps the floor it always had, so no figure moves. Every member is
/// real-time safe.
struct ImpedanceHold {
  /// Closed-loop stiffness. Unit: [1/s^2]
  double beta_per_s2 = 0.0;
  /// Closed-loop damping. Unit: [1/s]
  double alpha_per_s = 0.0;
  /// |G| below this counts as this when the apparent mass is formed. Unit: [N]
  double min_gravity_n = 0.0;

  /// The gains of `parameters` with the floor `min_gravity_n`.
  static ImpedanceHold from(const EstimationParameters& parameters, double min_gravity_n) noexcept {
    return ImpedanceHold{parameters.beta_per_s2, parameters.alpha_per_s, min_gravity_n};
  }

  /// M = max(|G|, min_gravity_n) / g (the free apparentMass_kg). Unit: [kg]
  double apparentMass_kg(const Eigen::Vector3d& gravity_n) const noexcept {
    return autograv::apparentMass_kg(gravity_n, min_gravity_n);
  }
  /// K_P = beta M. Unit: [N/m]
  double stiffness_n_per_m(double mass_kg) const noexcept { return beta_per_s2 * mass_kg; }
  /// K_D = alpha M. Unit: [N s/m]
  double damping_n_s_per_m(double mass_kg) const noexcept { return alpha_per_s * mass_kg; }

  /// Eq. (10) holding `target_m`: K_P (X_D - X) - K_D Xd + feedforward, unclamped. Unit: [N]
  Eigen::Vector3d holdForce_n(const Eigen::Vector3d& target_m, const ServoSample& sample,
                              double mass_kg, const Eigen::Vector3d& feedforward_n) const noexcept {
    return beta_per_s2 * mass_kg * (target_m - sample.position_m) -
           alpha_per_s * mass_kg * sample.velocity_m_per_s + feedforward_n;
  }

  /// Eq. (10) tracking a moving target, with the path's acceleration fed forward:
  /// K_P (X_D - X) + K_D (Xd_D - Xd) + M Xdd_D + feedforward, unclamped. Unit: [N]
  Eigen::Vector3d trackForce_n(const Eigen::Vector3d& desired_m,
                               const Eigen::Vector3d& desired_velocity_m_per_s,
                               const Eigen::Vector3d& desired_acceleration_m_per_s2,
                               const ServoSample& sample, double mass_kg,
                               const Eigen::Vector3d& feedforward_n) const noexcept {
    return beta_per_s2 * mass_kg * (desired_m - sample.position_m) +
           alpha_per_s * mass_kg * (desired_velocity_m_per_s - sample.velocity_m_per_s) +
           mass_kg * desired_acceleration_m_per_s2 + feedforward_n;
  }
};

/// Servo periods of invalid readings tolerated before a hold gives up: kMaxInvalidReadings_s
/// in periods of `servo_period_s`, plus the slack every servo-time count keeps. A loop that
/// counts invalid servo time in periods gives up once its count exceeds this. Real-time safe.
inline double maxInvalidPeriods(double servo_period_s) noexcept {
  return kMaxInvalidReadings_s / servo_period_s + kServoTimeSlackPeriods;
}

}  // namespace autograv
