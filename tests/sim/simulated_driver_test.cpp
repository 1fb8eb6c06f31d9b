#include "autograv/sim/simulated_driver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <ostream>
#include <string>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"
#include "device_checks.h"
#include "scripted_run.h"

namespace autograv::sim {
namespace {

TEST(RandomTest, SameSeedSameNumbersAndGaussianMoments) {
  Random a(99), b(99), c(100);
  bool differs = false;
  for (int i = 0; i < 100; ++i) {
    const std::uint64_t x = a.nextBits();
    EXPECT_EQ(x, b.nextBits());
    differs = differs || x != c.nextBits();
  }
  EXPECT_TRUE(differs);
  Random r(5);
  double sum = 0.0, sum2 = 0.0, max_abs = 0.0;
  constexpr int kCount = 200000;
  for (int i = 0; i < kCount; ++i) {
    const double g = r.gaussian();
    sum += g;
    sum2 += g * g;
    max_abs = std::max(max_abs, std::abs(g));
  }
  EXPECT_NEAR(sum / kCount, 0.0, 0.01);
  EXPECT_NEAR(sum2 / kCount, 1.0, 0.01);
  EXPECT_GT(max_abs, 3.5);
  EXPECT_TRUE(std::isfinite(max_abs));
  for (int i = 0; i < 1000; ++i) {
    const double u = r.uniform();
    EXPECT_GE(u, 0.0);
    EXPECT_LT(u, 1.0);
  }
}

TEST(VelocityEstimatorTest, ZeroWithoutChangeAndExactSlopeOverTheWindow) {
  VelocityEstimator estimator(0.01, 0.0);
  for (int k = 0; k <= 20; ++k) {
    EXPECT_EQ(estimator.update(k * 0.001, Eigen::Vector3d(0.1, 0.2, 0.3)), Eigen::Vector3d::Zero());
  }
  // A ramp at 0.05 m/s along x: the windowed difference is exact without low-pass.
  for (int k = 21; k <= 60; ++k) {
    const Eigen::Vector3d p(0.1 + 0.05 * (k - 20) * 0.001, 0.2, 0.3);
    const Eigen::Vector3d v = estimator.update(k * 0.001, p);
    if (k >= 31) {
      EXPECT_NEAR(v.x(), 0.05, 1e-9) << k;
    }
  }
  // Stops: exactly zero once the window holds no change, not an exponential tail.
  Eigen::Vector3d v;
  for (int k = 61; k <= 72; ++k)
    v = estimator.update(k * 0.001, Eigen::Vector3d(0.1 + 0.002, 0.2, 0.3));
  EXPECT_EQ(v, Eigen::Vector3d::Zero());
}

TEST(VelocityEstimatorTest, LowPassSmoothsAStep) {
  VelocityEstimator raw(0.005, 0.0), smooth(0.005, 0.002);
  raw.update(0.0, Eigen::Vector3d::Zero());
  smooth.update(0.0, Eigen::Vector3d::Zero());
  const Eigen::Vector3d jump(0.001, 0.0, 0.0);
  const double r = raw.update(0.001, jump).x();
  const double s = smooth.update(0.001, jump).x();
  EXPECT_NEAR(r, 1.0, 1e-12);  // 1 mm over 1 ms
  EXPECT_NEAR(s, 1.0 * 0.001 / (0.002 + 0.001), 1e-12);
}

// What every simulated device must do, checked with each preset's own figures (its published or
// assumed encoder resolution, force and workspace; see the presets' sources).

// Commanding the true gravity at `offset_m` from the workspace centre must hold the device: it
// may creep by `creep_m` in 1 s, its readings wander by `reading_change_m` (a distance) or by
// `reading_axis_change_m` along any one axis. Unit: [m]
struct HoldFigures {
  Eigen::Vector3d offset_m;
  double creep_m;
  double reading_change_m;
  double reading_axis_change_m;
};

// Released with zero force, after 2 s on its end stop: its distance from the centre lies between
// `min_distance_m` and `max_distance_m`, and it is lower than `below_z_m` (from the centre).
// Unit: [m]
struct FallFigures {
  double min_distance_m;
  double max_distance_m;
  double below_z_m;
};

// A frozen reading: the device falls for `before_s` and then, frozen, for `while_s` ([s]); once
// unfrozen (or calibrated) a reading is within `reading_error_m` ([m]) of the truth.
struct FreezeFigures {
  double reading_error_m;
  double before_s;
  double while_s;
};

// The servo-path check: a hand leads the device to `hand_goal_m` (absolute) under a loop lifting
// by `lift_n` and damping by `damping_n_s_per_m`. Units: [m], [N], [N s/m]
struct ServoFigures {
  Eigen::Vector3d hand_goal_m;
  double lift_n;
  double damping_n_s_per_m;
};

struct PresetFigures {
  const char* name;
  double max_force_n;         // Unit: [N]
  double workspace_radius_m;  // Unit: [m]
  HoldFigures hold;
  FallFigures fall;
  FreezeFigures freeze;
  ServoFigures servo;
  testing::ScriptGains script;  // of the determinism check
  /// A point the device can be put at, from the workspace centre. Unit: [m]
  Eigen::Vector3d reachable_offset_m;
};

void PrintTo(const PresetFigures& figures, std::ostream* out) { *out << figures.name; }

// An upper bound that is not checked for this preset.
constexpr double kUnchecked = std::numeric_limits<double>::infinity();
constexpr double kServo_s = 0.001;
// sim:falcon's published resolution, 400 dpi.
constexpr double kFalconResolution_m = 0.0254 / 400.0;
// About one encoder count at sim:omni's tip.
constexpr double kOmniResolution_m = 0.055e-3;
// sim:omega's Cartesian encoders.
constexpr double kOmegaResolution_m = 1e-5;

// clang-format off
const PresetFigures kPresets[] = {
    {"sim:omega", 12.0, 0.055,
     HoldFigures{Eigen::Vector3d(0.0123, -0.0271, 0.0189), kOmegaResolution_m, kUnchecked,
                 kOmegaResolution_m * 1.000001},
     FallFigures{0.055, 0.055 + 0.002, -0.04},  // about |G| / k_stop = 1 mm into the stop
     FreezeFigures{2e-5, 0.01, 0.05},
     ServoFigures{Eigen::Vector3d(0.01, 0.01, 0.0), 2.0, 5.0},
     {150.0, 8.0, 2.0}, Eigen::Vector3d(0.03, -0.02, 0.01)},
    {"sim:omni", 3.3, 0.10,
     HoldFigures{Eigen::Vector3d(0.031, -0.022, -0.04), kOmniResolution_m, 2 * kOmniResolution_m,
                 kUnchecked},
     FallFigures{0.099, 0.1 + 0.002, -0.05},
     FreezeFigures{1e-4, 0.02, 0.1},
     ServoFigures{Eigen::Vector3d(0.02, -0.02, 0.01), 0.5, 0.5},
     {60.0, 0.5, 0.5}, Eigen::Vector3d(0.05, 0.05, 0.05)},
    // The falcon's arms stop in joint space, beyond the sphere inscribed in its cube (which it
    // falls below).
    {"sim:falcon", 8.9, 0.0508,
     HoldFigures{Eigen::Vector3d(0.031, -0.022, -0.04), kFalconResolution_m,
                 2 * kFalconResolution_m, kUnchecked},
     FallFigures{0.0508 - 0.002, kUnchecked, -0.0508},
     FreezeFigures{1e-4, 0.02, 0.1},
     ServoFigures{Eigen::Vector3d(0.02, -0.02, 0.01), 1.0, 1.0},
     {100.0, 1.0, 1.0}, Eigen::Vector3d(0.04, 0.04, 0.04)},
};
// clang-format on

class EveryPresetTest : public ::testing::TestWithParam<PresetFigures> {
 protected:
  std::unique_ptr<SimulatedDevice> makeOpen(std::uint64_t seed) const {
    auto device = makeSimulatedDevice(GetParam().name, seed);
    EXPECT_TRUE(device->open());
    EXPECT_TRUE(device->calibrate());
    return device;
  }
};

TEST_P(EveryPresetTest, SpecificationsNameThePresetAndItsForce) {
  const auto device = makeSimulatedDevice(GetParam().name, 1);
  const auto& spec = device->specifications();
  EXPECT_EQ(spec.model_name, GetParam().name);
  EXPECT_FALSE(spec.manufacturer.empty());
  EXPECT_EQ(spec.max_linear_force_n, GetParam().max_force_n);
  EXPECT_EQ(spec.workspace_radius_m, GetParam().workspace_radius_m);
  EXPECT_NO_THROW(validateSpecifications(spec));
}

TEST_P(EveryPresetTest, ClosedDeviceAnswersNothingAndSwitchesWork) {
  auto device = makeSimulatedDevice(GetParam().name, 1);
  Eigen::Vector3d x;
  bool pressed = true;
  EXPECT_FALSE(device->getPosition(x));
  EXPECT_FALSE(device->setForce(Eigen::Vector3d::Zero()));
  ASSERT_TRUE(device->open());
  EXPECT_TRUE(device->getUserSwitch(0, pressed));
  EXPECT_FALSE(pressed);
  device->setUserSwitch(1, true);
  EXPECT_TRUE(device->getUserSwitch(1, pressed));
  EXPECT_TRUE(pressed);
  EXPECT_FALSE(device->getUserSwitch(SimulatedDriver::kSwitchCount, pressed));
  EXPECT_FALSE(device->getUserSwitch(-1, pressed));
  ASSERT_TRUE(device->setForce(Eigen::Vector3d(0, 0, 1)));
  ASSERT_TRUE(device->close());
  EXPECT_EQ(device->appliedForce_n(), Eigen::Vector3d::Zero());
  EXPECT_FALSE(device->getPosition(x));
}

TEST_P(EveryPresetTest, NonFiniteForceIsRefusedAndZeroed) {
  auto device = makeOpen(7);
  ASSERT_TRUE(device->setForce(Eigen::Vector3d(1.0, 1.0, 1.0)));
  EXPECT_FALSE(device->setForce(Eigen::Vector3d(NAN, 0.0, 0.0)));
  EXPECT_EQ(device->appliedForce_n(), Eigen::Vector3d::Zero());
}

TEST_P(EveryPresetTest, FaultsBehaveAsDeclared) {
  const PresetFigures& figures = GetParam();
  auto device = makeSimulatedDevice(figures.name, 3);
  ASSERT_TRUE(device->open());
  ASSERT_TRUE(device->calibrate());
  Eigen::Vector3d x, v;
  bool pressed = false;
  ASSERT_TRUE(device->setForce(Eigen::Vector3d(0.0, 0.0, 0.2)));

  device->injectFault(DeviceFault::kStopsAnswering);
  EXPECT_FALSE(device->getPosition(x));
  EXPECT_FALSE(device->getLinearVelocity(v));
  EXPECT_FALSE(device->getUserSwitch(0, pressed));
  EXPECT_FALSE(device->setForce(Eigen::Vector3d(0.0, 0.0, 0.2)));
  EXPECT_FALSE(device->calibrate());
  EXPECT_EQ(device->appliedForce_n(), Eigen::Vector3d::Zero());  // watchdog
  device->injectFault(DeviceFault::kNone);
  EXPECT_TRUE(device->getPosition(x));
  EXPECT_TRUE(device->setForce(Eigen::Vector3d(0.0, 0.0, 0.2)));

  device->injectFault(DeviceFault::kNanPosition);
  EXPECT_TRUE(device->getPosition(x));
  EXPECT_TRUE(x.array().isNaN().all());
  EXPECT_TRUE(device->getLinearVelocity(v));
  EXPECT_TRUE(v.array().isNaN().all());
  EXPECT_TRUE(device->setForce(Eigen::Vector3d::Zero()));

  // Frozen while it falls from the centre: over the common 20 ms + 100 ms and the preset's own.
  const FreezeFigures common{figures.freeze.reading_error_m, 0.02, 0.1};
  for (const FreezeFigures& freeze : {common, figures.freeze}) {
    device->injectFault(DeviceFault::kNone);
    device->resetState(device->workspaceCenter_m());
    device->advance(freeze.before_s);
    Eigen::Vector3d before;
    ASSERT_TRUE(device->getPosition(before));
    device->injectFault(DeviceFault::kFrozenPosition);
    device->advance(freeze.while_s);  // falls with zero force
    ASSERT_TRUE(device->getPosition(x));
    EXPECT_EQ(x, before);
    EXPECT_GT((device->truePosition_m() - before).norm(), 0.005);

    device->injectFault(DeviceFault::kNone);
    ASSERT_TRUE(device->getPosition(x));
    EXPECT_LT((x - device->truePosition_m()).norm(), freeze.reading_error_m);
  }
}

TEST_P(EveryPresetTest, UncalibratedUntilForcedHoming) {
  auto device = makeSimulatedDevice(GetParam().name, 3);
  device->setCalibrated(false);
  ASSERT_TRUE(device->open());
  EXPECT_FALSE(device->isCalibrated());
  EXPECT_FALSE(device->calibrate());
  Eigen::Vector3d x;
  ASSERT_TRUE(device->getPosition(x));
  EXPECT_GT((x - device->truePosition_m()).norm(), 0.01);
  EXPECT_TRUE(device->calibrate(true));
  EXPECT_TRUE(device->isCalibrated());
  EXPECT_TRUE(device->calibrate());
  device->advance(0.001);
  ASSERT_TRUE(device->getPosition(x));
  EXPECT_LT((x - device->truePosition_m()).norm(), GetParam().freeze.reading_error_m);
}

TEST_P(EveryPresetTest, TickSourceAdvancesOnePeriodPerTick) {
  auto device = makeSimulatedDevice(GetParam().name, 3);
  ASSERT_TRUE(device->open());
  SimulatedTickSource ticks(*device, 0.001, SimulatedTickSource::Mode::kAsFastAsPossible);
  for (int i = 0; i < 250; ++i) ASSERT_TRUE(ticks.waitForNextTick());
  EXPECT_NEAR(ticks.now_s(), 0.25, 1e-12);
  EXPECT_NEAR(device->time_s(), 0.25, 1e-12);
  EXPECT_THROW(SimulatedTickSource(*device, 0.0, SimulatedTickSource::Mode::kAsFastAsPossible),
               Error);
}

TEST_P(EveryPresetTest, CommandingTheTrueGravityHoldsItStill) {
  const PresetFigures& figures = GetParam();
  auto device = makeOpen(7);
  const Eigen::Vector3d start = device->workspaceCenter_m() + figures.hold.offset_m;
  testing::restWithGravityCancelled(*device, start);
  Eigen::Vector3d first;
  ASSERT_TRUE(device->getPosition(first));
  double max_reading_change = 0.0, max_axis_change = 0.0;
  for (int ms = 0; ms < 1000; ++ms) {
    Eigen::Vector3d measured;
    ASSERT_TRUE(device->getPosition(measured));
    ASSERT_TRUE(device->setForce(device->trueGravity(measured)));
    device->advance(kServo_s);
    max_reading_change = std::max(max_reading_change, (measured - first).norm());
    max_axis_change = std::max(max_axis_change, (measured - first).cwiseAbs().maxCoeff());
  }
  EXPECT_LT((device->truePosition_m() - start).norm(), figures.hold.creep_m);
  EXPECT_LT(max_reading_change, figures.hold.reading_change_m);
  EXPECT_LE(max_axis_change, figures.hold.reading_axis_change_m);
}

TEST_P(EveryPresetTest, ReleasedDeviceSettlesOnTheEndStop) {
  const PresetFigures& figures = GetParam();
  auto device = makeOpen(7);
  device->setForce(Eigen::Vector3d::Zero());
  EXPECT_FALSE(device->endStopHit());
  device->advance(2.0);
  EXPECT_TRUE(device->endStopHit());
  Eigen::Vector3d offset = device->truePosition_m() - device->workspaceCenter_m();
  EXPECT_GT(offset.norm(), figures.fall.min_distance_m);
  EXPECT_LT(offset.norm(), figures.fall.max_distance_m);
  EXPECT_LT(offset.z(), figures.fall.below_z_m);
  EXPECT_LT(device->trueVelocity_m_per_s().norm(), 0.005);  // settled, not sliding round
  // Still there a second later: the stop holds it, it does not creep round the sphere.
  device->advance(1.0);
  EXPECT_TRUE(device->endStopHit());
  EXPECT_LT(device->trueVelocity_m_per_s().norm(), 0.005);
  offset = device->truePosition_m() - device->workspaceCenter_m();
  EXPECT_GT(offset.norm(), figures.workspace_radius_m - 0.002);
  EXPECT_LT(offset.norm(), figures.fall.max_distance_m);
  device->resetState(device->workspaceCenter_m());
  EXPECT_FALSE(device->endStopHit());
}

TEST_P(EveryPresetTest, ResetStateTakesReachablePositionsAndRefusesOthers) {
  auto device = makeSimulatedDevice(GetParam().name, 1);
  EXPECT_THROW(device->resetState(Eigen::Vector3d(0.0, 0.0, 0.3)), Error);
  EXPECT_THROW(device->resetState(Eigen::Vector3d(0.5, 0.0, 0.0)), Error);
  EXPECT_THROW(device->resetState(Eigen::Vector3d(NAN, 0.0, 0.0)), Error);
  const Eigen::Vector3d reachable = device->workspaceCenter_m() + GetParam().reachable_offset_m;
  device->resetState(reachable);
  EXPECT_LT((device->truePosition_m() - reachable).norm(), 1e-12);
}

TEST_P(EveryPresetTest, SameSeedSameTrajectoryBitForBitOtherSeedDiffers) {
  auto runScript = [&](std::uint64_t seed) {
    auto device = makeOpen(seed);
    return testing::scriptedTrajectory(*device, GetParam().script);
  };
  testing::expectSameSeedSameBitsOtherSeedDiffers(runScript(5), runScript(5), runScript(6));
}

TEST_P(EveryPresetTest, ChunkingOfAdvanceDoesNotChangeTheTrajectory) {
  auto a = makeOpen(3);
  auto b = makeOpen(3);
  for (int i = 0; i < 100; ++i) a->advance(0.001);
  b->advance(0.1);
  EXPECT_EQ(a->time_s(), b->time_s());
  EXPECT_TRUE((a->truePosition_m().array() == b->truePosition_m().array()).all());
  EXPECT_NEAR(a->time_s(), 0.1, 1e-12);
}

TEST_P(EveryPresetTest, ServoPathAllocatesNothing) {
  const PresetFigures& figures = GetParam();
  auto device = makeOpen(7);
  device->hand().grab(device->truePosition_m());
  device->hand().moveTo(figures.servo.hand_goal_m, 0.05);
  Eigen::Vector3d x, v;
  bool pressed = false;
  testing::AllocationCounter counter;
  for (int ms = 0; ms < 2000; ++ms) {
    device->getPosition(x);
    device->getLinearVelocity(v);
    device->getUserSwitch(0, pressed);
    device->setForce(Eigen::Vector3d(0.0, 0.0, figures.servo.lift_n) -
                     figures.servo.damping_n_s_per_m * v);
    device->advance(kServo_s);
    if (ms == 1000) device->injectFault(DeviceFault::kFrozenPosition);
  }
  device->injectFault(DeviceFault::kNone);
  device->hand().release();
  for (int ms = 0; ms < 1000; ++ms) {  // onto the end stop
    device->setForce(Eigen::Vector3d(9.0, 0.0, 0.0));
    device->advance(kServo_s);
  }
  EXPECT_TRUE(device->endStopHit());
  // Saturating commands, faults coming and going and the switches, every period.
  for (int i = 0; i < 500; ++i) {
    device->setForce(Eigen::Vector3d(100.0, 0.0, 0.0));
    device->advance(kServo_s);
    device->injectFault(i % 2 == 0 ? DeviceFault::kFrozenPosition : DeviceFault::kNone);
    device->setUserSwitch(1, i % 3 == 0);
    device->getUserSwitch(1, pressed);
    device->getLinearVelocity(v);
  }
  EXPECT_EQ(counter.count(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Presets, EveryPresetTest, ::testing::ValuesIn(kPresets),
                         [](const auto& info) {
                           return std::string(info.param.name).substr(4);  // "omega", ...
                         });

}  // namespace
}  // namespace autograv::sim
