// A loop that runs in simulated time with the default (wall) clock sees its map fade in over
// wall-clock seconds, i.e. hardly at all: the decorator says so through fadeStalled() within the
// first second of simulated time, and never on a loop whose clock moves as real time does.

#include <cmath>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/map/gravity_map.h"
#include "field_map.h"
#include "recording_device.h"

namespace autograv {
namespace {

using testing::RecordingDevice;

std::shared_ptr<const GravityMap> uniformMap() {
  return testing::uniformFieldMap(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 3),
                                  Eigen::Vector3d(0.0, 0.0, 1.0), "fake:recording");
}

/// A clock that moves on by the next period at every reading, as real time does between the
/// ticks of a loop paced by the wall clock (a loop that sleeps until its next period).
class PacedClock final : public ServoClock {
 public:
  explicit PacedClock(std::vector<double> periods_s) : periods_s_(std::move(periods_s)) {}
  double now_s() noexcept override {
    time_s_ += periods_s_[next_++ % periods_s_.size()];
    return time_s_;
  }

 private:
  std::vector<double> periods_s_;
  std::size_t next_ = 0;
  double time_s_ = 50.0;
};

/// Ticks until fadeStalled() (or `ticks` of them); returns the tick it was set on, 0 if never.
long ticksUntilStalled(GravityCompensatedDevice& device, long ticks) {
  device.publishMap(uniformMap());
  for (long k = 1; k <= ticks; ++k) {
    device.setForce(Eigen::Vector3d::Zero());
    if (device.fadeStalled()) return k;
  }
  return 0;
}

// The wall clock as a simulated loop sees it: 2 us per tick, a thousand times faster than real
// time (a fast machine's SteadyServoClock; a fake so that the test does not depend on how fast
// this machine, its load or a sanitizer lets the loop run).
CompensationOptions onAFastWallClock() {
  CompensationOptions options;
  options.clock = std::make_shared<PacedClock>(std::vector<double>{2e-6});
  return options;
}

TEST(GravityCompensatedDeviceStallTest, ASimulatedLoopOnTheWallClockIsToldWithinItsFirstSecond) {
  // 1000 ticks are one second of simulated time at 1 kHz; they take microseconds of wall time.
  auto fake = std::make_shared<RecordingDevice>();
  GravityCompensatedDevice device(fake, onAFastWallClock());
  const long stalled_at = ticksUntilStalled(device, 1000);
  EXPECT_GE(stalled_at, GravityCompensatedDevice::kStalledFadeTicks);
  EXPECT_LE(stalled_at, 1000);
  EXPECT_LT(device.compensationLevel(), 0.5) << "the fade indeed did not get far";
  // It stays set, and compensation goes on as before (the application's force passes).
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(device.setForce(Eigen::Vector3d(0.1, 0.0, 0.0)));
  EXPECT_TRUE(device.fadeStalled());
}

TEST(GravityCompensatedDeviceStallTest, AFixedPeriodClockIsNeverTakenForAStall) {
  auto fake = std::make_shared<RecordingDevice>();
  CompensationOptions options;
  options.clock = std::make_shared<FixedPeriodServoClock>(1e-3);
  GravityCompensatedDevice device(fake, options);
  EXPECT_EQ(ticksUntilStalled(device, 5000), 0);
  EXPECT_DOUBLE_EQ(device.compensationLevel(), 1.0);
  EXPECT_TRUE(device.latestMapInUse());
}

TEST(GravityCompensatedDeviceStallTest, ARealTimeLoopAtOneToTenKilohertzOrJitteryIsNeverFlagged) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> jitter_s(1e-5, 2e-3);  // 10 us to 2 ms per tick
  std::vector<double> jittery(4096);
  for (double& period_s : jittery) period_s = jitter_s(random);
  const std::vector<std::vector<double>> loops = {{1e-3}, {2.5e-4}, {1e-4}, jittery};
  for (const auto& periods : loops) {
    auto fake = std::make_shared<RecordingDevice>();
    CompensationOptions options;
    options.clock = std::make_shared<PacedClock>(periods);
    options.ramp_duration_s = 2.0;  // a long fade: many ticks watched
    GravityCompensatedDevice device(fake, options);
    EXPECT_EQ(ticksUntilStalled(device, 30000), 0) << "first period " << periods.front();
    // Ramps in the middle of the run too: disable, re-enable, a new map.
    device.setCompensationEnabled(false);
    device.setCompensationEnabled(true);
    device.publishMap(uniformMap());
    for (int k = 0; k < 30000; ++k) device.setForce(Eigen::Vector3d::Zero());
    EXPECT_FALSE(device.fadeStalled()) << "first period " << periods.front();
  }
}

TEST(GravityCompensatedDeviceStallTest, WatchingTheFadeAllocatesNothing) {
  auto fake = std::make_shared<RecordingDevice>();
  GravityCompensatedDevice device(fake, onAFastWallClock());
  device.setForce(Eigen::Vector3d::Zero());
  device.publishMap(uniformMap());
  testing::AllocationCounter counter;
  for (int k = 0; k < 5000; ++k) device.setForce(Eigen::Vector3d(0.01 * std::sin(0.01 * k), 0, 0));
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(device.fadeStalled());
}

}  // namespace
}  // namespace autograv
