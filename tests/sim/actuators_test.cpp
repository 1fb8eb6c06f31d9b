// Simulated units whose motors deliver their command times their own gain: the same unit whatever
// the seed, gains within the published tolerances, and a truth that is the command holding the
// unit still (so that on a delta it has a curl).
#include "autograv/sim/actuators.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {
namespace {

constexpr double kServo_s = 0.001;

TEST(ActuatorsTest, AUnitIsTheSameHardwareWhateverTheSeed) {
  for (const std::string& model : simulatedDeviceNames()) {
    const Eigen::Vector3d unit1 = actuatorGains(model, {1, ActuatorTolerance::kTypical});
    const auto device_a = makeSimulatedDevice(model, 1);
    const auto device_b = makeSimulatedDevice(model, 99);
    EXPECT_EQ(dynamic_cast<const SimulatedDriver&>(*device_a).actuatorGains(), unit1) << model;
    EXPECT_EQ(dynamic_cast<const SimulatedDriver&>(*device_b).actuatorGains(), unit1) << model;
    EXPECT_NE(actuatorGains(model, {2, ActuatorTolerance::kTypical}), unit1) << model;
    EXPECT_EQ(actuatorGains(model, {1, ActuatorTolerance::kIdeal}), Eigen::Vector3d::Ones());
    // The same draw, twice as far from nominal at kHigh.
    const Eigen::Vector3d high = actuatorGains(model, {1, ActuatorTolerance::kHigh});
    for (int motor = 0; motor < 3; ++motor) {
      EXPECT_EQ(high[motor] > 1.0, unit1[motor] > 1.0) << model << " motor " << motor;
    }
  }
  EXPECT_THROW(actuatorGains("sim:omni", {0, ActuatorTolerance::kTypical}), Error);
  EXPECT_THROW(actuatorGains("sim:phantom", {1, ActuatorTolerance::kTypical}), Error);
}

TEST(ActuatorsTest, GainsStayWithinThePublishedToleranceAndUseIt) {
  for (const std::string& model : simulatedDeviceNames()) {
    for (const ActuatorTolerance level : {ActuatorTolerance::kTypical, ActuatorTolerance::kHigh}) {
      const double bound = actuatorGainBound(model, level);
      double largest = 0.0;
      double sum_of_squares = 0.0;
      constexpr int kUnits = 400;
      for (int unit = 1; unit <= kUnits; ++unit) {
        const Eigen::Vector3d gains = actuatorGains(model, {unit, level});
        for (int motor = 0; motor < 3; ++motor) {
          const double error = std::abs(gains[motor] - 1.0);
          EXPECT_LE(error, bound) << model << " unit " << unit;
          largest = std::max(largest, error);
          sum_of_squares += error * error;
        }
      }
      // The draws reach most of the band, and spread as three uniform factors do.
      EXPECT_GT(largest, 0.6 * bound) << model;
      const double rms = std::sqrt(sum_of_squares / (3.0 * kUnits));
      EXPECT_GT(rms, 0.25 * bound) << model;
      EXPECT_LT(rms, 0.6 * bound) << model;
    }
    EXPECT_NEAR(actuatorGainBound(model, ActuatorTolerance::kHigh),
                2.0 * actuatorGainBound(model, ActuatorTolerance::kTypical),
                0.2 * actuatorGainBound(model, ActuatorTolerance::kTypical));
    EXPECT_EQ(actuatorGainBound(model, ActuatorTolerance::kIdeal), 0.0);
  }
  EXPECT_EQ(parseActuatorTolerance("high"), ActuatorTolerance::kHigh);
  EXPECT_THROW(parseActuatorTolerance("perfect"), Error);
  EXPECT_EQ(actuatorToleranceNames().size(), 3u);
}

/// How far the end-effector moves in `seconds` when it is held by `force_n` at `start_m`. [m]
double driftHeldBy(SimulatedDevice& device, const Eigen::Vector3d& start_m,
                   const Eigen::Vector3d& force_n, double seconds) {
  // The command in flight reaches the actuators a period later: send it before the reset.
  EXPECT_TRUE(device.setForce(force_n));
  device.advance(kServo_s);
  device.resetState(start_m);
  for (int ms = 0; ms < static_cast<int>(seconds / kServo_s); ++ms) {
    EXPECT_TRUE(device.setForce(force_n));
    device.advance(kServo_s);
  }
  return (device.truePosition_m() - start_m).norm();
}

// The truth is the command that holds this unit: a unit held by the ideal unit's truth drifts
// (one motor gives too little), held by its own it stays where friction alone would keep it.
TEST(ActuatorsTest, TheTruthIsTheCommandThatHoldsThisUnit) {
  for (const std::string& model : simulatedDeviceNames()) {
    const auto ideal =
        makeSimulatedDevice(model, 4, FrictionLevel::kNone, {1, ActuatorTolerance::kIdeal});
    const auto unit =
        makeSimulatedDevice(model, 4, FrictionLevel::kNone, {1, ActuatorTolerance::kHigh});
    ASSERT_TRUE(unit->open());
    const Eigen::Vector3d x_m = unit->workspaceCenter_m() + Eigen::Vector3d(0.01, -0.005, 0.0);
    const Eigen::Vector3d own_n = unit->trueGravity(x_m);
    const Eigen::Vector3d nominal_n = ideal->trueGravity(x_m);
    // A few percent of |G|, as the gains are off.
    EXPECT_GT((own_n - nominal_n).norm(), 0.005 * nominal_n.norm()) << model;
    EXPECT_LT((own_n - nominal_n).norm(), 0.25 * nominal_n.norm()) << model;
    // Cogging and the DAC's counts move it a little even so.
    const double own_drift_m = driftHeldBy(*unit, x_m, own_n, 0.3);
    const double nominal_drift_m = driftHeldBy(*unit, x_m, nominal_n, 0.3);
    EXPECT_GT(nominal_drift_m, 2e-3) << model;
    EXPECT_LT(own_drift_m, 0.3 * nominal_drift_m) << model;
  }
}

/// The curl of `device`'s truth at `x_m`, by central differences. Unit: [N/m]
Eigen::Vector3d curlOf(const SimulatedDevice& device, const Eigen::Vector3d& x_m) {
  constexpr double h = 1e-4;
  Eigen::Matrix3d jacobian;  // d G_i / d x_j
  for (int j = 0; j < 3; ++j) {
    const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(j);
    jacobian.col(j) = (device.trueGravity(x_m + step) - device.trueGravity(x_m - step)) / (2 * h);
  }
  return {jacobian(2, 1) - jacobian(1, 2), jacobian(0, 2) - jacobian(2, 0),
          jacobian(1, 0) - jacobian(0, 1)};
}

// Unequal gains on a mechanism whose potential couples its joints (the Falcon's delta, the
// Omega-like axes under a curved field) leave a curl in the command that holds it; the Omni's arm,
// whose potential has one term per motor, stays a gradient.
TEST(ActuatorsTest, UnequalGainsLeaveACurlWhereThePotentialCouplesTheJoints) {
  const Eigen::Vector3d offset_m(0.012, -0.02, 0.015);
  for (const std::string& model : simulatedDeviceNames()) {
    const auto ideal =
        makeSimulatedDevice(model, 1, FrictionLevel::kNone, {1, ActuatorTolerance::kIdeal});
    const auto typical =
        makeSimulatedDevice(model, 1, FrictionLevel::kNone, {1, ActuatorTolerance::kTypical});
    const Eigen::Vector3d x_m = ideal->workspaceCenter_m() + offset_m;
    const double gradient_scale_n_per_m = ideal->trueGravity(x_m).norm() / 0.05;
    EXPECT_LT(curlOf(*ideal, x_m).norm(), 1e-4 * gradient_scale_n_per_m) << model;
    // Relative to the field's own slope: nothing on the arm, a clear curl on the others.
    const double curl = curlOf(*typical, x_m).norm() / gradient_scale_n_per_m;
    const bool separable = model == "sim:omni";
    EXPECT_EQ(curl > 1e-3, !separable) << model << ": curl " << curl;
    EXPECT_EQ(curl < 1e-4, separable) << model << ": curl " << curl;
  }
}

}  // namespace
}  // namespace autograv::sim
