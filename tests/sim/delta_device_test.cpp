#include "autograv/sim/delta_device.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "autograv/error.h"
#include "autograv/sim/actuators.h"
#include "autograv/sim/friction_measurement.h"
#include "autograv/sim/simulated_device.h"
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

// sim:falcon-can: sim:falcon's delta between a flat floor and a flat ceiling, in a round wall.

// Points on a face of the can: its middle and eight points on two circles about it, the outer
// 1 mm inside the rim.
std::vector<Eigen::Vector2d> canFacePoints(double radius_m) {
  std::vector<Eigen::Vector2d> points{Eigen::Vector2d::Zero()};
  for (int k = 0; k < 8; ++k) {
    const double angle = kTwoPi * k / 8.0 + 0.3;
    const double r = (k % 2 == 0 ? 0.5 * radius_m : radius_m - 1e-3);
    points.emplace_back(r * std::cos(angle), r * std::sin(angle));
  }
  return points;
}

TEST(FalconCanTest, FloorAndCeilingPushStraightUpAndDownByStiffnessTimesDepth) {
  const DeltaDevice device(falconCanParameters(), 1);
  const auto& p = device.parameters();
  const Eigen::Vector3d at_rest = Eigen::Vector3d::Zero();
  for (const Eigen::Vector2d& xy : canFacePoints(p.travel_stop_radius_m)) {
    for (const double depth_m : {0.2e-3, 1e-3, 3e-3}) {
      const Eigen::Vector3d below(xy.x(), xy.y(), p.travel_stop_floor_m - depth_m);
      const Eigen::Vector3d up = device.travelStopForce_n(below, at_rest);
      EXPECT_EQ(up.x(), 0.0) << below.transpose();
      EXPECT_EQ(up.y(), 0.0) << below.transpose();
      EXPECT_NEAR(up.z(), p.travel_stop_stiffness_n_per_m * depth_m, 1e-9) << below.transpose();
      const Eigen::Vector3d above(xy.x(), xy.y(), p.travel_stop_ceiling_m + depth_m);
      const Eigen::Vector3d down = device.travelStopForce_n(above, at_rest);
      EXPECT_EQ(down.x(), 0.0) << above.transpose();
      EXPECT_EQ(down.y(), 0.0) << above.transpose();
      EXPECT_NEAR(down.z(), -p.travel_stop_stiffness_n_per_m * depth_m, 1e-9) << above.transpose();
    }
    // On the face and inside, nothing.
    EXPECT_EQ(
        device.travelStopForce_n(Eigen::Vector3d(xy.x(), xy.y(), p.travel_stop_floor_m), at_rest),
        Eigen::Vector3d::Zero());
    EXPECT_EQ(device.travelStopForce_n(Eigen::Vector3d(xy.x(), xy.y(), 0.0), at_rest),
              Eigen::Vector3d::Zero());
  }
  // Sliding along the floor drags nothing sideways; sinking into it is damped along the normal.
  const Eigen::Vector3d on_floor(0.01, -0.02, p.travel_stop_floor_m - 1e-3);
  const Eigen::Vector3d sliding =
      device.travelStopForce_n(on_floor, Eigen::Vector3d(0.1, 0.2, 0.0));
  EXPECT_EQ(sliding.head<2>(), Eigen::Vector2d::Zero());
  const Eigen::Vector3d sinking =
      device.travelStopForce_n(on_floor, Eigen::Vector3d(0.0, 0.0, -0.1));
  EXPECT_NEAR(sinking.z(),
              p.travel_stop_stiffness_n_per_m * 1e-3 + p.travel_stop_damping_n_s_per_m * 0.1, 1e-9);
}

TEST(FalconCanTest, RoundWallPushesTowardTheAxisByStiffnessTimesDepth) {
  const DeltaDevice device(falconCanParameters(), 1);
  const auto& p = device.parameters();
  for (int k = 0; k < 12; ++k) {
    const double angle = kTwoPi * k / 12.0;
    const Eigen::Vector3d outward(std::cos(angle), std::sin(angle), 0.0);
    const Eigen::Vector3d beyond =
        (p.travel_stop_radius_m + 2e-3) * outward + Eigen::Vector3d(0.0, 0.0, 0.01);
    const Eigen::Vector3d force = device.travelStopForce_n(beyond, Eigen::Vector3d::Zero());
    EXPECT_LT((force + p.travel_stop_stiffness_n_per_m * 2e-3 * outward).norm(), 1e-9)
        << beyond.transpose();
  }
}

