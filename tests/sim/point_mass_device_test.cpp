#include "autograv/sim/point_mass_device.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/sim/paper_frame.h"
#include "device_checks.h"

namespace autograv::sim {
namespace {

constexpr double kServo_s = 0.001;

PointMassDevice makeOpenOmega(std::uint64_t seed = 7) {
  return testing::openCalibrated<PointMassDevice>(omegaParameters(), seed);
}

TEST(PointMassDeviceTest, GravityAtThePaperTargetWeighs214Grams) {
  const PointMassDevice device(omegaParameters(), 1);
  const Eigen::Vector3d target = paperTargetPoint_m();
  const Eigen::Vector3d gravity = device.trueGravity(target);
  EXPECT_NEAR(gravity.norm(), 0.214 * kStandardGravity, 1e-12);
  // The holding force points up (eq. 1: F = G holds the end-effector still).
  EXPECT_GT(gravity.z(), 0.9 * gravity.norm());
}

TEST(PointMassDeviceTest, GravityIsTheGradientOfAPotential) {
  const PointMassDevice device(omegaParameters(), 1);
  const double h = 1e-6;
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.01, -0.02, 0.03),
                                   Eigen::Vector3d(-0.05, 0.03, -0.04), paperStartPoint_m()}) {
    Eigen::Vector3d numeric;
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(axis);
      numeric[axis] =
          (device.potentialEnergy_j(p + step) - device.potentialEnergy_j(p - step)) / (2 * h);
    }
    EXPECT_LT((numeric - device.trueGravity(p)).norm(), 1e-8) << p.transpose();
  }
}

TEST(PointMassDeviceTest, FieldVariesAcrossTheWorkspaceLikeAMechanism) {
  const PointMassDevice device(omegaParameters(), 1);
  const double radius = device.specifications().workspace_radius_m;
  double smallest = 1e9, largest = 0.0, max_horizontal = 0.0, max_gradient = 0.0;
  double min_gradient = 1e9;
  for (int i = -3; i <= 3; ++i) {
    for (int j = -3; j <= 3; ++j) {
      for (int k = -3; k <= 3; ++k) {
        const Eigen::Vector3d offset = Eigen::Vector3d(i, j, k) * (radius / 3.0);
        if (offset.norm() > radius) continue;
        const Eigen::Vector3d p = device.workspaceCenter_m() + offset;
        const Eigen::Vector3d g = device.trueGravity(p);
        smallest = std::min(smallest, g.norm());
        largest = std::max(largest, g.norm());
        max_horizontal = std::max(max_horizontal, g.head<2>().norm());
        // Spectral norm of the Jacobian dG/dX by central differences.
        Eigen::Matrix3d jacobian;
        for (int axis = 0; axis < 3; ++axis) {
          const Eigen::Vector3d step = 1e-6 * Eigen::Vector3d::Unit(axis);
          jacobian.col(axis) = (device.trueGravity(p + step) - device.trueGravity(p - step)) / 2e-6;
        }
        const double norm = jacobian.jacobiSvd().singularValues()(0);
        max_gradient = std::max(max_gradient, norm);
        min_gradient = std::min(min_gradient, norm);
      }
    }
  }
  const double mean = 0.5 * (smallest + largest);
  EXPECT_GT((largest - smallest) / mean, 0.2);  // tens of percent...
  EXPECT_LT((largest - smallest) / mean, 0.8);  // ...but not a different device
  EXPECT_GT(max_horizontal, 0.2);               // x/y components of a few tenths of a newton
  EXPECT_GT(min_gradient, 5.0);                 // N/m: the gradient makes the method iterate
  EXPECT_LT(max_gradient, 30.0);
}

