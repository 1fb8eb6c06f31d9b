// The simulated devices are at least as hard as the hardware: friction with pre-sliding and a
// breakaway within the published bounds, force DAC quantization, one servo period of transport
// delay, and the omega's inertia of its own.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include "allocation_counter.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/sim/friction_measurement.h"
#include "autograv/sim/paper_frame.h"
#include "autograv/sim/point_mass_device.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/serial_arm_device.h"
#include "autograv/sim/simulated_device.h"
#include "device_checks.h"

namespace autograv::sim {
namespace {

constexpr double kServo_s = 0.001;
// SensAble's PHANToM Omni datasheet: backdrive friction < 0.26 N.
constexpr double kOmniBackdriveBound_n = 0.26;
// One encoder count at the Omni's tip is about 0.055 mm; the omega's is 0.01 mm.
constexpr double kOmniCount_m = 0.055e-3;
constexpr double kOmegaCount_m = 0.01e-3;

double encoderCount_m(const std::string& name) {
  return name == "sim:omni" ? kOmniCount_m : kOmegaCount_m;
}

std::unique_ptr<SimulatedDevice> openDevice(
    const std::string& name, FrictionLevel level, std::uint64_t seed = 3,
    ActuatorTolerance actuators = ActuatorTolerance::kTypical) {
  auto device = makeSimulatedDevice(name, seed, level, {1, actuators});
  EXPECT_TRUE(device->open());
  EXPECT_TRUE(device->calibrate());
  return device;
}

// From rest at the centre, pushes with `force_n` on top of the true gravity, faded in over 0.1 s
// as a hand would, then held for `seconds`; returns the largest distance of the true position
// from the start.
double driftUnder(SimulatedDevice& device, const Eigen::Vector3d& force_n, double seconds) {
  const Eigen::Vector3d start = device.workspaceCenter_m();
  testing::restWithGravityCancelled(device, start);
  constexpr double kFadeIn_s = 0.1;
  double worst_m = 0.0;
  for (double t = 0.0; t < kFadeIn_s + seconds; t += kServo_s) {
    Eigen::Vector3d measured;
    EXPECT_TRUE(device.getPosition(measured));
    const double fade = std::min(1.0, t / kFadeIn_s);
    device.setForce(device.trueGravity(device.truePosition_m()) + fade * force_n);
    device.advance(kServo_s);
    worst_m = std::max(worst_m, (device.truePosition_m() - start).norm());
  }
  return worst_m;
}

TEST(DeviceFrictionTest, OmniBreakawayAtTypicalIsWithinTheDatasheetBoundInEveryDirection) {
  auto device = openDevice("sim:omni", FrictionLevel::kTypical);
  const FrictionMeasurement friction = measureFriction(*device);
  ASSERT_EQ(friction.directions.size(), 14u);
  for (std::size_t i = 0; i < friction.directions.size(); ++i) {
    EXPECT_GE(friction.breakaway_n[i], 0.030) << friction.directions[i].transpose();
    EXPECT_LE(friction.breakaway_n[i], kOmniBackdriveBound_n) << friction.directions[i].transpose();
  }
  EXPECT_LE(friction.breakaway_force_n, kOmniBackdriveBound_n);
  EXPECT_GE(friction.min_breakaway_force_n, 0.030);
  // Sliding friction is below the breakaway and well above zero.
  EXPECT_GT(friction.coulomb_force_n, 0.02);
  EXPECT_LT(friction.coulomb_force_n, friction.breakaway_force_n);
}

TEST(DeviceFrictionTest, LevelsOrderTheBreakawayAndNoneHasNoDryFriction) {
  for (const std::string name : {"sim:omni", "sim:omega"}) {
    double previous_n = 0.0;
    for (const FrictionLevel level : {FrictionLevel::kNone, FrictionLevel::kLow,
                                      FrictionLevel::kTypical, FrictionLevel::kHigh}) {
      auto device = openDevice(name, level);
      const FrictionMeasurement friction = measureFriction(*device);
      if (level == FrictionLevel::kNone) {
        // Sliding takes only the viscous force, which the measurement takes out; what the ramp
        // needs to move it 0.1 mm is cogging, DAC rounding and the viscous drag: a few mN.
        EXPECT_LT(std::abs(friction.coulomb_force_n), 0.002) << name;
        EXPECT_LT(friction.breakaway_force_n, 0.010) << name;
      } else {
        // Each level is a few times the one below (dry friction 1/3, 1 and 2.5 times typical).
        EXPECT_GT(friction.breakaway_force_n, 2.0 * previous_n) << name << " " << toString(level);
      }
      if (level == FrictionLevel::kHigh && name == "sim:omni") {
        EXPECT_LT(friction.breakaway_force_n, 0.4);  // a stiff unit, still a plausible Omni
      }
      previous_n = friction.breakaway_force_n;
    }
  }
}

TEST(DeviceFrictionTest, WithoutDryFrictionATinyForceMovesIt) {
  for (const std::string name : {"sim:omni", "sim:omega"}) {
    auto device = openDevice(name, FrictionLevel::kNone);
    EXPECT_GT(driftUnder(*device, Eigen::Vector3d(0.0, 0.01, 0.0), 0.5), 0.002) << name;
  }
}

TEST(DeviceFrictionTest, StuckBelowBreakawaySlidesAbove) {
  for (const std::string name : {"sim:omni", "sim:omega"}) {
    auto device = openDevice(name, FrictionLevel::kTypical);
    const FrictionMeasurement friction = measureFriction(*device);
    for (std::size_t i : {0u, 3u, 5u, 9u}) {  // +x, -y, -z, a diagonal
      const Eigen::Vector3d direction = friction.directions[i];
      const double breakaway_n = friction.breakaway_n[i];
      // 70 % of the breakaway for 2 s: pre-sliding only, below a few encoder counts.
      EXPECT_LT(driftUnder(*device, 0.7 * breakaway_n * direction, 2.0), 3.0 * encoderCount_m(name))
          << name << " " << direction.transpose();
      // 130 %: it slides away.
      EXPECT_GT(driftUnder(*device, 1.3 * breakaway_n * direction, 0.5), 0.002)
          << name << " " << direction.transpose();
    }
  }
}

TEST(DeviceFrictionTest, PreSlidingIsSmallAndSpringsBack) {
  auto device = openDevice("sim:omni", FrictionLevel::kTypical);
  const Eigen::Vector3d start = device->workspaceCenter_m();
  testing::restWithGravityCancelled(*device, start);
  const Eigen::Vector3d push_n(0.0, 0.03, 0.0);  // below the breakaway along y
  for (int ms = 0; ms < 500; ++ms) {
    device->setForce(device->trueGravity(device->truePosition_m()) + push_n);
    device->advance(kServo_s);
  }
  const double loaded_m = (device->truePosition_m() - start).norm();
  for (int ms = 0; ms < 500; ++ms) {
    device->setForce(device->trueGravity(device->truePosition_m()));
    device->advance(kServo_s);
  }
  const double released_m = (device->truePosition_m() - start).norm();
  EXPECT_GT(loaded_m, 1e-6);          // the bristles deflect: it is not an exact stop
  EXPECT_LT(loaded_m, kOmniCount_m);  // but by less than an encoder count
  EXPECT_LT(released_m, 0.8 * loaded_m);
}

TEST(DeviceFrictionTest, DacQuantizationAndOnePeriodDelayShowInTheAppliedForce) {
  for (const std::string name : {"sim:omni", "sim:omega"}) {
    // Ideal actuators: what reaches the end-effector is the quantized command itself.
    auto device = openDevice(name, FrictionLevel::kTypical, 3, ActuatorTolerance::kIdeal);
    const Eigen::Vector3d first(0.1234567, -0.2345678, 0.3456789);
    ASSERT_TRUE(device->setForce(first));
    EXPECT_EQ(device->appliedForce_n(), Eigen::Vector3d::Zero()) << name;  // not there yet
    device->advance(0.0009);
    EXPECT_EQ(device->appliedForce_n(), Eigen::Vector3d::Zero()) << name;
    device->advance(0.0001);
    const Eigen::Vector3d applied = device->appliedForce_n();
    // Quantized: close to the command, but not equal to it.
    EXPECT_LT((applied - first).norm(), 0.003) << name;
    EXPECT_GT((applied - first).norm(), 1e-6) << name;
    // A second command replaces the first one a period later.
    ASSERT_TRUE(device->setForce(-first));
    device->advance(0.0005);
    EXPECT_LT((device->appliedForce_n() - applied).norm(), 1e-3) << name;
    device->advance(0.0005);
    EXPECT_LT((device->appliedForce_n() + first).norm(), 0.003) << name;
  }
}

TEST(DeviceFrictionTest, OmniJointsSaturateBeforeTheCartesianClamp) {
  SerialArmDevice device(omniParameters(), 1);
  ASSERT_TRUE(device.open());
  device.resetState(Eigen::Vector3d(0.05, 0.0, 0.0));            // 19 cm from the yaw axis
  ASSERT_TRUE(device.setForce(Eigen::Vector3d(0.0, 3.0, 0.0)));  // below the 3.3 N clamp
  EXPECT_EQ(device.saturationCount(), 1u);
  device.advance(kServo_s);
  EXPECT_NEAR(std::abs(device.activeMotorCommand()[0]), 0.45, 1e-3);
  EXPECT_LT(device.appliedForce_n().norm(), 2.6);
}

TEST(DeviceFrictionTest, OmegaInertiaIsItsOwnAnisotropicAndPositionDependent) {
  const PointMassDevice device(omegaParameters(), 1);
  const Eigen::Vector3d centre = device.workspaceCenter_m();
  const Eigen::Matrix3d at_centre = device.trueApparentMass(centre);
  const Eigen::Matrix3d off_centre =
      device.trueApparentMass(centre + Eigen::Vector3d(0.03, -0.02, 0.02));
  for (const Eigen::Matrix3d& mass : {at_centre, off_centre}) {
    EXPECT_TRUE(mass.isApprox(mass.transpose(), 1e-12));
    const Eigen::Vector3d eigen =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mass).eigenvalues();
    EXPECT_GT(eigen.minCoeff(), 0.05);                    // positive definite, a real handle's mass
    EXPECT_GT(eigen.maxCoeff() / eigen.minCoeff(), 1.1);  // anisotropic
  }
  EXPECT_GT((off_centre - at_centre).norm(), 0.02);  // kg: position dependent
  // Not the paper's modelling assumption |G|/g.
  const Eigen::Vector3d target = paperTargetPoint_m();
  const double paper_mass = device.trueGravity(target).norm() / kStandardGravity;
  EXPECT_NEAR(paper_mass, 0.214, 1e-9);
  EXPECT_GT((device.trueApparentMass(target) - paper_mass * Eigen::Matrix3d::Identity()).norm(),
            0.02);
}

TEST(DeviceFrictionTest, OmegaDynamicsFollowItsInertia) {
  // Frictionless and uncogged, released from rest: Xdd = -M(X)^-1 G(X), not -G / (|G|/g).
  PointMassParameters parameters = omegaParameters(FrictionLevel::kNone);
  parameters.cogging_amplitude_n.setZero();
  PointMassDevice device(parameters, 1);
  ASSERT_TRUE(device.open());
  const Eigen::Vector3d start = device.workspaceCenter_m() + Eigen::Vector3d(0.01, 0.02, 0.0);
  device.resetState(start);
  const Eigen::Vector3d expected =
      -device.trueApparentMass(start).inverse() * device.trueGravity(start);
  device.advance(0.002);
  const Eigen::Vector3d measured = device.trueVelocity_m_per_s() / 0.002;
  EXPECT_LT((measured - expected).norm(), 0.01 * expected.norm());
  const Eigen::Vector3d paper =
      -device.trueGravity(start) / (device.trueGravity(start).norm() / kStandardGravity);
  EXPECT_GT((measured - paper).norm(), 0.05 * paper.norm());
}

TEST(DeviceFrictionTest, PaperStartPointIsInsideOmegaWorkspaceWithMargin) {
  auto device = openDevice("sim:omega", FrictionLevel::kTypical);
  const double radius_m = device->specifications().workspace_radius_m;
  const Eigen::Vector3d start = paperStartPoint_m();
  EstimationParameters parameters;
  // After the sag in the k0 field the end-effector still clears the stop by 5 mm.
  const Eigen::Vector3d sagged = start - device->trueGravity(start) / parameters.k0_n_per_m;
  EXPECT_LT((sagged - device->workspaceCenter_m()).norm(), radius_m - 0.005);
  // Omega.3 workspace: 160 mm across, 110 mm high.
  EXPECT_LE(2.0 * radius_m, 0.110);
}

TEST(DeviceFrictionTest, PaperExperimentDoesNotStartOnAnEndStop) {
  auto device = openDevice("sim:omega", FrictionLevel::kTypical);
  EstimationParameters parameters;
  const InitializationResult initialization =
      initializeWithSimulatedHand(*device, parameters, paperStartPoint_m());
  ASSERT_TRUE(initialization.ok) << initialization.message;
  EXPECT_FALSE(initialization.end_stop_hit);
  EXPECT_FALSE(device->endStopHit());
  const Eigen::Vector3d truth = device->trueGravity(paperStartPoint_m());
  EXPECT_LT((initialization.gravity_n - truth).norm(), 0.1 * truth.norm());
}

TEST(DeviceFrictionTest, InitializationOnAnEndStopSaysSo) {
  auto device = openDevice("sim:omega", FrictionLevel::kTypical);
  EstimationParameters parameters;
  const double radius_m = device->specifications().workspace_radius_m;
  const Eigen::Vector3d low = device->workspaceCenter_m() - Eigen::Vector3d(0, 0, radius_m - 0.001);
  const InitializationResult initialization = initializeWithSimulatedHand(*device, parameters, low);
  EXPECT_TRUE(initialization.end_stop_hit);
  EXPECT_FALSE(initialization.ok);
  EXPECT_NE(initialization.message.find("end stop"), std::string::npos) << initialization.message;
}

std::vector<Eigen::Vector3d> scriptedRun(const std::string& name, std::uint64_t seed) {
  auto device = openDevice(name, FrictionLevel::kTypical, seed);
  std::vector<Eigen::Vector3d> trajectory;
  const Eigen::Vector3d centre = device->workspaceCenter_m();
  for (int ms = 0; ms < 800; ++ms) {
    Eigen::Vector3d x, v;
    device->getPosition(x);
    device->getLinearVelocity(v);
    const Eigen::Vector3d target = centre + Eigen::Vector3d(0.01 * std::sin(ms * 0.01), 0.0, 0.0);
    device->setForce(device->trueGravity(x) + 200.0 * (target - x) - 1.0 * v);
    device->advance(kServo_s);
    trajectory.push_back(device->truePosition_m());
    trajectory.push_back(device->appliedForce_n());
  }
  return trajectory;
}

TEST(DeviceFrictionTest, SameSeedSameRunBitForBit) {
  for (const std::string name : {"sim:omni", "sim:omega"}) {
    const auto a = scriptedRun(name, 9);
    const auto b = scriptedRun(name, 9);
    ASSERT_EQ(a.size(), b.size());
    bool identical = true;
    for (std::size_t i = 0; i < a.size(); ++i)
      identical = identical && (a[i].array() == b[i].array()).all();
    EXPECT_TRUE(identical) << name;
  }
}

TEST(DeviceFrictionTest, SetForceAndAdvanceAllocateNothingAtEveryLevel) {
  for (const std::string name : {"sim:omni", "sim:omega"}) {
    for (const FrictionLevel level : {FrictionLevel::kNone, FrictionLevel::kHigh}) {
      auto device = openDevice(name, level);
      device->hand().grab(device->truePosition_m());
      device->hand().moveTo(device->workspaceCenter_m() + Eigen::Vector3d(0.01, 0.0, 0.0), 0.05);
      const autograv::testing::AllocationCounter counter;
      for (int ms = 0; ms < 500; ++ms) {
        device->setForce(Eigen::Vector3d(0.0, 0.0, 0.5 + 0.001 * ms));
        device->setForce(Eigen::Vector3d(0.0, 0.0, 0.5));  // twice in a period: the later wins
        device->advance(kServo_s);
        (void)device->appliedForce_n();
      }
      EXPECT_EQ(counter.count(), 0u) << name;
    }
  }
}

}  // namespace
}  // namespace autograv::sim
