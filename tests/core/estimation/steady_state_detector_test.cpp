#include "core/estimation/steady_state_detector.h"

#include <cmath>

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

const Eigen::Vector3d kStill = Eigen::Vector3d::Zero();
const Eigen::Vector3d kSlow(0.0, 0.0, 0.5e-4);  // 0.05 mm/s, under eps_S = 0.1 mm/s
const Eigen::Vector3d kFast(0.0, 0.0, 2e-4);    // 0.2 mm/s

TEST(SteadyStateDetectorTest, NeedsNConsecutiveSlowSamples) {
  SteadyStateDetector detector(20, 1e-4, 0.0, 1e-3);
  for (int k = 0; k < 19; ++k) EXPECT_FALSE(detector.update(Eigen::Vector3d::Zero(), kSlow));
  EXPECT_FALSE(detector.update(Eigen::Vector3d::Zero(), kFast));  // breaks the run
  for (int k = 0; k < 19; ++k) EXPECT_FALSE(detector.update(Eigen::Vector3d::Zero(), kStill));
  EXPECT_TRUE(detector.update(Eigen::Vector3d::Zero(), kStill));
  EXPECT_TRUE(detector.settled());
}

TEST(SteadyStateDetectorTest, HonoursTheMinimumDuration) {
  SteadyStateDetector detector(20, 1e-4, 0.1, 1e-3);  // the paper's 100 ms lower bound
  int ticks = 0;
  while (!detector.update(Eigen::Vector3d::Zero(), kStill)) ++ticks;
  EXPECT_EQ(ticks + 1, 100);
  EXPECT_NEAR(detector.elapsed_s(), 0.1, 1e-12);
}

TEST(SteadyStateDetectorTest, AveragesThePositionsOfTheSettledWindow) {
  SteadyStateDetector detector(4, 1e-4, 0.0, 1e-3);
  detector.update(Eigen::Vector3d(9.0, 9.0, 9.0), kFast);  // not part of the window
  detector.update(Eigen::Vector3d(1.0, 0.0, 0.0), kStill);
  detector.update(Eigen::Vector3d(2.0, 0.0, 0.0), kStill);
  detector.update(Eigen::Vector3d(3.0, 0.0, 0.0), kStill);
  ASSERT_TRUE(detector.update(Eigen::Vector3d(4.0, 0.0, 0.0), kStill));
  EXPECT_TRUE(detector.settledPosition_m().isApprox(Eigen::Vector3d(2.5, 0.0, 0.0)));
  detector.reset();
  EXPECT_FALSE(detector.settled());
  EXPECT_EQ(detector.elapsed_s(), 0.0);
}

TEST(SteadyStateDetectorTest, NonFiniteVelocityIsNeverSlow) {
  SteadyStateDetector detector(1, 1e-4, 0.0, 1e-3);
  EXPECT_FALSE(detector.update(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(NAN)));
}

// 100-tick windows, two agreeing pairs, eps_S = 0.1 mm/s: window means may move 10 um.
SteadyStateDetector windowDetector() {
  return SteadyStateDetector::windowMeans(100, 2, 1e-4, 0.0, 1e-3);
}

TEST(SteadyStateDetectorTest, WindowMeansSettleOnALimitCycleAroundAFixedPoint) {
  // A 1 mm, 20 Hz oscillation (a dithered or limit-cycling end-effector) about (1, 2, 3) mm: its
  // velocity is never slow, but its mean is still.
  SteadyStateDetector detector = windowDetector();
  const Eigen::Vector3d centre(1e-3, 2e-3, 3e-3);
  int ticks = 0;
  for (; ticks < 10000 && !detector.settled(); ++ticks) {
    const double angle = 2.0 * M_PI * 20.0 * ticks * 1e-3;
    const Eigen::Vector3d position = centre + 1e-3 * Eigen::Vector3d(std::sin(angle), 0, 0);
    const Eigen::Vector3d velocity(2.0 * M_PI * 20.0 * 1e-3 * std::cos(angle), 0, 0);
    detector.update(position, velocity);
  }
  EXPECT_EQ(ticks, 300);  // three windows: two agreeing pairs
  EXPECT_LT((detector.settledPosition_m() - centre).norm(), 1e-9);
  EXPECT_DOUBLE_EQ(detector.progress(), 1.0);
}

TEST(SteadyStateDetectorTest, WindowMeansDoNotSettleWhileTheMeanCreeps) {
  SteadyStateDetector detector = windowDetector();
  for (int tick = 0; tick < 5000; ++tick) {
    // 0.2 mm/s drift: 20 um per window, twice the threshold.
    detector.update(Eigen::Vector3d(0.0, 0.0, 2e-4 * tick * 1e-3), kSlow);
  }
  EXPECT_FALSE(detector.settled());
}

TEST(SteadyStateDetectorTest, ForParametersFollowsTheMethod) {
  const EstimationParameters paper = EstimationParameters::paper();
  EXPECT_EQ(SteadyStateDetector::forParameters(paper).windowTicks(), 0);
  const EstimationParameters dither = EstimationParameters{};
  EXPECT_EQ(SteadyStateDetector::forParameters(dither).windowTicks(), 50);  // 1 period at 20 Hz
}

TEST(SteadyStateDetectorTest, RejectsBadParameters) {
  EXPECT_THROW(SteadyStateDetector(0, 1e-4, 0.1, 1e-3), Error);
  EXPECT_THROW(SteadyStateDetector(20, 0.0, 0.1, 1e-3), Error);
  EXPECT_THROW(SteadyStateDetector(20, 1e-4, 0.1, 0.0), Error);
  EXPECT_THROW(SteadyStateDetector::windowMeans(1, 2, 1e-4, 0.0, 1e-3), Error);
}

