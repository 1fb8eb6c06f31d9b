#include "autograv/sim/serial_arm_device.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>

#include "autograv/error.h"
#include "device_checks.h"

namespace autograv::sim {
namespace {

constexpr double kServo_s = 0.001;

SerialArmDevice makeOpenOmni() {
  return testing::openCalibrated<SerialArmDevice>(omniParameters(), 7);
}

// Points spread through the workspace sphere (radius 0.1 m), centre included.
std::vector<Eigen::Vector3d> workspacePoints(double radius) {
  std::vector<Eigen::Vector3d> points;
  for (int i = -2; i <= 2; ++i) {
    for (int j = -2; j <= 2; ++j) {
      for (int k = -2; k <= 2; ++k) {
        const Eigen::Vector3d p = Eigen::Vector3d(i, j, k) * (radius / 2.0);
        if (p.norm() <= radius) points.push_back(p);
      }
    }
  }
  return points;
}

TEST(SerialArmDeviceTest, HomePoseIsTheWorkspaceCentre) {
  const SerialArmDevice device(omniParameters(), 1);
  EXPECT_LT(device.forwardKinematics(device.parameters().home_joint_angles_rad).norm(), 1e-15);
  EXPECT_LT(device.truePosition_m().norm(), 1e-15);
  EXPECT_EQ(device.workspaceCenter_m(), Eigen::Vector3d::Zero());
}

TEST(SerialArmDeviceTest, InverseKinematicsInvertsForwardKinematics) {
  const SerialArmDevice device(omniParameters(), 1);
  int checked = 0;
  for (double q1 = -0.8; q1 <= 0.8; q1 += 0.2) {
    for (double q2 = -0.3; q2 <= 1.2; q2 += 0.15) {
      for (double offset = -1.3; offset <= 1.3; offset += 0.2) {
        const Eigen::Vector3d q(q1, q2, q2 + offset);
        // The device's branch: the tip stays in front of the yaw axis.
        const double l = device.parameters().upper_arm_length_m;
        if (l * std::cos(q[1]) + l * std::sin(q[2]) < 0.01) continue;
        Eigen::Vector3d back;
        ASSERT_TRUE(device.inverseKinematics(device.forwardKinematics(q), back));
        EXPECT_LT((back - q).cwiseAbs().maxCoeff(), 1e-10) << q.transpose();
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 500);
  for (const auto& p : workspacePoints(0.1)) {
    Eigen::Vector3d q;
    ASSERT_TRUE(device.inverseKinematics(p, q));
    EXPECT_LT((device.forwardKinematics(q) - p).norm(), 1e-12);
  }
  Eigen::Vector3d q;
  EXPECT_FALSE(device.inverseKinematics(Eigen::Vector3d(0.4, 0.0, 0.0), q));  // beyond l1 + l2
}

TEST(SerialArmDeviceTest, JacobianIsTheDerivativeOfForwardKinematics) {
  const SerialArmDevice device(omniParameters(), 1);
  for (const Eigen::Vector3d& q : {Eigen::Vector3d(0.0, 0.48, 0.16), Eigen::Vector3d(0.5, 0.1, 0.9),
                                   Eigen::Vector3d(-0.6, 1.0, 0.2)}) {
    Eigen::Matrix3d numeric;
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d step = 1e-7 * Eigen::Vector3d::Unit(j);
      numeric.col(j) =
          (device.forwardKinematics(q + step) - device.forwardKinematics(q - step)) / 2e-7;
    }
    EXPECT_LT((numeric - device.jacobian(q)).cwiseAbs().maxCoeff(), 1e-8);
  }
}

TEST(SerialArmDeviceTest, GravityTorqueIsTheDerivativeOfThePotential) {
  const SerialArmDevice device(omniParameters(), 1);
  testing::expectGravityTorqueIsTheDerivativeOfThePotential(device,
                                                            Eigen::Vector3d(0.3, 0.7, -0.2));
}

// The brief's check: J^-T g(q) is the Cartesian gradient of the potential energy.
TEST(SerialArmDeviceTest, CartesianGravityMatchesFiniteDifferenceOfPotentialEnergy) {
  const SerialArmDevice device(omniParameters(), 1);
  testing::expectCartesianGravityIsTheGradientOfThePotential(device, workspacePoints(0.09));
}

TEST(SerialArmDeviceTest, GravityAndMassLookLikeAnOmni) {
  const SerialArmDevice device(omniParameters(), 1);
  const testing::FieldRange range = testing::fieldRange(device, workspacePoints(0.1));
  EXPECT_GT(range.lightest_kg, 0.0);
  // About 0.5 N at the centre, within the Omni's continuous force, varying by tens of percent.
  const Eigen::Vector3d centre_gravity = device.trueGravity(Eigen::Vector3d::Zero());
  EXPECT_NEAR(centre_gravity.norm(), 0.5, 0.1);
  EXPECT_LT(range.largest_gravity_n, 0.88);
  EXPECT_GT((range.largest_gravity_n - range.smallest_gravity_n) / centre_gravity.norm(), 0.2);
  // Apparent mass: tens of grams and anisotropic; the paper's |G|/g I is only an approximation.
  const Eigen::Vector3d eigen = testing::apparentMassEigenvalues(device, Eigen::Vector3d::Zero());
  EXPECT_GT(eigen.minCoeff(), 0.02);
  EXPECT_LT(eigen.maxCoeff(), 0.12);
  EXPECT_GT(eigen.maxCoeff() / eigen.minCoeff(), 1.5);
}

TEST(SerialArmDeviceTest, MotionConservesEnergyWithoutFriction) {
  // Yaw and pitch swing together, so the Coriolis terms matter; the tip reaches about 1.7 m/s.
  SerialArmParameters parameters = omniParameters();
  parameters.cogging_amplitude_n_m.setZero();
  testing::expectEnergyErrorFirstOrderInTheStep<SerialArmDevice>(
      parameters, {Eigen::Vector3d(-0.02, -0.02, 0.02), Eigen::Vector3d(0.01, 0.01, 0.0), 60.0},
      0.005, 1.0);
}

TEST(SerialArmDeviceTest, ReleasedFromRestAcceleratesAsGOverM) {
  SerialArmDevice device = makeOpenOmni();
  const Eigen::Vector3d start(0.02, -0.03, 0.01);
  device.resetState(start);
  ASSERT_TRUE(device.setForce(Eigen::Vector3d::Zero()));
  const Eigen::Vector3d q = device.jointAngles_rad();
  // Without friction: -Lambda^-1 G, the Cartesian form of eq. (1).
  const Eigen::Matrix3d m = device.massMatrix(q);
  const Eigen::Vector3d free = -m.inverse() * device.gravityTorque(q);
  const Eigen::Vector3d frictionless =
      -device.trueApparentMass(start).inverse() * device.trueGravity(start);
  EXPECT_LT((frictionless - device.jacobian(q) * free).norm(), 1e-9 * frictionless.norm());
  // Half a millisecond. Joint friction (7 mN m against gravity torques of tens of mN m) slows
  // the fall by several %, cogging and the bristles' build-up by less.
  device.advance(0.0005);
  const Eigen::Vector3d measured = device.trueVelocity_m_per_s() / 0.0005;
  EXPECT_LT((measured - frictionless).norm(), 0.25 * frictionless.norm());
  EXPECT_GT((measured - frictionless).norm(), 0.01 * frictionless.norm());  // friction is visible
  EXPECT_GT(measured.normalized().dot(frictionless.normalized()), 0.97);
}

TEST(SerialArmDeviceTest, SaturationClampsTheMagnitudeAndCounts) {
  SerialArmDevice device = makeOpenOmni();
  ASSERT_TRUE(device.setForce(Eigen::Vector3d(0.0, 3.0, 0.0)));
  EXPECT_EQ(device.saturationCount(), 0u);
  const Eigen::Vector3d large(4.0, 0.0, 3.0);  // 5 N
  ASSERT_TRUE(device.setForce(large));
  device.advance(kServo_s);  // one servo period of transport delay
  // The clamp keeps the direction; the DAC rounds each joint torque to 0.22 mN m.
  EXPECT_NEAR(device.appliedForce_n().norm(), 3.3, 0.01);
  EXPECT_TRUE(device.appliedForce_n().normalized().isApprox(large.normalized(), 1e-3));
  EXPECT_EQ(device.saturationCount(), 1u);
}

TEST(SerialArmDeviceTest, VelocityIsZeroAtRestAndTracksConstantVelocity) {
  SerialArmDevice device = makeOpenOmni();
  Eigen::Vector3d x, v;
  int zero = 0;
  for (int ms = 0; ms < 300; ++ms) {
    ASSERT_TRUE(device.getPosition(x));
    ASSERT_TRUE(device.getLinearVelocity(v));
    zero += v.isZero(0.0) ? 1 : 0;
    device.setForce(device.trueGravity(device.truePosition_m()));
    device.advance(kServo_s);
  }
  EXPECT_GT(zero, 250);  // only encoder flicker near a count transition can make it nonzero
  const Eigen::Vector3d direction = Eigen::Vector3d(-1.0, 1.0, 0.5).normalized();
  device.hand().grab(device.truePosition_m());
  device.hand().moveTo(device.truePosition_m() + 0.05 * direction, 0.05);
  double worst = 0.0;
  for (int ms = 0; ms < 900; ++ms) {
    ASSERT_TRUE(device.getPosition(x));
    ASSERT_TRUE(device.getLinearVelocity(v));
    if (ms >= 300) worst = std::max(worst, (v - 0.05 * direction).norm());
    device.setForce(device.trueGravity(device.truePosition_m()));
    device.advance(kServo_s);
  }
  EXPECT_LT(worst, 0.005);  // m/s: 10 %; one tip count over the 15 ms window is 3.7 mm/s
}

TEST(SerialArmDeviceTest, TrueGravityRefusesPointsOutOfReach) {
  const SerialArmDevice device(omniParameters(), 1);
  EXPECT_THROW(device.trueGravity(Eigen::Vector3d(0.5, 0.0, 0.0)), Error);
}

TEST(SerialArmDeviceTest, BadParametersAreRefusedWithTheirName) {
  using P = SerialArmParameters;
  const testing::RefusalCheck<SerialArmDevice, P> refused(omniParameters(),
                                                          "sim serial-arm device");
  // 200 mm is beyond the arm's reach; stiction may not be below Coulomb friction.
  refused([](P& p) { p.specifications.workspace_radius_m = 0.2; }, "the workspace sphere");
  refused([](P& p) { p.tip_mass_kg = -0.01; }, "tip_mass_kg");
  refused([](P& p) { p.cogging_phase_rad[1] = NAN; }, "cogging_phase_rad");
  refused([](P& p) { p.friction.stiction[2] = 0.0; }, "friction stiction");
}

}  // namespace
}  // namespace autograv::sim