TEST(FalconCanTest, StopStiffnessIsTheParameterWithADefaultOf3000NPerM) {
  // The default lies in the 1,000-5,000 N/m of desktop devices' bumpers and stops (the source is
  // beside falconCanParameters).
  EXPECT_EQ(falconCanParameters().travel_stop_stiffness_n_per_m, 3000.0);
  for (const double stiffness : {1000.0, 3000.0, 5000.0}) {
    DeltaParameters parameters = falconCanParameters();
    parameters.travel_stop_stiffness_n_per_m = stiffness;
    const DeltaDevice device(parameters, 1);
    const Eigen::Vector3d shallow(0.01, 0.0, parameters.travel_stop_floor_m - 0.5e-3);
    const Eigen::Vector3d deep(0.01, 0.0, parameters.travel_stop_floor_m - 2.5e-3);
    const double slope = (device.travelStopForce_n(deep, Eigen::Vector3d::Zero()).z() -
                          device.travelStopForce_n(shallow, Eigen::Vector3d::Zero()).z()) /
                         2e-3;
    EXPECT_NEAR(slope, stiffness, 1e-6 * stiffness);
  }
}

TEST(FalconCanTest, HeldWithGravityCancelledAPushDownSinksByPushOverStiffnessEverywhereOnTheFloor) {
  // The dynamics, not just the stop's formula: gravity cancelled at the true position and 4 N
  // down, at typical friction, at points across the floor. The grip sinks by 4 N / k to the same
  // height wherever it is on the floor (a slanted or rounded floor would not).
  const DeltaParameters parameters = falconCanParameters();
  const double push_n = 4.0;
  for (const Eigen::Vector2d& xy : canFacePoints(0.6 * parameters.travel_stop_radius_m)) {
    DeltaDevice device = testing::openCalibrated<DeltaDevice>(parameters, 3);
    const Eigen::Vector3d start(xy.x(), xy.y(), parameters.travel_stop_floor_m);
    testing::restWithGravityCancelled(device, start);
    for (int ms = 0; ms < 1500; ++ms) {
      ASSERT_TRUE(device.setForce(device.trueGravity(device.truePosition_m()) +
                                  Eigen::Vector3d(0.0, 0.0, -push_n)));
      device.advance(kServo_s);
    }
    EXPECT_TRUE(device.endStopHit());
    const Eigen::Vector3d end = device.truePosition_m();
    const double depth_m = parameters.travel_stop_floor_m - end.z();
    // Friction at the grip (under 0.1 N) is under 3 % of the push.
    EXPECT_NEAR(depth_m, push_n / parameters.travel_stop_stiffness_n_per_m,
                0.03 * push_n / parameters.travel_stop_stiffness_n_per_m)
        << start.transpose();
    // Sideways it moves by a fraction of the sink: each arm's friction, met at the grip through
    // J^-T, is not along the grip's motion (0.25-0.37 mm measured here, at seed 3).
    EXPECT_LT((end.head<2>() - xy).norm(), 0.5 * depth_m) << start.transpose();
  }
}

TEST(FalconCanTest, ReleasedWithZeroForceFallsOntoTheFloorWithTheArmsClearOfTheirStops) {
  DeltaDevice device = testing::openCalibrated<DeltaDevice>(falconCanParameters(), 7);
  device.setForce(Eigen::Vector3d::Zero());
  device.advance(2.0);
  EXPECT_TRUE(device.endStopHit());
  const auto& p = device.parameters();
  // Resting on the floor, sunk by about |G_z| / k (1 N against 3,000 N/m: a third of a mm).
  EXPECT_LT(device.truePosition_m().z(), p.travel_stop_floor_m);
  EXPECT_GT(device.truePosition_m().z(), p.travel_stop_floor_m - 1e-3);
  const Eigen::Vector3d& theta = device.jointAngles_rad();
  EXPECT_TRUE(
      ((theta.array() > p.joint_min_rad.array()) && (theta.array() < p.joint_max_rad.array()))
          .all());
}

TEST(FalconCanTest, ReachesInsideTheCanAndNotBeyondItsFloorCeilingOrWall) {
  const DeltaDevice can(falconCanParameters(), 1);
  const DeltaDevice falcon(falconParameters(), 1);
  const auto& p = can.parameters();
  const double r = p.travel_stop_radius_m;
  // Inside, on a grid through the whole can (its faces 0.5 mm in): reachable.
  int inside = 0;
  for (const Eigen::Vector3d& point : cubePoints(2.0 * r - 1e-3, 9)) {
    if (point.head<2>().norm() > r - 0.5e-3) continue;
    ++inside;
    EXPECT_TRUE(can.isReachable(point)) << point.transpose();
  }
  EXPECT_GT(inside, 400);
  // 1 mm beyond the floor, the ceiling or the wall: not reachable, though the mechanism reaches
  // there with its arms clear of their stops (sim:falcon does): the can cuts, not the arms.
  for (const Eigen::Vector2d& xy : canFacePoints(r)) {
    for (const Eigen::Vector3d& beyond :
         {Eigen::Vector3d(xy.x(), xy.y(), p.travel_stop_floor_m - 1e-3),
          Eigen::Vector3d(xy.x(), xy.y(), p.travel_stop_ceiling_m + 1e-3)}) {
      EXPECT_FALSE(can.isReachable(beyond)) << beyond.transpose();
      EXPECT_TRUE(falcon.isReachable(beyond)) << beyond.transpose();
    }
  }
  for (int k = 0; k < 12; ++k) {
    const double angle = kTwoPi * k / 12.0;
    for (const double z : {p.travel_stop_floor_m + 1e-3, 0.0, p.travel_stop_ceiling_m - 1e-3}) {
      const Eigen::Vector3d beyond((r + 1e-3) * std::cos(angle), (r + 1e-3) * std::sin(angle), z);
      EXPECT_FALSE(can.isReachable(beyond)) << beyond.transpose();
      EXPECT_TRUE(falcon.isReachable(beyond)) << beyond.transpose();
    }
  }
  // The workspace sphere it specifies is the one inscribed in the can.
  EXPECT_EQ(can.specifications().workspace_radius_m, r);
  EXPECT_EQ(-p.travel_stop_floor_m, r);
  EXPECT_EQ(p.travel_stop_ceiling_m, r);
}