TEST(PointMassDeviceTest, ReleasedFromRestAcceleratesAsMInverseG) {
  PointMassDevice device = makeOpenOmega();
  const Eigen::Vector3d start = paperTargetPoint_m();
  device.resetState(start);
  ASSERT_TRUE(device.setForce(Eigen::Vector3d::Zero()));
  const Eigen::Vector3d gravity = device.trueGravity(start);
  const Eigen::Vector3d acceleration = -device.trueApparentMass(start).inverse() * gravity;
  const double h = device.internalStep_s();
  for (int ms = 1; ms <= 5; ++ms) {
    device.advance(kServo_s);
    const double t = ms * kServo_s;
    // Friction (about 30 mN per axis against 2.1 N), the bristle damping's impulse while the
    // bristles first deflect (sigma1 z_ss / m, under 1 mm/s) and the change of M over 0.1 mm.
    EXPECT_LT((device.trueVelocity_m_per_s() - acceleration * t).norm(),
              0.04 * acceleration.norm() * t + 0.001)
        << "t=" << t;
    const Eigen::Vector3d expected = start + 0.5 * acceleration * t * (t + h);
    EXPECT_LT((device.truePosition_m() - expected).norm(),
              0.04 * (expected - start).norm() + 0.001 * t)
        << "t=" << t;
  }
  // Friction is visible: the fall is slower than the frictionless one.
  EXPECT_LT(device.trueVelocity_m_per_s().dot(acceleration.normalized()),
            0.999 * acceleration.norm() * 0.005);
}

TEST(PointMassDeviceTest, SaturationClampsTheMagnitudeKeepsTheDirectionAndCounts) {
  PointMassDevice device = makeOpenOmega();
  const Eigen::Vector3d small(1.0, -2.0, 3.0);
  ASSERT_TRUE(device.setForce(small));
  device.advance(kServo_s);  // one servo period of transport delay
  const double dac_count_n = 12.0 * 2.0 / 16384.0;
  EXPECT_LT((device.appliedForce_n() - small).cwiseAbs().maxCoeff(), 0.5 * dac_count_n + 1e-12);
  EXPECT_EQ(device.saturationCount(), 0u);
  const Eigen::Vector3d large(30.0, 0.0, -40.0);  // 50 N
  ASSERT_TRUE(device.setForce(large));
  device.advance(kServo_s);
  EXPECT_NEAR(device.appliedForce_n().norm(), 12.0, dac_count_n);
  EXPECT_TRUE(device.appliedForce_n().normalized().isApprox(large.normalized(), 1e-3));
  EXPECT_EQ(device.saturationCount(), 1u);
  ASSERT_TRUE(device.setForce(large));
  EXPECT_EQ(device.saturationCount(), 2u);
  // The clamped force is what moves the mass.
  const Eigen::Vector3d centre = device.workspaceCenter_m();
  device.resetState(centre);
  device.advance(0.002);
  const Eigen::Vector3d expected_direction =
      (device.trueApparentMass(centre).inverse() *
       (device.appliedForce_n() - device.trueGravity(centre)))
          .normalized();
  EXPECT_GT((device.truePosition_m() - centre).normalized().dot(expected_direction), 0.999);
}

TEST(PointMassDeviceTest, VelocityIsExactlyZeroAtRestAndTracksConstantVelocity) {
  PointMassDevice device = makeOpenOmega();
  // Mid-count on every axis: the encoder noise (0.05 counts) never reaches a transition.
  // The force reaches the actuators one servo period after setForce: command it first.
  ASSERT_TRUE(device.setForce(device.trueGravity(Eigen::Vector3d(0.0, 0.0, -0.03))));
  device.advance(kServo_s);
  device.resetState(Eigen::Vector3d(0.0, 0.0, -0.03));
  Eigen::Vector3d x, v;
  for (int ms = 0; ms < 300; ++ms) {
    ASSERT_TRUE(device.getPosition(x));
    ASSERT_TRUE(device.getLinearVelocity(v));
    EXPECT_EQ(v, Eigen::Vector3d::Zero()) << "ms=" << ms;
    device.setForce(device.trueGravity(x));
    device.advance(kServo_s);
  }
  // The hand drags it at 50 mm/s along a diagonal; gravity is cancelled.
  const Eigen::Vector3d direction = Eigen::Vector3d(1.0, 1.0, 0.5).normalized();
  device.hand().grab(device.truePosition_m());
  device.hand().moveTo(device.truePosition_m() + 0.04 * direction, 0.05);
  double worst = 0.0;
  for (int ms = 0; ms < 700; ++ms) {
    ASSERT_TRUE(device.getPosition(x));
    ASSERT_TRUE(device.getLinearVelocity(v));
    if (ms >= 300) worst = std::max(worst, (v - 0.05 * direction).norm());
    device.setForce(device.trueGravity(x));
    device.advance(kServo_s);
  }
  EXPECT_LT(worst, 0.002);  // m/s: 4 % of the speed; 0.5 mm/s is one count over the window
}

