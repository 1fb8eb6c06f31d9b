#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"

// Checks and set-ups shared by the simulated devices' tests. The energy and potential templates
// are for the devices whose dynamics live in joint space (SerialArmDevice, DeltaDevice): both
// expose inverseKinematics, potentialEnergy_j, gravityTorque, kineticEnergy_j and their joint
// state under the same names.
namespace autograv::testing {

/// Checks that a device refuses a preset with one parameter made unusable, naming the device
/// and the parameter in the autograv::Error it throws.
template <class Device, class Parameters>
class RefusalCheck {
 public:
  /// `device` starts every message, e.g. "sim delta device".
  RefusalCheck(Parameters preset, std::string device)
      : preset_(std::move(preset)), device_(std::move(device)) {}

  /// Building from the preset changed by `change` must throw an Error whose message contains
  /// "<device>: <what>".
  template <class Change>
  void operator()(Change change, const std::string& what) const {
    const std::string expected = device_ + ": " + what;
    Parameters parameters = preset_;
    change(parameters);
    try {
      const Device device(parameters, 1);
      ADD_FAILURE() << "expected autograv::Error naming \"" << expected << "\"";
    } catch (const Error& error) {
      EXPECT_NE(std::string(error.what()).find(expected), std::string::npos) << error.what();
    }
  }

 private:
  Parameters preset_;
  std::string device_;
};

/// Puts the end-effector at rest at `position_m` with its true gravity already acting (a force
/// reaches the actuators one servo period after setForce).
inline void restWithGravityCancelled(sim::SimulatedDevice& device,
                                     const Eigen::Vector3d& position_m) {
  constexpr double kServo_s = 0.001;
  device.resetState(position_m);
  ASSERT_TRUE(device.setForce(device.trueGravity(position_m)));
  device.advance(kServo_s);
  device.resetState(position_m);
}

/// A device built from `parameters` and `seed`, opened and calibrated.
template <class Device, class Parameters>
Device openCalibrated(const Parameters& parameters, std::uint64_t seed) {
  Device device(parameters, seed);
  EXPECT_TRUE(device.open());
  EXPECT_TRUE(device.calibrate());
  return device;
}

/// Eigenvalues of the apparent mass at `position_m`, in increasing order. Unit: [kg]
inline Eigen::Vector3d apparentMassEigenvalues(const sim::SimulatedDevice& device,
                                               const Eigen::Vector3d& position_m) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(device.trueApparentMass(position_m))
      .eigenvalues();
}

/// What the true gravity and apparent mass span over a set of points. Units: [N], [kg]
struct FieldRange {
  double smallest_gravity_n = std::numeric_limits<double>::infinity();
  double largest_gravity_n = 0.0;
  double lightest_kg = std::numeric_limits<double>::infinity();  // smallest eigenvalue
  double heaviest_kg = 0.0;                                      // largest eigenvalue
};

/// The range of |G| and of the apparent mass's eigenvalues over `points_m`, checking on the way
/// that the holding force points up and the apparent mass is symmetric at every point.
inline FieldRange fieldRange(const sim::SimulatedDevice& device,
                             const std::vector<Eigen::Vector3d>& points_m) {
  FieldRange range;
  for (const auto& x : points_m) {
    const Eigen::Vector3d g = device.trueGravity(x);
    EXPECT_GT(g.z(), 0.0) << x.transpose();  // holding force points up
    range.smallest_gravity_n = std::min(range.smallest_gravity_n, g.norm());
    range.largest_gravity_n = std::max(range.largest_gravity_n, g.norm());
    const Eigen::Matrix3d lambda = device.trueApparentMass(x);
    EXPECT_TRUE(lambda.isApprox(lambda.transpose(), 1e-12)) << x.transpose();
    const Eigen::Vector3d eigen = apparentMassEigenvalues(device, x);
    range.lightest_kg = std::min(range.lightest_kg, eigen.minCoeff());
    range.heaviest_kg = std::max(range.heaviest_kg, eigen.maxCoeff());
  }
  return range;
}

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

/// A loose undamped spring of `stiffness_n_per_m` from `anchor_m` that keeps a device released
/// at `start_m` swinging fast through its workspace. Units: [m], [N/m]
struct Swing {
  Eigen::Vector3d start_m;
  Eigen::Vector3d anchor_m;
  double stiffness_n_per_m;
};

/// Largest error of the total energy (kinetic, gravity, spring) over 0.5 s of `swing`, relative
/// to the largest kinetic energy, on a device built from `parameters` without friction and
/// integrated at `internal_rate_hz`.
template <class JointDevice, class Parameters>
double relativeSwingEnergyError(Parameters parameters, double internal_rate_hz,
                                const Swing& swing) {
  constexpr double kServo_s = 0.001;
  parameters.friction = sim::LuGreParameters{};  // no friction at all
  parameters.driver.internal_rate_hz = internal_rate_hz;
  JointDevice device(parameters, 1);
  EXPECT_TRUE(device.open());
  device.resetState(swing.start_m);
  device.hand().stiffness_n_per_m = swing.stiffness_n_per_m;
  device.hand().damping_n_s_per_m = 0.0;
  device.hand().grab(swing.anchor_m);
  auto kinetic = [&] {
    return device.kineticEnergy_j(device.jointAngles_rad(), device.jointVelocities_rad_per_s());
  };
  auto energy = [&] {
    const Eigen::Vector3d x = device.truePosition_m();
    return kinetic() + device.potentialEnergy_j(device.jointAngles_rad()) +
           0.5 * swing.stiffness_n_per_m * (x - swing.anchor_m).squaredNorm();
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

/// Semi-implicit Euler keeps the energy error bounded and first order in the step: a wrong
/// inertia, Coriolis or velocity-product term leaves an error that does not shrink with it. The
/// relative error of `swing` without friction must stay under `bound_at_10khz` at 10 kHz, ten
/// times less at 100 kHz, and shrink by 10 +- `ratio_tolerance` between the two.
template <class JointDevice, class Parameters>
void expectEnergyErrorFirstOrderInTheStep(const Parameters& parameters, const Swing& swing,
                                          double bound_at_10khz, double ratio_tolerance) {
  const double at_10khz = relativeSwingEnergyError<JointDevice>(parameters, 10000.0, swing);
  const double at_100khz = relativeSwingEnergyError<JointDevice>(parameters, 100000.0, swing);
  EXPECT_LT(at_10khz, bound_at_10khz);
  EXPECT_LT(at_100khz, bound_at_10khz / 10.0);
  EXPECT_NEAR(at_10khz / at_100khz, 10.0, ratio_tolerance);
}

}  // namespace autograv::testing
