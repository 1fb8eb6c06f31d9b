// A point load and a tilted base on the simulated devices: the truth they report and the physics
// they integrate must agree, or retare and check would be tested against a lie.
#include <cmath>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {
namespace {

constexpr double kServo_s = 1e-3;
constexpr double kPayload_kg = 0.030;

/// Unit 1 of `name`; with `actuators` ideal, the truth is the physical force, so that a load's
/// weight shows in it as it is.
std::unique_ptr<SimulatedDevice> openDevice(
    const std::string& name, ActuatorTolerance actuators = ActuatorTolerance::kTypical) {
  auto device = makeSimulatedDevice(name, 1, FrictionLevel::kTypical, {1, actuators});
  EXPECT_TRUE(device->open());
  return device;
}

/// Holds the end-effector with the true gravity for `seconds`; returns how far it moved. [m]
double driftWhenHeldByTrueGravity(SimulatedDevice& device, double seconds) {
  const Eigen::Vector3d start_m = device.workspaceCenter_m() + Eigen::Vector3d(0.005, -0.01, 0.0);
  device.resetState(start_m);
  for (int ms = 0; ms < static_cast<int>(seconds / kServo_s); ++ms) {
    EXPECT_TRUE(device.setForce(device.trueGravity(device.truePosition_m())));
    device.advance(kServo_s);
  }
  return (device.truePosition_m() - start_m).norm();
}

class SimulatedLoadTest : public ::testing::TestWithParam<std::string> {};

TEST_P(SimulatedLoadTest, PayloadAddsItsWeightAlongUpAndItsMass) {
  auto device = openDevice(GetParam(), ActuatorTolerance::kIdeal);
  const Eigen::Vector3d x_m = device->workspaceCenter_m() + Eigen::Vector3d(0.01, 0.01, -0.01);
  const Eigen::Vector3d unloaded_n = device->trueGravity(x_m);
  const Eigen::Matrix3d unloaded_kg = device->trueApparentMass(x_m);
  device->setPayload_kg(kPayload_kg);
  const Eigen::Vector3d added_n = device->trueGravity(x_m) - unloaded_n;
  EXPECT_NEAR(added_n.x(), 0.0, 1e-12);
  EXPECT_NEAR(added_n.y(), 0.0, 1e-12);
  EXPECT_NEAR(added_n.z(), kPayload_kg * kStandardGravity, 1e-9);
  // A point mass at the tip: the arm's Cartesian mass gains exactly m I; the point-mass model's
  // mass is |G| / g, so it gains the added weight's share of |G| / g.
  const Eigen::Matrix3d added_kg = device->trueApparentMass(x_m) - unloaded_kg;
  EXPECT_NEAR(added_kg.trace() / 3.0, kPayload_kg, 0.05 * kPayload_kg);
  device->setPayload_kg(0.0);
  EXPECT_TRUE(device->trueGravity(x_m).isApprox(unloaded_n, 1e-12));
}

TEST_P(SimulatedLoadTest, TheLoadedTruthHoldsTheLoadedDeviceAsStillAsTheUnloadedOne) {
  // Cogging and friction move a device held by its true gravity a little anyway: the loaded
  // truth must hold the loaded device as well as the plain truth holds the plain device.
  auto plain = openDevice(GetParam());
  const double plain_drift_m = driftWhenHeldByTrueGravity(*plain, 1.0);
  auto device = openDevice(GetParam());
  device->setPayload_kg(kPayload_kg);
  device->setTilt_rad(10.0 * M_PI / 180.0);
  EXPECT_LT(driftWhenHeldByTrueGravity(*device, 1.0), plain_drift_m + 2e-4);
}

TEST_P(SimulatedLoadTest, UnloadedTruthLetsTheLoadedDeviceSag) {
  auto device = openDevice(GetParam());
  const Eigen::Vector3d x_m = device->workspaceCenter_m();
  const Eigen::Vector3d unloaded_n = device->trueGravity(x_m);
  device->setPayload_kg(kPayload_kg);
  device->resetState(x_m);
  for (int ms = 0; ms < 100; ++ms) {
    device->setForce(unloaded_n);
    device->advance(kServo_s);
  }
  EXPECT_LT(device->truePosition_m().z() - x_m.z(), -1e-3);  // the extra weight pulls it down
}

TEST_P(SimulatedLoadTest, TiltTurnsGravityAboutY) {
  auto device = openDevice(GetParam(), ActuatorTolerance::kIdeal);
  const Eigen::Vector3d x_m = device->workspaceCenter_m();
  const Eigen::Vector3d level_n = device->trueGravity(x_m);
  const double tilt_rad = 10.0 * M_PI / 180.0;
  device->setTilt_rad(tilt_rad);
  const Eigen::Vector3d tilted_n = device->trueGravity(x_m);
  EXPECT_NEAR(tilted_n.norm(), level_n.norm(), 1e-12);
  EXPECT_TRUE(
      tilted_n.isApprox(Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()) * level_n, 1e-12));
}

TEST_P(SimulatedLoadTest, RefusesLoadsItCannotSimulate) {
  auto device = openDevice(GetParam());
  EXPECT_THROW(device->setPayload_kg(-0.001), Error);
  EXPECT_THROW(device->setPayload_kg(std::nan("")), Error);
  EXPECT_THROW(
      device->setPayload_kg(device->specifications().max_linear_force_n / kStandardGravity), Error);
  EXPECT_THROW(device->setTilt_rad(INFINITY), Error);
}

TEST_P(SimulatedLoadTest, AdvanceWithALoadAllocatesNothing) {
  auto device = openDevice(GetParam());
  device->setPayload_kg(kPayload_kg);
  device->setTilt_rad(0.1);
  device->resetState(device->workspaceCenter_m());
  const Eigen::Vector3d hold_n = device->trueGravity(device->workspaceCenter_m());
  testing::AllocationCounter counter;
  for (int ms = 0; ms < 200; ++ms) {
    device->setForce(hold_n);
    device->advance(kServo_s);
  }
  EXPECT_EQ(counter.count(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Devices, SimulatedLoadTest, ::testing::ValuesIn(simulatedDeviceNames()),
                         [](const auto& info) { return info.param.substr(4); });

}  // namespace
}  // namespace autograv::sim
