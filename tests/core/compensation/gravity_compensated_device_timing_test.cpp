// Ramps, map fades and the frozen-driver window last the same number of seconds whatever the
// servo loop's rate: steady at 1, 4 and 10 kHz, jittery (periods drawn from 0.1 to 2 ms), and
// the simulated loops of --servo-timing desktop (late ticks, catch-up bursts) and free (2-8 kHz).
// A scripted clock stands for the loop's time, so the runs are exact and deterministic.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/servo_timing_model.h"
#include "field_map.h"
#include "recording_device.h"

namespace autograv {
namespace {

using testing::RecordingDevice;

class ScriptedClock final : public ServoClock {
 public:
  double now_s() noexcept override { return time_s; }
  double time_s = 100.0;  // any origin: only differences matter
};

/// The periods of a servo loop: fixed, uniform in [0.1, 2] ms from a seeded generator, or those
/// of a simulated loop's timing model.
class LoopRate {
 public:
  LoopRate(double rate_hz, bool jittery) : rate_hz_(rate_hz), jittery_(jittery) {}
  explicit LoopRate(sim::ServoTiming timing)
      : rate_hz_(1000.0), jittery_(false), timing_(timing), model_(timing, 7) {}
  double nextPeriod_s() {
    if (timing_ != sim::ServoTiming::kExact) return model_.nextInterval_s();
    if (!jittery_) return 1.0 / rate_hz_;
    const double unit = static_cast<double>(random_() >> 11) * 0x1.0p-53;  // [0, 1)
    return 1e-4 + unit * (2e-3 - 1e-4);
  }
  /// The longest period this loop can have: the tolerance of "one tick". Unit: [s]
  double longestPeriod_s() const {
    switch (timing_) {
      case sim::ServoTiming::kDesktop:  // a stall, after a tick that was late already
      case sim::ServoTiming::kRealTime:
        return sim::ServoTimingModel::kStall_s + 1e-3;
      case sim::ServoTiming::kFree:
        return 1.2 / sim::ServoTimingModel::kFreeMinRate_hz;
      case sim::ServoTiming::kExact:
        break;
    }
    return jittery_ ? 2e-3 : 1.0 / rate_hz_;
  }
  std::string name() const {
    if (timing_ != sim::ServoTiming::kExact) return sim::toString(timing_);
    return jittery_ ? "jittery" : std::to_string(rate_hz_) + " Hz";
  }

