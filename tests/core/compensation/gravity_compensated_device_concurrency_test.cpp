// A live servo thread while other threads publish maps, toggle compensation and read the status.
// Meant to run under ThreadSanitizer too (the CI builds this binary again with
// -fsanitize=thread): any race between publication, reclamation and the servo path shows up there
// as a report, and here as a wrong force or a map that is never released.

#include <atomic>
#include <cmath>
#include <memory>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/map/gravity_map.h"
#include "field_map.h"
#include "recording_device.h"

namespace autograv {
namespace {

// A constant field G = (0, 0, -strength) on a 2x2x2 grid around the origin.
std::shared_ptr<const GravityMap> constantMap(double strength_n) {
  return testing::uniformFieldMap(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2),
                                  Eigen::Vector3d(0.0, 0.0, -strength_n), "fake:recording");
}

TEST(GravityCompensatedDeviceConcurrencyTest, MapsSwapUnderALiveServoLoop) {
  auto fake = std::make_shared<testing::RecordingDevice>();
  CompensationOptions options;
  options.clock = std::make_shared<FixedPeriodServoClock>(1e-3);  // one period per tick
  options.ramp_duration_s = 3e-3;  // short fades: many swaps during the test
  GravityCompensatedDevice device(fake, options);
  ASSERT_TRUE(device.open());

  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> bad_forces{0};
  std::atomic<std::uint64_t> servo_ticks{0};
  std::atomic<bool> reader_saw_ticks{false};
  const Eigen::Vector3d application_force(0.25, -0.5, 0.0);

  // The servo thread: only it touches the fake device after open().
  std::thread servo([&] {
    std::uint64_t ticks = 0;
    std::uint64_t bad = 0;
    Eigen::Vector3d position;
    while (!stop.load(std::memory_order_acquire)) {
      fake->position = Eigen::Vector3d(0.01 * std::sin(1e-3 * ticks), 0.0, 0.0);
      device.getPosition(position);
      device.setForce(application_force);
      // Every map is a vertical field of 1..3 N, and any fade or ramp mixes them with weights
      // in [0, 1]: the vertical part must stay in [-3, 0] and the rest must be the application's.
      const Eigen::Vector3d& sent = fake->last_force;
      const bool ok = sent.allFinite() && sent.z() <= 1e-12 && sent.z() >= -3.0 - 1e-12 &&
                      sent.x() == application_force.x() && sent.y() == application_force.y();
      if (!ok) ++bad;
      ++ticks;
      if (ticks % 64 == 0) {
        servo_ticks.store(ticks, std::memory_order_relaxed);
        std::this_thread::yield();
      }
    }
    bad_forces.store(bad);
    servo_ticks.store(ticks);
  });

  // A status reader, as an application's user interface would be.
  std::thread reader([&] {
    std::uint64_t reads = 0;
    while (!stop.load(std::memory_order_acquire)) {
      const double level = device.compensationLevel();
      EXPECT_GE(level, 0.0);
      EXPECT_LE(level, 1.0);
      EXPECT_EQ(device.faultCount(), 0u);
      reads += device.tickCount() > 0 ? 1 : 0;
      if (reads > 0) reader_saw_ticks.store(true, std::memory_order_release);
      const auto map = device.publishedMap();
      EXPECT_TRUE(!map || map->vertices().size() == 8u);  // none yet, or the whole one
      std::this_thread::yield();
    }
    EXPECT_GT(reads, 0u);
  });

  // The publisher (this thread): many maps, some toggling of the switch.
  std::vector<std::weak_ptr<const GravityMap>> published;
  constexpr int kMaps = 400;
  for (int i = 0; i < kMaps; ++i) {
    auto map = constantMap(1.0 + 2.0 * (i % 7) / 6.0);
    published.push_back(map);
    device.publishMap(std::move(map));
    if (i % 50 == 25) device.setCompensationEnabled(false);
    if (i % 50 == 30) device.setCompensationEnabled(true);
    if (i % 4 == 0) {
      // Let the servo thread catch up now and then, so that maps are taken and released.
      while (!device.latestMapInUse()) std::this_thread::yield();
      device.reclaimRetiredMaps();
    }
  }
  device.setCompensationEnabled(true);
  while (!device.latestMapInUse()) std::this_thread::yield();
  device.reclaimRetiredMaps();

  // On a loaded machine the publisher can finish before the reader has seen a tick: let it.
  for (int i = 0; i < 100000 && !reader_saw_ticks.load(std::memory_order_acquire); ++i) {
    std::this_thread::yield();
  }
  stop.store(true, std::memory_order_release);
  servo.join();
  reader.join();

  EXPECT_EQ(bad_forces.load(), 0u);
  EXPECT_GT(servo_ticks.load(), 0u);
  // Everything but the latest map has been released; the latest is the one in use.
  EXPECT_EQ(device.retainedMapCount(), 1u);
  for (int i = 0; i + 1 < kMaps; ++i) EXPECT_TRUE(published[i].expired()) << "map " << i;
  EXPECT_FALSE(published.back().expired());
  EXPECT_EQ(device.faultCount(), 0u);
}

}  // namespace
}  // namespace autograv
