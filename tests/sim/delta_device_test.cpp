#include "autograv/sim/delta_device.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "autograv/error.h"
#include "autograv/sim/friction_measurement.h"
#include "device_checks.h"

namespace autograv::sim {
namespace {

constexpr double kServo_s = 0.001;
// Novint's published figures: a 4 x 4 x 4 in workspace, 2 lbf, 400 dpi.
constexpr double kCubeSide_m = 4.0 * 0.0254;
constexpr double kMaxForce_n = 8.9;
constexpr double kResolution_m = 0.0254 / 400.0;
constexpr double kTwoPi = 6.283185307179586476925286766559;

DeltaDevice makeOpenFalcon() { return testing::openCalibrated<DeltaDevice>(falconParameters(), 7); }

// A cubic grid of `per_axis` points per axis over a cube of side `side_m` around the centre.
std::vector<Eigen::Vector3d> cubePoints(double side_m, int per_axis) {
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < per_axis; ++i) {
    for (int j = 0; j < per_axis; ++j) {
      for (int k = 0; k < per_axis; ++k) {
        points.push_back(
            (Eigen::Vector3d(i, j, k) / (per_axis - 1) - Eigen::Vector3d::Constant(0.5)) * side_m);
      }
    }
  }
  return points;
}

// The 26 directions to the faces, edges and corners of a cube.
std::vector<Eigen::Vector3d> unitDirections() {
  std::vector<Eigen::Vector3d> directions;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      for (int k = -1; k <= 1; ++k) {
        if (i != 0 || j != 0 || k != 0) directions.push_back(Eigen::Vector3d(i, j, k).normalized());
      }
    }
  }
  return directions;
}

Eigen::Vector3d inverse(const DeltaDevice& device, const Eigen::Vector3d& position_m) {
  Eigen::Vector3d theta;
  EXPECT_TRUE(device.inverseKinematics(position_m, theta)) << position_m.transpose();
  return theta;
}

TEST(DeltaDeviceTest, HomePoseIsTheWorkspaceCentreWithTheArmsAlike) {
  const DeltaDevice device(falconParameters(), 1);
  const Eigen::Vector3d& theta = device.jointAngles_rad();
  EXPECT_NEAR(theta[0], theta[1], 1e-12);
  EXPECT_NEAR(theta[0], theta[2], 1e-12);
  Eigen::Vector3d position;
  ASSERT_TRUE(device.forwardKinematics(theta, position));
  EXPECT_LT(position.norm(), 1e-12);
  EXPECT_LT(device.truePosition_m().norm(), 1e-12);
  EXPECT_EQ(device.workspaceCenter_m(), Eigen::Vector3d::Zero());
}

