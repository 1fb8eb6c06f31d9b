#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/Core>

#include "autograv/device/servo_sample.h"

namespace autograv::testing {

/// The paper's model, eq. (1), with no noise or quantization: M(X) Xdd + G(X) = F with
/// M = |G(X)|/g and an affine field G(X) = G0 + J (X - X_ref). Integrated exactly enough
/// (10 substeps per 1 ms tick) to check the estimator's mathematics in isolation. Optional dry
/// friction per axis (0 by default): an axis at rest sticks while the net force on it stays within
/// static_friction_n, and slides against coulomb_friction_n otherwise.
class IdealPointMass {
 public:
  Eigen::Vector3d gravity_at_origin_n = Eigen::Vector3d(0.3, -0.2, -2.1);
  Eigen::Matrix3d gradient_n_per_m =
      (Eigen::Matrix3d() << 8, 2, -3, 1, -6, 2, 4, -1, 12).finished();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();
  double static_friction_n = 0.0;   ///< Unit: [N]
  double coulomb_friction_n = 0.0;  ///< Unit: [N]
  /// A stop: a stiff spring and damper pushing back where x exceeds wall_x_m (none by default).
  double wall_x_m = HUGE_VAL;              ///< Unit: [m]
  double wall_stiffness_n_per_m = 2000.0;  ///< Unit: [N/m]
  double wall_damping_n_s_per_m = 5.0;     ///< Unit: [N s/m]
  /// The true inertia in units of the paper's |G|/g (1: the paper's model).
  double mass_factor = 1.0;
  /// Largest x the end-effector reached. Unit: [m]
  double max_x_m = -HUGE_VAL;

  Eigen::Vector3d gravity(const Eigen::Vector3d& x) const {
    return gravity_at_origin_n + gradient_n_per_m * x;
  }
  ServoSample sample() const { return {position_m, velocity_m_per_s, true}; }
  void advance(const Eigen::Vector3d& force_n, double dt_s) {
    const int substeps = 10;
    const double h = dt_s / substeps;
    for (int k = 0; k < substeps; ++k) {
      const Eigen::Vector3d g = gravity(position_m);
      const double mass_kg = mass_factor * g.norm() / 9.81;
      Eigen::Vector3d net_n = force_n - g;
      if (position_m.x() > wall_x_m) {
        net_n.x() -= wall_stiffness_n_per_m * (position_m.x() - wall_x_m) +
                     wall_damping_n_s_per_m * velocity_m_per_s.x();
      }
      for (int axis = 0; axis < 3; ++axis) {
        double& v = velocity_m_per_s[axis];
        if (v == 0.0 && std::abs(net_n[axis]) <= static_friction_n) {
          net_n[axis] = 0.0;  // sticking
          continue;
        }
        const double direction = v != 0.0 ? (v > 0.0 ? 1.0 : -1.0) : (net_n[axis] > 0 ? 1.0 : -1.0);
        const double new_v = v + h * (net_n[axis] - direction * coulomb_friction_n) / mass_kg;
        // Friction stops the axis; it does not reverse it within a substep.
        v = (coulomb_friction_n > 0.0 && new_v * direction < 0.0) ? 0.0 : new_v;
        net_n[axis] = 0.0;
      }
      position_m += h * velocity_m_per_s;
      max_x_m = std::max(max_x_m, position_m.x());
    }
  }
};

}  // namespace autograv::testing
