// The frozen-driver check alone: a push that swings both ways over bit-identical readings is a
// frozen driver once the window has passed, a still hand or a stop is not, and the encoder
// resolution is learned from the readings.

#include "core/compensation/frozen_driver_detector.h"

#include <cmath>

#include <gtest/gtest.h>

#include "allocation_counter.h"

namespace autograv {
namespace {

constexpr double kPeriod_s = 1e-3;
constexpr double kTwoPi = 6.283185307179586;

// The push of a 5 Hz swing of `amplitude_n` along x at tick `k`.
Eigen::Vector3d swingingPush(int k, double amplitude_n) {
  return Eigen::Vector3d(amplitude_n * std::sin(kTwoPi * 5.0 * k * kPeriod_s), 0.0, 0.0);
}

// The first tick at which the detector reports a frozen driver over `ticks` ticks at one
// reading, or -1.
template <typename Push>
int firstFrozenTick(FrozenDriverDetector& detector, int ticks, Push push) {
  const Eigen::Vector3d still_m(0.01, 0.02, 0.03);
  for (int k = 0; k < ticks; ++k) {
    if (detector.frozen(still_m, push(k), kPeriod_s)) return k;
  }
  return -1;
}

TEST(FrozenDriverDetectorTest, APushSwingingBothWaysIsCaughtAfterTheWindow) {
  FrozenDriverDetector detector{CompensationOptions{}};
  const int tick = firstFrozenTick(detector, 1000, [](int k) { return swingingPush(k, 1.0); });
  EXPECT_GE(tick, 100);  // frozen_window_s
  EXPECT_LE(tick, 300);
}

TEST(FrozenDriverDetectorTest, AStillHandOrAStopIsNeverAFrozenDriver) {
  FrozenDriverDetector steady{CompensationOptions{}};
  EXPECT_EQ(firstFrozenTick(steady, 2000, [](int) { return Eigen::Vector3d(0.0, 0.0, 1.5); }), -1);
  // A push that only changes in size, into a stop.
  FrozenDriverDetector into_stop{CompensationOptions{}};
  EXPECT_EQ(firstFrozenTick(
                into_stop, 2000,
                [](int k) { return Eigen::Vector3d(0.0, 0.0, -1.0 - swingingPush(k, 0.8).x()); }),
            -1);
}

TEST(FrozenDriverDetectorTest, AMovingReadingOrAZeroWindowDisarmsIt) {
  CompensationOptions disabled;
  disabled.frozen_window_s = 0.0;
  FrozenDriverDetector off{disabled};
  EXPECT_EQ(firstFrozenTick(off, 1000, [](int k) { return swingingPush(k, 1.0); }), -1);

  FrozenDriverDetector moving{CompensationOptions{}};
  for (int k = 0; k < 1000; ++k) {
    const Eigen::Vector3d position_m(1e-5 * (k % 2), 0.0, 0.0);
    EXPECT_FALSE(moving.frozen(position_m, swingingPush(k, 1.0), kPeriod_s)) << k;
  }
}

TEST(FrozenDriverDetectorTest, ACaughtDriverStaysCaughtUntilTheRunIsRestarted) {
  FrozenDriverDetector detector{CompensationOptions{}};
  ASSERT_GE(firstFrozenTick(detector, 1000, [](int k) { return swingingPush(k, 1.0); }), 0);
  EXPECT_TRUE(detector.frozen(Eigen::Vector3d(0.01, 0.02, 0.03), Eigen::Vector3d::Zero(), 0.0));
  detector.restartRun();
  EXPECT_FALSE(detector.frozen(Eigen::Vector3d(0.01, 0.02, 0.03), Eigen::Vector3d::Zero(), 0.0));
}

TEST(FrozenDriverDetectorTest, LearnsTheSmallestStepBetweenReadings) {
  FrozenDriverDetector detector{CompensationOptions{}};
  EXPECT_DOUBLE_EQ(detector.resolution_m(), 1e-4);  // coarser than any device until a step
  EXPECT_FALSE(detector.learnResolution(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(detector.learnResolution(Eigen::Vector3d(3e-5, 0.0, 0.0)));
  EXPECT_DOUBLE_EQ(detector.resolution_m(), 3e-5);
  EXPECT_FALSE(detector.learnResolution(Eigen::Vector3d(3e-5, 5e-5, 0.0)));  // coarser
  EXPECT_FALSE(detector.learnResolution(Eigen::Vector3d(3e-5, 5e-5, 0.0)));  // no step
  detector.reset();  // forgets the previous reading, keeps the resolution
  EXPECT_FALSE(detector.learnResolution(Eigen::Vector3d(1.0, 1.0, 1.0)));
  EXPECT_DOUBLE_EQ(detector.resolution_m(), 3e-5);
}

TEST(FrozenDriverDetectorTest, AllocatesNothing) {
  FrozenDriverDetector detector{CompensationOptions{}};
  testing::AllocationCounter counter;
  for (int k = 0; k < 2000; ++k) {
    const Eigen::Vector3d position_m(k < 1000 ? 1e-5 * k : 0.0, 0.0, 0.0);
    detector.learnResolution(position_m);
    detector.frozen(position_m, swingingPush(k, 1.0), kPeriod_s);
  }
  EXPECT_EQ(counter.count(), 0u);
}

}  // namespace
}  // namespace autograv