 private:
  double rate_hz_;
  bool jittery_;
  std::mt19937_64 random_{12345};
  sim::ServoTiming timing_ = sim::ServoTiming::kExact;
  sim::ServoTimingModel model_;
};

std::shared_ptr<const GravityMap> uniformMap(const Eigen::Vector3d& gravity_n) {
  return testing::uniformFieldMap(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 3), gravity_n,
                                  "fake:recording");
}

struct Loop {
  explicit Loop(const CompensationOptions& base) : device(fake, withClock(base)) {}
  CompensationOptions withClock(CompensationOptions options) {
    options.clock = clock;
    return options;
  }
  /// One servo tick `period_s` after the previous one.
  bool tick(double period_s, const Eigen::Vector3d& force_n = Eigen::Vector3d::Zero()) {
    clock->time_s += period_s;
    return device.setForce(force_n);
  }
  std::shared_ptr<ScriptedClock> clock = std::make_shared<ScriptedClock>();
  std::shared_ptr<RecordingDevice> fake = std::make_shared<RecordingDevice>();
  GravityCompensatedDevice device;
};

std::vector<LoopRate> rates() {
  return {LoopRate(1000.0, false),
          LoopRate(4000.0, false),
          LoopRate(10000.0, false),
          LoopRate(0.0, true),
          LoopRate(sim::ServoTiming::kDesktop),
          LoopRate(sim::ServoTiming::kRealTime),
          LoopRate(sim::ServoTiming::kFree)};
}

TEST(GravityCompensatedDeviceTimingTest, TheFirstMapFadesInOverTheRampAtAnyRate) {
  for (LoopRate rate : rates()) {
    CompensationOptions options;
    options.ramp_duration_s = 0.5;
    Loop loop(options);
    // Running without a map for 0.6 s: compensation is fully on, only the map is missing.
    while (loop.clock->time_s < 100.6) loop.tick(rate.nextPeriod_s());
    ASSERT_EQ(loop.device.compensationLevel(), 1.0);
    const Eigen::Vector3d gravity(0.0, 0.3, -0.48);
    loop.device.publishMap(uniformMap(gravity));
    const double published_s = loop.clock->time_s;
    double largest_step_n = 0.0;
    Eigen::Vector3d previous = loop.fake->last_force;
    while (!loop.device.latestMapInUse()) {
      const double period_s = rate.nextPeriod_s();
      ASSERT_TRUE(loop.tick(period_s));
      const double step_n = (loop.fake->last_force - previous).norm();
      // A tick adds at most its own share of |G|: no step when the map arrives.
      EXPECT_LE(step_n, gravity.norm() * period_s / 0.5 + 1e-12) << rate.name();
      largest_step_n = std::max(largest_step_n, step_n);
      previous = loop.fake->last_force;
      ASSERT_LT(loop.clock->time_s - published_s, 1.0) << rate.name();
    }
    EXPECT_NEAR(loop.clock->time_s - published_s, 0.5, rate.longestPeriod_s()) << rate.name();
    EXPECT_TRUE(loop.fake->last_force.isApprox(gravity, 1e-12)) << rate.name();
    EXPECT_GT(largest_step_n, 0.0) << rate.name();
  }
}

TEST(GravityCompensatedDeviceTimingTest, TheCompensationRampTakesItsDurationAtAnyRate) {
  for (LoopRate rate : rates()) {
    CompensationOptions options;
    options.ramp_duration_s = 0.5;
    options.enabled = false;
    Loop loop(options);
    loop.device.publishMap(uniformMap(Eigen::Vector3d(0.0, 0.0, -1.0)));
    while (!loop.device.latestMapInUse()) loop.tick(rate.nextPeriod_s());
    loop.device.setCompensationEnabled(true);
    const double enabled_s = loop.clock->time_s;
    while (loop.device.compensationLevel() < 1.0) {
      ASSERT_TRUE(loop.tick(rate.nextPeriod_s()));
      ASSERT_LT(loop.clock->time_s - enabled_s, 1.0) << rate.name();
    }
    EXPECT_NEAR(loop.clock->time_s - enabled_s, 0.5, rate.longestPeriod_s()) << rate.name();
    loop.device.setCompensationEnabled(false);
    const double disabled_s = loop.clock->time_s;
    while (loop.device.compensationLevel() > 0.0) loop.tick(rate.nextPeriod_s());
    EXPECT_NEAR(loop.clock->time_s - disabled_s, 0.5, rate.longestPeriod_s()) << rate.name();
  }
}

TEST(GravityCompensatedDeviceTimingTest, TheFrozenDriverWindowHoldsItsDurationAtAnyRate) {
  for (LoopRate rate : rates()) {
    CompensationOptions options;
    options.frozen_window_s = 0.1;
    Loop loop(options);
    // Readings frozen from the first tick; the push is +1 N for 10 ms, then -1 N: both ways past
    // the 0.75 N threshold after ~65 ms of filtering, so the window decides.
    ASSERT_TRUE(loop.tick(0.0, Eigen::Vector3d(1.0, 0.0, 0.0)));
    const double start_s = loop.clock->time_s;
    double caught_s = -1.0;
    while (caught_s < 0.0 && loop.clock->time_s - start_s < 1.0) {
      const double push_n = loop.clock->time_s - start_s < 0.01 ? 1.0 : -1.0;
      if (!loop.tick(rate.nextPeriod_s(), Eigen::Vector3d(push_n, 0.0, 0.0))) {
        caught_s = loop.clock->time_s;
      }
    }
    EXPECT_EQ(loop.device.activeFault(), ServoFault::kStalePosition) << rate.name();
    EXPECT_NEAR(caught_s - start_s, 0.1, rate.longestPeriod_s()) << rate.name();
  }
}

TEST(GravityCompensatedDeviceTimingTest, APausedLoopResumesItsRampWhereItWas) {
  CompensationOptions options;
  options.ramp_duration_s = 0.5;
  Loop loop(options);
  loop.device.publishMap(uniformMap(Eigen::Vector3d(0.0, 0.0, -1.0)));
  loop.tick(0.0);  // the first tick counts for nothing
  EXPECT_EQ(loop.device.compensationLevel(), 0.0);
  for (int k = 0; k < 100; ++k) loop.tick(1e-3);
  EXPECT_NEAR(loop.device.compensationLevel(), 0.2, 1e-12);
  loop.tick(3.0);  // a 3 s pause counts as max_tick_interval_s (10 ms)
  EXPECT_NEAR(loop.device.compensationLevel(), 0.22, 1e-12);
  loop.clock->time_s -= 1.0;  // a clock going backwards counts as no time
  loop.tick(0.0);
  EXPECT_NEAR(loop.device.compensationLevel(), 0.22, 1e-12);
}

}  // namespace
}  // namespace autograv
