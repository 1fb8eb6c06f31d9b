#include "autograv/sim/simulated_driver.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"

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

class EveryPresetTest : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryPresetTest, FaultsBehaveAsDeclared) {
  auto device = makeSimulatedDevice(GetParam(), 3);
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

  device->injectFault(DeviceFault::kNanPosition);
  EXPECT_TRUE(device->getPosition(x));
  EXPECT_TRUE(x.array().isNaN().all());
  EXPECT_TRUE(device->setForce(Eigen::Vector3d::Zero()));

  device->injectFault(DeviceFault::kNone);
  device->advance(0.02);
  Eigen::Vector3d before;
  ASSERT_TRUE(device->getPosition(before));
  device->injectFault(DeviceFault::kFrozenPosition);
  device->advance(0.1);  // falls with zero force
  ASSERT_TRUE(device->getPosition(x));
  EXPECT_EQ(x, before);
  EXPECT_GT((device->truePosition_m() - before).norm(), 0.005);

  device->injectFault(DeviceFault::kNone);
  ASSERT_TRUE(device->getPosition(x));
  EXPECT_LT((x - device->truePosition_m()).norm(), 1e-4);
}

TEST_P(EveryPresetTest, UncalibratedUntilForcedHoming) {
  auto device = makeSimulatedDevice(GetParam(), 3);
  device->setCalibrated(false);
  ASSERT_TRUE(device->open());
  EXPECT_FALSE(device->calibrate());
  Eigen::Vector3d x;
  ASSERT_TRUE(device->getPosition(x));
  EXPECT_GT((x - device->truePosition_m()).norm(), 0.01);
  EXPECT_TRUE(device->calibrate(true));
  EXPECT_TRUE(device->isCalibrated());
  device->advance(0.001);
  ASSERT_TRUE(device->getPosition(x));
  EXPECT_LT((x - device->truePosition_m()).norm(), 1e-4);
}

TEST_P(EveryPresetTest, TickSourceAdvancesOnePeriodPerTick) {
  auto device = makeSimulatedDevice(GetParam(), 3);
  ASSERT_TRUE(device->open());
  SimulatedTickSource ticks(*device, 0.001, SimulatedTickSource::Mode::kAsFastAsPossible);
  for (int i = 0; i < 250; ++i) ASSERT_TRUE(ticks.waitForNextTick());
  EXPECT_NEAR(ticks.now_s(), 0.25, 1e-12);
  EXPECT_NEAR(device->time_s(), 0.25, 1e-12);
  EXPECT_THROW(SimulatedTickSource(*device, 0.0, SimulatedTickSource::Mode::kAsFastAsPossible),
               Error);
}

TEST_P(EveryPresetTest, ReleasedDeviceSettlesOnTheEndStop) {
  auto device = makeSimulatedDevice(GetParam(), 3);
  ASSERT_TRUE(device->open());
  device->advance(3.0);
  EXPECT_TRUE(device->endStopHit());
  EXPECT_LT(device->trueVelocity_m_per_s().norm(), 0.005);  // settled, not sliding round
  const double radius = device->specifications().workspace_radius_m;
  const double distance = (device->truePosition_m() - device->workspaceCenter_m()).norm();
  EXPECT_GT(distance, radius - 0.002);
  // sim:omega and sim:omni stop on the workspace sphere; sim:falcon's arms stop in joint space,
  // beyond the sphere inscribed in its cubic workspace.
  if (GetParam() != "sim:falcon") {
    EXPECT_LT(distance, radius + 0.002);
  }
}

TEST_P(EveryPresetTest, GettersAndAdvanceAllocateNothing) {
  auto device = makeSimulatedDevice(GetParam(), 3);
  ASSERT_TRUE(device->open());
  Eigen::Vector3d x, v;
  bool pressed = false;
  testing::AllocationCounter counter;
  for (int i = 0; i < 500; ++i) {
    device->getPosition(x);
    device->getLinearVelocity(v);
    device->getUserSwitch(1, pressed);
    device->setForce(Eigen::Vector3d(0.0, 0.0, 0.1) - 0.1 * v);
    device->setForce(Eigen::Vector3d(100.0, 0.0, 0.0));  // saturates
    device->advance(0.001);
    device->injectFault(i % 2 == 0 ? DeviceFault::kFrozenPosition : DeviceFault::kNone);
    device->setUserSwitch(1, i % 3 == 0);
  }
  EXPECT_EQ(counter.count(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Presets, EveryPresetTest,
                         ::testing::Values("sim:omega", "sim:omni", "sim:falcon"),
                         [](const auto& info) {
                           return std::string(info.param).substr(4);  // "omega", "omni", ...
                         });

}  // namespace
}  // namespace autograv::sim
