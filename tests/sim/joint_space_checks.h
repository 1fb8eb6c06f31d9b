#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

// Checks shared by the simulated devices whose dynamics live in joint space (SerialArmDevice,
// DeltaDevice): both expose inverseKinematics, potentialEnergy_j, gravityTorque, kineticEnergy_j
// and their joint state under the same names.
namespace autograv::testing {

/// g(q) is the derivative of the potential energy at `q_rad` (central differences of 1e-6 rad).
template <class JointDevice>
void expectGravityTorqueIsTheDerivativeOfThePotential(const JointDevice& device,
                                                      const Eigen::Vector3d& q_rad) {
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d step = 1e-6 * Eigen::Vector3d::Unit(j);
    const double numeric =
        (device.potentialEnergy_j(q_rad + step) - device.potentialEnergy_j(q_rad - step)) / 2e-6;
    EXPECT_NEAR(numeric, device.gravityTorque(q_rad)[j], 1e-9);
  }
}

/// J^-T g(q) is the Cartesian gradient of the potential energy at every point of `points_m`.
template <class JointDevice>
void expectCartesianGravityIsTheGradientOfThePotential(
    const JointDevice& device, const std::vector<Eigen::Vector3d>& points_m) {
  auto energyAt = [&](const Eigen::Vector3d& x) {
    Eigen::Vector3d q;
    EXPECT_TRUE(device.inverseKinematics(x, q)) << x.transpose();
    return device.potentialEnergy_j(q);
  };
  const double h = 1e-6;
  for (const auto& x : points_m) {
    Eigen::Vector3d numeric;
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(axis);
      numeric[axis] = (energyAt(x + step) - energyAt(x - step)) / (2 * h);
    }
    const Eigen::Vector3d gravity = device.trueGravity(x);
    EXPECT_LT((numeric - gravity).norm(), 1e-6 * gravity.norm() + 1e-8) << x.transpose();
  }
}

/// A loose undamped spring of `stiffness_n_per_m` from `anchor_m` keeps an open, frictionless
/// device swinging fast from `start_m` through its workspace for 0.5 s; the total energy
/// (kinetic, gravity, spring) must stay put. Returns the largest energy error relative to the
/// largest kinetic energy.
template <class JointDevice>
double relativeSwingEnergyError(JointDevice& device, const Eigen::Vector3d& start_m,
                                const Eigen::Vector3d& anchor_m, double stiffness_n_per_m) {
  constexpr double kServo_s = 0.001;
  device.resetState(start_m);
  device.hand().stiffness_n_per_m = stiffness_n_per_m;
  device.hand().damping_n_s_per_m = 0.0;
  device.hand().grab(anchor_m);
  auto kinetic = [&] {
    return device.kineticEnergy_j(device.jointAngles_rad(), device.jointVelocities_rad_per_s());
  };
  auto energy = [&] {
    const Eigen::Vector3d x = device.truePosition_m();
    return kinetic() + device.potentialEnergy_j(device.jointAngles_rad()) +
           0.5 * stiffness_n_per_m * (x - anchor_m).squaredNorm();
  };
  const double start = energy();
  double max_kinetic = 0.0, worst = 0.0;
  for (int ms = 0; ms < 500; ++ms) {
    device.advance(kServo_s);
    max_kinetic = std::max(max_kinetic, kinetic());
    worst = std::max(worst, std::abs(energy() - start));
  }
  EXPECT_FALSE(device.endStopHit());
  EXPECT_GT(max_kinetic, 0.05);  // J: the tip moves at about 1 m/s or more
  return worst / max_kinetic;
}

}  // namespace autograv::testing