TEST(PointMassDeviceTest, VelocityReadsZeroWheneverTheCountsDidNotChangeOverTheWindow) {
  PointMassDevice device = makeOpenOmega(11);
  // Near a count transition on x, so that the noise makes the reading flicker now and then.
  // The force reaches the actuators one servo period after setForce: command it first.
  ASSERT_TRUE(device.setForce(device.trueGravity(Eigen::Vector3d(0.000005, 0.0, -0.03))));
  device.advance(kServo_s);
  device.resetState(Eigen::Vector3d(0.000005, 0.0, -0.03));
  std::vector<Eigen::Vector3d> readings;
  int zero = 0, checked = 0;
  for (int ms = 0; ms < 1000; ++ms) {
    Eigen::Vector3d x, v;
    ASSERT_TRUE(device.getPosition(x));
    ASSERT_TRUE(device.getLinearVelocity(v));
    readings.push_back(x);
    const int window = 21;  // 20 ms at 1 kHz, both ends included
    if (static_cast<int>(readings.size()) >= window) {
      bool unchanged = true;
      for (int k = 1; k < window; ++k)
        unchanged = unchanged && readings[readings.size() - 1 - k] == x;
      if (unchanged) {
        ++checked;
        EXPECT_EQ(v, Eigen::Vector3d::Zero());
      }
    }
    zero += v.isZero(0.0) ? 1 : 0;
    device.setForce(device.trueGravity(device.truePosition_m()));
    device.advance(kServo_s);
  }
  EXPECT_GT(checked, 100);
  EXPECT_LT(zero, 1000);  // the flicker is there, so the check above was not vacuous
  // Held by friction: pre-sliding under the DAC's rounding and cogging only.
  EXPECT_LT((device.truePosition_m() - Eigen::Vector3d(0.000005, 0.0, -0.03)).norm(), 1e-6);
}

TEST(PointMassDeviceTest, HandPullsTheEndEffectorAlongItsPath) {
  PointMassDevice device = makeOpenOmega();
  device.hand().grab(device.truePosition_m());
  const Eigen::Vector3d goal = device.workspaceCenter_m() + Eigen::Vector3d(0.03, -0.02, 0.01);
  device.hand().moveTo(goal, 0.1);
  device.advance(1.0);
  EXPECT_TRUE(device.hand().atGoal());
  // The grip spring carries the weight: it sags by G/k below the goal.
  const Eigen::Vector3d sag = -device.trueGravity(goal) / device.hand().stiffness_n_per_m;
  EXPECT_LT((device.truePosition_m() - (goal + sag)).norm(), 2e-4);
  device.hand().release();
  device.advance(0.05);
  EXPECT_LT(device.truePosition_m().z(), goal.z() + sag.z() - 0.005);
}

TEST(PointMassDeviceTest, BadParametersAreRefusedWithTheirName) {
  using P = PointMassParameters;
  const testing::RefusalCheck<PointMassDevice, P> refused(omegaParameters(),
                                                          "sim point-mass device");
  // Not symmetric, stiction below Coulomb, not a unit vector, no period.
  refused([](P& p) { p.gravity_gradient_n_per_m(0, 1) = 7.0; }, "gravity_gradient_n_per_m");
  refused([](P& p) { p.friction.stiction[1] = 0.001; }, "friction stiction");
  refused([](P& p) { p.actuator_directions(0, 0) = 2.0; }, "actuator_directions");
  refused([](P& p) { p.cogging_period_m[2] = 0.0; }, "cogging_period_m");
}

TEST(PointMassDeviceTest, SpecificationsDescribeAnOmega3) {
  const PointMassDevice device(omegaParameters(), 1);
  const auto& spec = device.specifications();
  EXPECT_EQ(spec.max_linear_stiffness_n_per_m, 14500.0);
  EXPECT_EQ(spec.max_linear_damping_n_s_per_m, 20.0);
  EXPECT_EQ(device.internalStep_s(), 1e-4);
  EXPECT_EQ(device.workspaceCenter_m(), paperTargetPoint_m());
}

}  // namespace
}  // namespace autograv::sim
