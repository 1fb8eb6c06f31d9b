#include "autograv/estimation/steady_state_detector.h"

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

}  // namespace
}  // namespace autograv