TEST(FalconCanTest, FieldAndMassInsideAreSimFalcons) {
  const DeltaDevice can(falconCanParameters(), 1);
  const DeltaDevice falcon(falconParameters(), 1);
  for (const Eigen::Vector3d& point : cubePoints(0.089, 7)) {
    if (!can.isReachable(point)) continue;
    EXPECT_EQ(can.trueGravity(point), falcon.trueGravity(point)) << point.transpose();
    EXPECT_EQ(can.trueApparentMass(point), falcon.trueApparentMass(point)) << point.transpose();
  }
  // The named devices too, unit for unit: the same motors' gains, so the same holding force.
  for (const int number : {1, 2, 5}) {
    const SimulatedUnit unit{number, ActuatorTolerance::kHigh};
    const auto named_can = makeSimulatedDevice("sim:falcon-can", 4, FrictionLevel::kHigh, unit);
    const auto named_falcon = makeSimulatedDevice("sim:falcon", 4, FrictionLevel::kHigh, unit);
    for (const Eigen::Vector3d& point :
         {Eigen::Vector3d(0.0, 0.0, -0.044), Eigen::Vector3d(-0.03, 0.02, 0.044)}) {
      EXPECT_EQ(named_can->trueGravity(point), named_falcon->trueGravity(point)) << number;
    }
  }
}

TEST(FalconCanTest, KeepsSimFalconsFrictionActuatorsDacEncodersAndDelay) {
  for (const FrictionLevel level :
       {FrictionLevel::kNone, FrictionLevel::kTypical, FrictionLevel::kHigh}) {
    const DeltaParameters can = falconCanParameters(level);
    const DeltaParameters falcon = falconParameters(level);
    EXPECT_EQ(can.friction.stiction, falcon.friction.stiction);
    EXPECT_EQ(can.friction.coulomb, falcon.friction.coulomb);
    EXPECT_EQ(can.friction.viscous, falcon.friction.viscous);
    EXPECT_EQ(can.driver.motor_limit, falcon.driver.motor_limit);
    EXPECT_EQ(can.driver.dac_bits, falcon.driver.dac_bits);
    EXPECT_EQ(can.driver.transport_delay_s, falcon.driver.transport_delay_s);
    EXPECT_EQ(can.driver.noise_sigma_counts, falcon.driver.noise_sigma_counts);
    EXPECT_EQ(can.joint_counts_per_rev, falcon.joint_counts_per_rev);
    EXPECT_EQ(can.specifications.max_linear_force_n, falcon.specifications.max_linear_force_n);
    EXPECT_EQ(can.grip_mass_kg, falcon.grip_mass_kg);
    EXPECT_EQ(can.travel_stop_damping_n_s_per_m, falcon.travel_stop_damping_n_s_per_m);
    EXPECT_EQ(can.travel_stop_shape, TravelStopShape::kCylinder);
    EXPECT_EQ(falcon.travel_stop_shape, TravelStopShape::kBox);
  }
  for (const ActuatorTolerance tolerance :
       {ActuatorTolerance::kTypical, ActuatorTolerance::kHigh}) {
    EXPECT_EQ(actuatorGainBound("sim:falcon-can", tolerance),
              actuatorGainBound("sim:falcon", tolerance));
    const SimulatedUnit unit{3, tolerance};
    EXPECT_EQ(actuatorGains("sim:falcon-can", unit), actuatorGains("sim:falcon", unit));
  }
}

TEST(FalconCanTest, BadCylinderParametersAreRefusedWithTheirName) {
  using P = DeltaParameters;
  const testing::RefusalCheck<DeltaDevice, P> refused(falconCanParameters(), "sim delta device");
  refused([](P& p) { p.travel_stop_radius_m = 0.0; }, "travel_stop_radius_m");
  refused([](P& p) { p.travel_stop_floor_m = 0.01; }, "travel_stop_floor_m");
  refused([](P& p) { p.travel_stop_ceiling_m = -0.01; }, "travel_stop_floor_m");
  // 90 mm out is beyond the arms' stops.
  refused([](P& p) { p.travel_stop_radius_m = 0.09; }, "the cylinder of travel stops");
}

}  // namespace
}  // namespace autograv::sim
