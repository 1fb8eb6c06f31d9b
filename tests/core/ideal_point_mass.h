#pragma once

#include <Eigen/Core>

#include "autograv/device/servo_sample.h"

namespace autograv::testing {

/// The paper's model, eq. (1), with no friction, noise or quantization: M(X) Xdd + G(X) = F with
/// M = |G(X)|/g and an affine field G(X) = G0 + J (X - X_ref). Integrated exactly enough
/// (10 substeps per 1 ms tick) to check the estimator's mathematics in isolation.
class IdealPointMass {
 public:
  Eigen::Vector3d gravity_at_origin_n = Eigen::Vector3d(0.3, -0.2, -2.1);
  Eigen::Matrix3d gradient_n_per_m =
      (Eigen::Matrix3d() << 8, 2, -3, 1, -6, 2, 4, -1, 12).finished();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();

  Eigen::Vector3d gravity(const Eigen::Vector3d& x) const {
    return gravity_at_origin_n + gradient_n_per_m * x;
  }
  ServoSample sample() const { return {position_m, velocity_m_per_s, true}; }
  void advance(const Eigen::Vector3d& force_n, double dt_s) {
    const int substeps = 10;
    const double h = dt_s / substeps;
    for (int k = 0; k < substeps; ++k) {
      const Eigen::Vector3d g = gravity(position_m);
      const double mass_kg = g.norm() / 9.81;
      velocity_m_per_s += h * (force_n - g) / mass_kg;
      position_m += h * velocity_m_per_s;
    }
  }
};

}  // namespace autograv::testing