TEST(DeltaDeviceTest, InverseKinematicsInvertsForwardKinematics) {
  const DeltaDevice device(falconParameters(), 1);
  const auto& p = device.parameters();
  int checked = 0;
  for (double t0 = p.joint_min_rad[0]; t0 <= p.joint_max_rad[0]; t0 += 0.25) {
    for (double t1 = p.joint_min_rad[1]; t1 <= p.joint_max_rad[1]; t1 += 0.25) {
      for (double t2 = p.joint_min_rad[2]; t2 <= p.joint_max_rad[2]; t2 += 0.25) {
        const Eigen::Vector3d theta(t0, t1, t2);
        Eigen::Vector3d position, back;
        if (!device.forwardKinematics(theta, position)) continue;  // the legs cannot close
        if (!device.inverseKinematics(position, back)) continue;   // beyond a forearm's reach
        // Off the device's branch (a knee folded inside its forearm) the inverse finds the other
        // pose; on it, it must come back exactly.
        const Eigen::Matrix3d j = device.jacobian(theta);
        const Eigen::Vector3d singular = Eigen::JacobiSVD<Eigen::Matrix3d>(j).singularValues();
        if (singular[2] * 20.0 < singular[0] || (back - theta).cwiseAbs().maxCoeff() > 1e-3) {
          continue;
        }
        EXPECT_LT((back - theta).cwiseAbs().maxCoeff(), 1e-9) << theta.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 400);
  for (const auto& x : cubePoints(kCubeSide_m, 9)) {
    Eigen::Vector3d position;
    ASSERT_TRUE(device.forwardKinematics(inverse(device, x), position));
    EXPECT_LT((position - x).norm(), 1e-12) << x.transpose();
  }
  Eigen::Vector3d theta;
  EXPECT_FALSE(device.inverseKinematics(Eigen::Vector3d(0.2, 0.0, 0.0), theta));  // too far
}

TEST(DeltaDeviceTest, JacobianIsTheDerivativeOfForwardKinematics) {
  const DeltaDevice device(falconParameters(), 1);
  for (const auto& x : cubePoints(kCubeSide_m, 3)) {
    const Eigen::Vector3d theta = inverse(device, x);
    Eigen::Matrix3d numeric;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d step = 1e-7 * Eigen::Vector3d::Unit(j);
      Eigen::Vector3d plus, minus;
      ASSERT_TRUE(device.forwardKinematics(theta + step, plus));
      ASSERT_TRUE(device.forwardKinematics(theta - step, minus));
      numeric.col(j) = (plus - minus) / 2e-7;
    }
    EXPECT_LT((numeric - device.jacobian(theta)).cwiseAbs().maxCoeff(), 1e-8) << x.transpose();
  }
}

TEST(DeltaDeviceTest, GravityTorqueIsTheDerivativeOfThePotential) {
  const DeltaDevice device(falconParameters(), 1);
  testing::expectGravityTorqueIsTheDerivativeOfThePotential(
      device, inverse(device, Eigen::Vector3d(0.02, -0.03, 0.01)));
}

// J^-T g(theta) is the Cartesian gradient of the potential energy over the whole cube.
TEST(DeltaDeviceTest, CartesianGravityMatchesFiniteDifferenceOfPotentialEnergy) {
  const DeltaDevice device(falconParameters(), 1);
  testing::expectCartesianGravityIsTheGradientOfThePotential(device, cubePoints(kCubeSide_m, 5));
}

TEST(DeltaDeviceTest, GravityAndMassLookLikeAFalcon) {
  const DeltaDevice device(falconParameters(), 1);
  const testing::FieldRange range = testing::fieldRange(device, cubePoints(kCubeSide_m, 5));
  // At least the grip, platform and forearm halves; never more than the motors can push.
  EXPECT_GT(range.lightest_kg, 0.098);
  EXPECT_LT(range.heaviest_kg, 1.0);
  // The grip and platform alone weigh 0.78 N; the arms add to it at the centre. The field varies
  // by tens of percent over the cube, well within the 8.9 N the motors make.
  const Eigen::Vector3d centre_gravity = device.trueGravity(Eigen::Vector3d::Zero());
  EXPECT_NEAR(centre_gravity.norm(), 1.05, 0.05);
  EXPECT_LT(centre_gravity.head<2>().norm(), 1e-9);  // the centre is on the symmetric axis
  EXPECT_GT(range.smallest_gravity_n, 0.4);
  EXPECT_LT(range.largest_gravity_n, 1.5);
  EXPECT_GT((range.largest_gravity_n - range.smallest_gravity_n) / centre_gravity.norm(), 0.3);
  // Apparent mass: anisotropic (the axis differs from the cross directions).
  const Eigen::Vector3d eigen = testing::apparentMassEigenvalues(device, Eigen::Vector3d::Zero());
  EXPECT_GT(eigen.maxCoeff() / eigen.minCoeff(), 1.15);
}

TEST(DeltaDeviceTest, WorkspaceCoversThePublishedFourInchCube) {
  DeltaDevice device(falconParameters(), 1);
  const auto& p = device.parameters();
  for (const auto& x : cubePoints(kCubeSide_m, 9)) {
    const Eigen::Vector3d theta = inverse(device, x);
    EXPECT_TRUE((theta.array() > p.joint_min_rad.array()).all()) << x.transpose();
    EXPECT_TRUE((theta.array() < p.joint_max_rad.array()).all()) << x.transpose();
    const Eigen::Vector3d singular =
        Eigen::JacobiSVD<Eigen::Matrix3d>(device.jacobian(theta)).singularValues();
    EXPECT_LT(singular[0] / singular[2], 10.0) << x.transpose();
  }
  // Every corner is a pose the device rests in.
  const Eigen::Vector3d corner = Eigen::Vector3d(0.5, -0.5, 0.5) * kCubeSide_m;
  device.resetState(corner);
  EXPECT_LT((device.truePosition_m() - corner).norm(), 1e-12);
  // The workspace sphere is the one inscribed in the cube.
  EXPECT_NEAR(device.specifications().workspace_radius_m, kCubeSide_m / 2.0, 1e-9);
}

TEST(DeltaDeviceTest, OneEncoderCountIsBelowThePublishedResolutionAtTheCentre) {
  const DeltaDevice device(falconParameters(), 1);
  const Eigen::Matrix3d j = device.jacobian(device.jointAngles_rad());
  for (int joint = 0; joint < 3; ++joint) {
    const double count_rad = kTwoPi / device.parameters().joint_counts_per_rev[joint];
    const double at_grip_m = j.col(joint).norm() * count_rad;
    EXPECT_LT(at_grip_m, kResolution_m);
    EXPECT_GT(at_grip_m, 0.5 * kResolution_m);  // and not far finer than the real one
  }
}

TEST(DeltaDeviceTest, MotionConservesEnergyWithoutFriction) {
  // The grip swings at about 1 m/s through the workspace.
  testing::expectEnergyErrorFirstOrderInTheStep<DeltaDevice>(
      falconParameters(),
      {Eigen::Vector3d(-0.02, -0.025, 0.03), Eigen::Vector3d(0.01, 0.005, 0.0), 150.0}, 0.01, 1.5);
}

TEST(DeltaDeviceTest, ReleasedFromRestAcceleratesAsGOverM) {
  DeltaDevice device = makeOpenFalcon();
  const Eigen::Vector3d start(0.02, -0.03, 0.01);
  device.resetState(start);
  ASSERT_TRUE(device.setForce(Eigen::Vector3d::Zero()));
  // Eq. (1) of the paper, in its Cartesian form: M Xdd = -G at rest (no velocity, no damping).
  const Eigen::Vector3d expected =
      -device.trueApparentMass(start).inverse() * device.trueGravity(start);
  device.advance(0.0002);
  const Eigen::Vector3d measured = device.trueVelocity_m_per_s() / 0.0002;
  EXPECT_LT((measured - expected).norm(), 0.01 * expected.norm());
}

TEST(DeltaDeviceTest, ForceIsLimitedInMagnitudeAndPerMotor) {
  DeltaDevice device = makeOpenFalcon();
  // The driver keeps the direction and clamps the magnitude to the published 8.9 N; the motors
  // apply it one servo period later, in DAC steps of a few mN.
  const Eigen::Vector3d large(8.0, 0.0, 6.0);  // 10 N
  ASSERT_TRUE(device.setForce(large));
  EXPECT_EQ(device.saturationCount(), 1u);
  device.advance(kServo_s);
  EXPECT_NEAR(device.appliedForce_n().norm(), kMaxForce_n, 0.02);
  EXPECT_GT(device.appliedForce_n().normalized().dot(large.normalized()), 0.9999);
  // At the centre the motors make the full force in every direction...
  for (const auto& direction : unitDirections()) {
    device.resetState(Eigen::Vector3d::Zero());
    ASSERT_TRUE(device.setForce(0.999 * kMaxForce_n * direction));
  }
  EXPECT_EQ(device.saturationCount(), 1u);
  // ...but near the edge of the cube the motor that this direction loads most runs out of torque
  // first, and the grip gets less than it was asked for.
  const Eigen::Vector3d edge = Eigen::Vector3d(0.5, 0.5, -0.5) * kCubeSide_m;
  const Eigen::Matrix3d j = device.jacobian(inverse(device, edge));
  int weakest = 0;
  j.colwise().norm().maxCoeff(&weakest);
  const Eigen::Vector3d direction = j.col(weakest).normalized();
  EXPECT_GT(j.col(weakest).norm() * kMaxForce_n,
            device.parameters().driver.motor_limit[weakest] * 1.05);
  device.resetState(edge);
  ASSERT_TRUE(device.setForce(0.999 * kMaxForce_n * direction));
  EXPECT_EQ(device.saturationCount(), 2u);
  device.advance(kServo_s);  // one servo period of transport delay
  EXPECT_LT(device.appliedForce_n().dot(direction), 0.95 * kMaxForce_n);
}

// EveryPresetTest checks where it lands; here, that the grip's travel stops hold it, at the
// bottom of the published cube, before the arms reach theirs.
TEST(DeltaDeviceTest, ReleasedWithZeroForceFallsOntoTheTravelStops) {
  DeltaDevice device = makeOpenFalcon();
  device.setForce(Eigen::Vector3d::Zero());
  device.advance(2.0);
  EXPECT_TRUE(device.endStopHit());
  const auto& p = device.parameters();
  EXPECT_NEAR(device.truePosition_m().z(), -p.travel_stop_half_width_m, 2e-3);
  const Eigen::Vector3d& theta = device.jointAngles_rad();
  EXPECT_TRUE(
      ((theta.array() >= p.joint_min_rad.array()) && (theta.array() <= p.joint_max_rad.array()))
          .all());
}

TEST(DeltaDeviceTest, TypicalFrictionBreaksAwayAtTensOfMillinewtons) {
  DeltaDevice device(falconParameters(FrictionLevel::kTypical), 3);
  ASSERT_TRUE(device.open());
  FrictionMeasurementOptions options;
  options.ramp_rate_n_per_s = 0.1;  // the ramp's lag adds a few mN; keeps the test short
  const FrictionMeasurement friction = measureFriction(device, options);
  for (std::size_t i = 0; i < friction.directions.size(); ++i) {
    EXPECT_GE(friction.breakaway_n[i], 0.030) << friction.directions[i].transpose();
  }
  // Along the axis all three arms turn together and their friction adds up.
  EXPECT_LT(friction.breakaway_force_n, 0.090);
  EXPECT_GT(friction.coulomb_force_n, 0.010);
  EXPECT_LT(friction.coulomb_force_n, friction.breakaway_force_n);
  RecordProperty("breakaway_min_mn", std::to_string(friction.min_breakaway_force_n * 1e3));
  RecordProperty("breakaway_max_mn", std::to_string(friction.breakaway_force_n * 1e3));
}

// Largest distance from the centre over `seconds` under a steady push on top of the true gravity.
double driftUnderPush(FrictionLevel level, const Eigen::Vector3d& push_n, double seconds) {
  DeltaDevice device(falconParameters(level), 3);
  EXPECT_TRUE(device.open());
  testing::restWithGravityCancelled(device, Eigen::Vector3d::Zero());
  double worst_m = 0.0;
  for (int ms = 0; ms < static_cast<int>(seconds / kServo_s); ++ms) {
    device.setForce(device.trueGravity(device.truePosition_m()) + push_n);
    device.advance(kServo_s);
    worst_m = std::max(worst_m, device.truePosition_m().norm());
  }
  return worst_m;
}

TEST(DeltaDeviceTest, FrictionLevelsHoldOrLetGoOfTheSamePush) {
  // 25 mN across the axis: under the breakaway at typical and high friction (pre-sliding only,
  // below an encoder count), over it at low (a third of typical) and without dry friction.
  const Eigen::Vector3d push(0.0, 0.025, 0.0);
  EXPECT_LT(driftUnderPush(FrictionLevel::kHigh, push, 0.5), 0.02e-3);
  EXPECT_LT(driftUnderPush(FrictionLevel::kTypical, push, 0.5), 0.04e-3);
  EXPECT_GT(driftUnderPush(FrictionLevel::kLow, push, 0.5), 1e-3);
  EXPECT_GT(driftUnderPush(FrictionLevel::kNone, push, 0.5), 1e-3);
}

TEST(DeltaDeviceTest, ResetStateRejectsPositionsBeyondTheArmStops) {
  DeltaDevice device(falconParameters(), 1);
  // Reachable by the legs, but only with an arm swung forward beyond its stop.
  const Eigen::Vector3d below(0.0, 0.0, -0.115);
  Eigen::Vector3d theta;
  ASSERT_TRUE(device.inverseKinematics(below, theta));
  EXPECT_GT(theta.maxCoeff(), device.parameters().joint_max_rad.maxCoeff());
  EXPECT_THROW(device.resetState(below), Error);
  EXPECT_THROW(device.trueGravity(Eigen::Vector3d(0.3, 0.0, 0.0)), Error);
}

TEST(DeltaDeviceTest, SpecificationsDescribeAFalcon) {
  const DeltaDevice device(falconParameters(), 1);
  EXPECT_NE(device.specifications().manufacturer.find("Falcon"), std::string::npos);
}

TEST(DeltaDeviceTest, BadParametersAreRefusedWithTheirName) {
  using P = DeltaParameters;
  const testing::RefusalCheck<DeltaDevice, P> refused(falconParameters(), "sim delta device");
  // 90 mm is beyond the mechanism's reach.
  refused([](P& p) { p.specifications.workspace_radius_m = 0.09; }, "the workspace sphere");
  refused([](P& p) { p.grip_mass_kg = -0.01; }, "grip_mass_kg");
  refused([](P& p) { p.leg_angles_rad[2] += 0.3; }, "leg_angles_rad must be 120 degrees apart");
  refused([](P& p) { p.joint_max_rad[1] = p.joint_min_rad[1]; }, "joint_min_rad");
  refused([](P& p) { p.friction.stiction[0] = -1.0; }, "friction stiction");
}

}  // namespace
}  // namespace autograv::sim
