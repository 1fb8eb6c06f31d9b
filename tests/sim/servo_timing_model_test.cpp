// The simulated servo loops of --servo-timing: exact ticks exactly, desktop is late as a desktop
// Linux thread is, free runs at 2-8 kHz; each is reproducible from its seed and reports itself
// truthfully through ServoLoopStats.

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/device/servo_loop_stats.h"
#include "autograv/error.h"
#include "autograv/sim/servo_timing_model.h"

namespace autograv::sim {
namespace {

std::vector<double> draw(ServoTimingModel& model, double duration_s) {
  std::vector<double> intervals;
  while (model.now_s() < duration_s) intervals.push_back(model.nextInterval_s());
  return intervals;
}

TEST(ServoTimingModelTest, NamesRoundTripAndUnknownOnesAreRefused) {
  for (const auto& name : servoTimingNames()) EXPECT_EQ(toString(parseServoTiming(name)), name);
  EXPECT_THROW(parseServoTiming("fast"), Error);
  EXPECT_THROW(ServoTimingModel(ServoTiming::kExact, 1, 0.0), Error);
}

TEST(ServoTimingModelTest, ExactTicksEveryPeriodExactly) {
  ServoTimingModel model(ServoTiming::kExact, 3, 1e-3);
  EXPECT_EQ(model.lastInterval_s(), 1e-3);
  for (int k = 1; k <= 5000; ++k) {
    ASSERT_EQ(model.nextInterval_s(), 1e-3);  // bit for bit: the published figures' loop
    ASSERT_EQ(model.lastLateness_s(), 0.0);
  }
  EXPECT_EQ(model.now_s(), 5000 * 1e-3);
}

TEST(ServoTimingModelTest, TheSameSeedGivesTheSameTicks) {
  for (const ServoTiming timing :
       {ServoTiming::kDesktop, ServoTiming::kRealTime, ServoTiming::kFree}) {
    ServoTimingModel a(timing, 2), b(timing, 2), c(timing, 3);
    const std::vector<double> first = draw(a, 5.0);
    EXPECT_EQ(first, draw(b, 5.0)) << toString(timing);
    EXPECT_NE(first, draw(c, 5.0)) << toString(timing);
  }
}

// Two minutes of a loop paced at 1 kHz on absolute deadlines, each tick late by 0 to
// `every_tick_s` (uniform), `rare_fraction` of them by 3-5 ms, a 20 ms stall every 10-30 s.
void expectLateAsAPacedThread(ServoTiming timing, double every_tick_s, double rare_fraction) {
  SCOPED_TRACE(toString(timing));
  ServoTimingModel model(timing, 1);
  ServoLoopStats stats;
  int rare = 0, stalls = 0;
  std::int64_t ticks = 0;
  double latest_stall_s = 0.0, shortest_spacing_s = 1e9;
  while (model.now_s() < 120.0) {
    const double interval_s = model.nextInterval_s();
    ++ticks;
    stats.record(interval_s, model.lastLateness_s());
    ASSERT_GE(interval_s, ServoTimingModel::kMinInterval_s - 1e-12);
    const double lateness_s = model.lastLateness_s();
    if (lateness_s > 2.9e-3 && lateness_s < 5.1e-3 && interval_s > 2e-3) ++rare;
    if (interval_s > 15e-3) {
      ++stalls;
      if (latest_stall_s > 0.0) {
        shortest_spacing_s = std::min(shortest_spacing_s, model.now_s() - latest_stall_s);
      }
      latest_stall_s = model.now_s();
    }
  }
  // Paced at 1 kHz on absolute deadlines: as many ticks as milliseconds, late or not.
  EXPECT_NEAR(static_cast<double>(ticks), 120000.0, 30.0);
  const ServoLoopStats::Summary summary = stats.summary();
  EXPECT_NEAR(summary.rate_hz, 1000.0, 1.0);
  EXPECT_NEAR(summary.lateness_p50_ms, 0.5 * every_tick_s * 1e3, 0.05 * every_tick_s * 1e3);
  EXPECT_GT(summary.lateness_p99_ms, 0.95 * every_tick_s * 1e3);
  const double rare_tolerance = 3.0 * std::sqrt(rare_fraction / static_cast<double>(ticks));
  EXPECT_NEAR(static_cast<double>(rare) / static_cast<double>(ticks), rare_fraction,
              rare_tolerance);
  // A 20 ms stall every 10-30 s: 4 to 12 in two minutes, never closer than 10 s.
  EXPECT_GE(stalls, 4);
  EXPECT_LE(stalls, 12);
  EXPECT_GE(shortest_spacing_s, ServoTimingModel::kStallSpacingMin_s - 0.1);
  EXPECT_NEAR(summary.longest_gap_ms, 21.0, 1.0);
  EXPECT_EQ(summary.gaps_over_10ms, stalls);
}

TEST(ServoTimingModelTest, DesktopIsLateAsADesktopThreadAndStallsNowAndThen) {
  expectLateAsAPacedThread(ServoTiming::kDesktop, ServoTimingModel::kLateness_s,
                           ServoTimingModel::kRareLateFraction);
}

// At real-time priority the same thread is late by a fifth as much, and rarely very late; the
// stalls (a driver, the machine's own hiccups) stay.
TEST(ServoTimingModelTest, RealTimeIsLateByAFifthOfDesktopAndStallsAsOften) {
  expectLateAsAPacedThread(ServoTiming::kRealTime, ServoTimingModel::kRealTimeLateness_s,
                           ServoTimingModel::kRealTimeRareLateFraction);
  EXPECT_DOUBLE_EQ(ServoTimingModel::kRealTimeLateness_s, 0.2 * ServoTimingModel::kLateness_s);
}

TEST(ServoTimingModelTest, FreeRunsAt2To8KilohertzAndWandersOverTheBand) {
  ServoTimingModel model(ServoTiming::kFree, 1);
  double lowest_hz = 1e9, highest_hz = 0.0;
  double window_start_s = 0.0;
  int window_ticks = 0;
  while (model.now_s() < 120.0) {
    const double interval_s = model.nextInterval_s();
    ASSERT_GE(interval_s, 0.85 / ServoTimingModel::kFreeMaxRate_hz);
    ASSERT_LE(interval_s, 1.15 / ServoTimingModel::kFreeMinRate_hz);
    ++window_ticks;
    if (model.now_s() - window_start_s >= 0.5) {  // rate over half a second
      const double rate_hz = window_ticks / (model.now_s() - window_start_s);
      lowest_hz = std::min(lowest_hz, rate_hz);
      highest_hz = std::max(highest_hz, rate_hz);
      window_start_s = model.now_s();
      window_ticks = 0;
    }
  }
  EXPECT_GE(lowest_hz, 0.95 * ServoTimingModel::kFreeMinRate_hz);
  EXPECT_LE(highest_hz, 1.05 * ServoTimingModel::kFreeMaxRate_hz);
  EXPECT_LT(lowest_hz, 3000.0);  // it does wander: not one rate in disguise
  EXPECT_GT(highest_hz, 6000.0);
}

TEST(ServoTimingModelTest, DrawingAndRecordingTicksAllocateNothing) {
  ServoTimingModel model(ServoTiming::kDesktop, 1);
  ServoLoopStats stats;
  testing::AllocationCounter counter;
  for (int k = 0; k < 100000; ++k) {
    const double interval_s = model.nextInterval_s();
    stats.record(interval_s, model.lastLateness_s());
  }
  EXPECT_EQ(counter.count(), 0u);
}

TEST(ServoLoopStatsTest, PercentilesAndLongestGapOfKnownIntervals) {
  ServoLoopStats stats;
  for (int k = 0; k < 990; ++k) stats.record(1e-3, 0.0);
  for (int k = 0; k < 9; ++k) stats.record(4e-3, 3e-3);
  stats.record(0.2, 0.199);  // beyond the histogram: kept exactly as the longest gap
  const ServoLoopStats::Summary summary = stats.summary();
  EXPECT_EQ(summary.ticks, 1000);
  EXPECT_NEAR(summary.duration_s, 0.99 + 0.036 + 0.2, 1e-9);
  EXPECT_NEAR(summary.rate_hz, 1000.0 / 1.226, 1e-6);
  EXPECT_NEAR(summary.interval_p50_ms, 1.0, 2.1 * ServoLoopStats::kBin_s * 1e3);
  EXPECT_NEAR(summary.interval_p99_ms, 1.0, 2.1 * ServoLoopStats::kBin_s * 1e3);
  EXPECT_NEAR(summary.lateness_p50_ms, 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(summary.longest_gap_ms, 200.0);
  EXPECT_DOUBLE_EQ(summary.max_lateness_ms, 199.0);
  EXPECT_EQ(summary.gaps_over_10ms, 1);
  stats.clear();
  EXPECT_EQ(stats.summary().ticks, 0);
}

}  // namespace
}  // namespace autograv::sim
