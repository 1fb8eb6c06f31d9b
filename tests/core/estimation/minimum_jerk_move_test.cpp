#include "core/estimation/minimum_jerk_move.h"

#include <gtest/gtest.h>

namespace autograv {
namespace {

TEST(MinimumJerkMoveTest, StartsAndEndsAtRest) {
  MinimumJerkMove move;
  const Eigen::Vector3d from(0.0, 0.0, 0.0), to(0.02, -0.01, 0.03);
  move.start(from, to, 0.5);
  Eigen::Vector3d p, v, a;
  move.sample(0.0, p, v, a);
  EXPECT_TRUE(p.isApprox(from));
  EXPECT_LT(v.norm() + a.norm(), 1e-12);
  move.sample(0.25, p, v, a);
  EXPECT_TRUE(p.isApprox(0.5 * (from + to)));                      // symmetric profile
  EXPECT_NEAR(v.norm(), 1.875 * (to - from).norm() / 0.5, 1e-12);  // peak speed 15/8 d/T
  move.sample(0.6, p, v, a);
  EXPECT_TRUE(p.isApprox(to));
  EXPECT_LT(v.norm() + a.norm(), 1e-12);
}

TEST(MinimumJerkMoveTest, DurationKeepsPeakAccelerationUnderTheLimit) {
  const double d = 0.03, limit = 0.5;
  const double duration = MinimumJerkMove::durationFor(d, limit, 0.1);
  MinimumJerkMove move;
  move.start(Eigen::Vector3d::Zero(), Eigen::Vector3d(d, 0, 0), duration);
  double peak = 0.0;
  for (int k = 0; k <= 1000; ++k) {
    Eigen::Vector3d p, v, a;
    move.sample(duration * k / 1000.0, p, v, a);
    peak = std::max(peak, a.norm());
  }
  EXPECT_NEAR(peak, limit, 1e-3);
  EXPECT_EQ(MinimumJerkMove::durationFor(1e-6, limit, 0.25), 0.25);
}

}  // namespace
}  // namespace autograv
