#include "autograv/estimation/steady_state_detector.h"

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

TEST(SteadyStateDetectorTest, RejectsBadParameters) {
  EXPECT_THROW(SteadyStateDetector(0, 1e-4, 0.1, 1e-3), Error);
  EXPECT_THROW(SteadyStateDetector(20, 0.0, 0.1, 1e-3), Error);
  EXPECT_THROW(SteadyStateDetector(20, 1e-4, 0.1, 0.0), Error);
}

}  // namespace
}  // namespace autograv
