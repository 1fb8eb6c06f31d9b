// Deadline statistics of the demo's servo loop, fed with made-up times (no clock involved).
#include "servo_timing.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "lock_free.h"

namespace autograv::demo {
namespace {

constexpr std::int64_t kPeriodNs = 1'000'000;  // 1 ms

TEST(ServoTimingTest, OnTimeLoopHasNoMissesAndTheNominalRate) {
  ServoTiming timing(kPeriodNs);
  for (std::int64_t k = 0; k <= 1000; ++k) timing.record(k * kPeriodNs, k * kPeriodNs + 20'000);
  const ServoTiming::Report r = timing.report();
  EXPECT_EQ(r.ticks, 1001);
  EXPECT_NEAR(r.rate_hz, 1000.0 * 1000.0 / (1000.0 + 0.02), 1e-6);
  EXPECT_EQ(r.missed_ticks, 0);
  EXPECT_DOUBLE_EQ(r.worst_burst_ms, 0.0);
  EXPECT_NEAR(r.max_lateness_ms, 0.02, 1e-12);
  EXPECT_NEAR(r.mean_lateness_ms, 0.02, 1e-12);
  EXPECT_NEAR(r.max_gap_ms, 1.0, 1e-12);
}

TEST(ServoTimingTest, AStallMakesOneBurstUntilTheLoopCatchesUp) {
  ServoTiming timing(kPeriodNs);
  // Ticks 0-9 on time; tick 10 starts 4.5 ms late, 11-14 run back to back behind it, tick 15 is
  // on time again.
  for (std::int64_t k = 0; k < 10; ++k) timing.record(k * kPeriodNs, k * kPeriodNs);
  const std::int64_t stall_end = 10 * kPeriodNs + 4'500'000;
  for (std::int64_t k = 10; k < 15; ++k) {
    timing.record(k * kPeriodNs, stall_end + (k - 10) * 10'000);
  }
  for (std::int64_t k = 15; k < 20; ++k) timing.record(k * kPeriodNs, k * kPeriodNs + 1000);
  const ServoTiming::Report r = timing.report();
  // Lateness 4.5, 3.51, 2.52, 1.53, 0.54 ms: the first four are missed (more than one period).
  EXPECT_EQ(r.missed_ticks, 4);
  EXPECT_NEAR(r.max_lateness_ms, 4.5, 1e-12);
  // From tick 10's deadline to tick 14's start, when it was within one period again.
  EXPECT_NEAR(r.worst_burst_ms, 4.54, 1e-9);
  EXPECT_NEAR(r.max_gap_ms, 5.5, 1e-12);
}

TEST(ServoTimingTest, ABurstStillOpenAtTheEndCounts) {
  ServoTiming timing(kPeriodNs);
  timing.record(0, 0);
  timing.record(kPeriodNs, kPeriodNs + 3'000'000);
  EXPECT_NEAR(timing.report().worst_burst_ms, 3.0, 1e-12);
  EXPECT_EQ(timing.report().missed_ticks, 1);
}

TEST(ServoTimingTest, EmptyReportIsZero) {
  const ServoTiming::Report r = ServoTiming(kPeriodNs).report();
  EXPECT_EQ(r.ticks, 0);
  EXPECT_DOUBLE_EQ(r.rate_hz, 0.0);
}

TEST(LockFreeTest, QueueKeepsOrderAndRefusesWhenFull) {
  SpscQueue<int, 4> queue;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(queue.push(i));
  EXPECT_FALSE(queue.push(99));
  int value = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(queue.pop(value));
    EXPECT_EQ(value, i);
  }
  EXPECT_FALSE(queue.pop(value));
  EXPECT_TRUE(queue.push(7));  // wraps around
  ASSERT_TRUE(queue.pop(value));
  EXPECT_EQ(value, 7);
}

TEST(LockFreeTest, TripleBufferGivesTheLatestValue) {
  TripleBuffer<int> buffer;
  EXPECT_EQ(buffer.read(), 0);
  buffer.writeSlot() = 1;
  buffer.publish();
  buffer.writeSlot() = 2;
  buffer.publish();
  EXPECT_EQ(buffer.read(), 2);
  EXPECT_EQ(buffer.read(), 2);  // nothing new: same value
  buffer.writeSlot() = 3;
  buffer.publish();
  EXPECT_EQ(buffer.read(), 3);
}

TEST(ServoTimingTest, RunPacedTicksOnItsDeadlinesUntilStopped) {
  // Behaviour, not speed: every tick is recorded with its work, and setting the flag ends the loop.
  std::atomic<bool> stop{false};
  ServoTiming timing(1'000'000);
  int ticks = 0;
  runPaced(1'000'000, stop, timing, [&] {
    if (++ticks == 5) stop.store(true);
  });
  EXPECT_EQ(ticks, 5);
  const ServoTiming::Report report = timing.report();
  EXPECT_EQ(report.ticks, 5);
  EXPECT_GE(report.elapsed_s, 0.0035);  // four periods between the first and the last start
}

TEST(ServoTimingTest, ReferenceLoopRunsUntilStoppedAndReportsItsTicks) {
  ReferenceLoop reference(1'000'000);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  const ServoTiming::Report report = reference.stop();
  EXPECT_GT(report.ticks, 0);
  EXPECT_EQ(reference.stop().ticks, report.ticks);  // stopped for good
  EXPECT_LT(report.max_tick_ms, 1.0);               // an empty tick
}

}  // namespace
}  // namespace autograv::demo
