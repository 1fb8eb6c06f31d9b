#include "autograv/device/wall_clock_tick_source.h"

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

TEST(WallClockTickSourceTest, RefusesPeriodsAServoLoopCannotUse) {
  EXPECT_THROW(WallClockTickSource(0.0), Error);
  EXPECT_THROW(WallClockTickSource(-1e-3), Error);
  EXPECT_THROW(WallClockTickSource(0.5), Error);
  EXPECT_DOUBLE_EQ(WallClockTickSource(1e-3).period_s(), 1e-3);
}

TEST(WallClockTickSourceTest, TicksAreAbsoluteDeadlinesSoTenTicksTakeAtLeastTenPeriods) {
  WallClockTickSource ticks(1e-3);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(ticks.waitForNextTick());
  // A lower bound only (sleep_until never returns early); no upper bound: CI machines are slow.
  EXPECT_GE(ticks.now_s(), 10 * 1e-3);
}

}  // namespace
}  // namespace autograv