// --- Servo time, not ticks -----------------------------------------------------------------------

TEST(SteadyStateDetectorTest, ExactIntervalsAreTheTickCountBitForBit) {
  // An exact loop passes its period as the interval: the same arithmetic as counting ticks.
  SteadyStateDetector counted = windowDetector();
  SteadyStateDetector timed = windowDetector();
  for (int tick = 0; tick < 2000; ++tick) {
    const double t = tick * 1e-3;
    const Eigen::Vector3d position(std::sin(2.0 * M_PI * 10.0 * t) * 1e-3,
                                   1e-3 * std::exp(-t / 0.1), 0.0);  // settling onto a fixed point
    const bool a = counted.update(position, kFast);
    const bool b = timed.update(position, kFast, 1e-3);
    ASSERT_EQ(a, b) << tick;
    ASSERT_EQ(counted.elapsed_s(), timed.elapsed_s());
    if (a) break;
  }
  ASSERT_TRUE(timed.settled());
  EXPECT_EQ(counted.settledPosition_m(), timed.settledPosition_m());
}

TEST(SteadyStateDetectorTest, WindowMeansAreTimeWeightedOverWholeWindowsInTime) {
  // A 10 Hz oscillation about 1 mm sampled by a loop that is slow (1.8 ms) on the upper half-wave
  // and fast (0.2 ms) on the lower one: nine samples in ten fall on the lower half, so a mean of
  // samples sits far below the centre; the mean over time does not.
  SteadyStateDetector detector = windowDetector();  // 100 ms windows: one period each
  const double centre_m = 1e-3, amplitude_m = 1e-3;
  double t = 0.0, interval_s = 1e-3, sample_sum = 0.0;
  int samples = 0;
  while (!detector.update(Eigen::Vector3d(centre_m + amplitude_m * std::sin(20.0 * M_PI * t), 0, 0),
                          kFast, interval_s)) {
    sample_sum += centre_m + amplitude_m * std::sin(20.0 * M_PI * t);
    ++samples;
    interval_s = std::sin(20.0 * M_PI * t) > 0.0 ? 1.8e-3 : 0.2e-3;
    t += interval_s;
    ASSERT_LT(t, 2.0);
  }
  EXPECT_LT(sample_sum / samples, centre_m - 0.4 * amplitude_m);  // what counting ticks reads
  EXPECT_NEAR(detector.settledPosition_m().x(), centre_m, 0.02 * amplitude_m);
  // Three windows of 100 ms of servo time, however many samples they took.
  EXPECT_NEAR(detector.elapsed_s(), 0.3, 2e-3);
}

TEST(SteadyStateDetectorTest, AWindowEndsInsideAnIntervalThatStraddlesIt) {
  // Intervals of 3 ms against 100 ms windows: each window ends a third of the way into a sample's
  // interval, which is split between the two windows.
  SteadyStateDetector detector = windowDetector();
  int samples = 0;
  while (!detector.update(Eigen::Vector3d(2e-3, 0.0, 0.0), kFast, 3e-3)) ASSERT_LT(++samples, 500);
  EXPECT_NEAR(detector.settledPosition_m().x(), 2e-3, 1e-15);
  EXPECT_NEAR(detector.elapsed_s(), 0.3, 3e-3);  // settled on the sample that crossed 300 ms
  EXPECT_GE(detector.elapsed_s(), 0.3 - 1e-9);
}

TEST(SteadyStateDetectorTest, AStallSpoilsItsWindowInsteadOfPassingForASteadyState) {
  // The loop stalls for 30 ms (over a fifth of a 100 ms window) in the second window: that window
  // is not trusted, nor paired with the next one; the steady state comes two windows later.
  SteadyStateDetector detector = windowDetector();
  double t = 0.0;
  bool stalled = false;
  while (true) {
    double interval_s = 1e-3;
    if (!stalled && t > 0.15) {
      interval_s = 0.03;
      stalled = true;
    }
    t += interval_s;
    if (detector.update(Eigen::Vector3d::Zero(), kFast, interval_s)) break;
    ASSERT_LT(t, 1.0);
  }
  EXPECT_EQ(detector.spoiltWindows(), 1);
  EXPECT_NEAR(detector.elapsed_s(), 0.5, 1.5e-3);  // without the stall: 0.3 s
}

TEST(SteadyStateDetectorTest, LateTicksOfAFewMillisecondsDoNotSpoilAWindow) {
  SteadyStateDetector detector = windowDetector();
  for (int k = 0; !detector.update(Eigen::Vector3d::Zero(), kFast, k % 10 == 0 ? 5e-3 : 1e-3);
       ++k) {
    ASSERT_LT(k, 1000);
  }
  EXPECT_EQ(detector.spoiltWindows(), 0);
  EXPECT_NEAR(detector.elapsed_s(), 0.3, 5e-3);
}

TEST(SteadyStateDetectorTest, SlowSamplesMustLastNPeriodsOfServoTime) {
  // n_S = 20 at a nominal 1 ms: a 4 kHz loop needs 80 slow samples, 20 ms of them.
  SteadyStateDetector detector(20, 1e-4, 0.0, 1e-3);
  int samples = 1;
  while (!detector.update(Eigen::Vector3d::Zero(), kStill, 0.25e-3)) ++samples;
  EXPECT_EQ(samples, 80);
  EXPECT_NEAR(detector.elapsed_s(), 0.02, 1e-12);
}

}  // namespace
}  // namespace autograv
