#include "autograv/device/gravity_compensated_device.h"

#include <stdlib.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "recording_device.h"

namespace autograv {
namespace {

using testing::RecordingDevice;

constexpr double kPeriod = 1e-3;

// A map over a 0.1 m cube centred at the origin holding G(X) = offset + gradient X at its
// vertices; trilinear interpolation reproduces an affine field exactly.
std::shared_ptr<const GravityMap> makeMap(const Eigen::Vector3d& offset,
                                          const Eigen::Matrix3d& gradient = Eigen::Matrix3d::Zero(),
                                          const std::string& model = "fake:recording") {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 3);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n = offset + gradient * grid.vertexPosition(i);
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = model;
  metadata.created_utc = "2026-11-23T13:25:00Z";
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

CompensationOptions optionsWithRamp(int ticks) {
  CompensationOptions options;
  options.servo_period_s = kPeriod;
  options.ramp_duration_s = ticks * kPeriod;
  return options;
}

struct Fixture {
  explicit Fixture(const CompensationOptions& options = optionsWithRamp(0))
      : fake(std::make_shared<RecordingDevice>()), device(fake, options) {}
  std::shared_ptr<RecordingDevice> fake;
  GravityCompensatedDevice device;
};

// --- Forwarding: one test per method of HapticDevice ----------------------------------------

TEST(GravityCompensatedDeviceTest, ForwardsOpen) {
  Fixture f;
  EXPECT_TRUE(f.device.open());
  f.fake->open_result = false;
  EXPECT_FALSE(f.device.open());
  EXPECT_EQ(f.fake->open_calls, 2);
}

TEST(GravityCompensatedDeviceTest, ForwardsClose) {
  Fixture f;
  EXPECT_TRUE(f.device.close());
  f.fake->close_result = false;
  EXPECT_FALSE(f.device.close());
  EXPECT_EQ(f.fake->close_calls, 2);
}

TEST(GravityCompensatedDeviceTest, ForwardsCalibrateAndItsFlag) {
  Fixture f;
  EXPECT_TRUE(f.device.calibrate(true));
  EXPECT_TRUE(f.fake->last_calibrate_force);
  f.fake->calibrate_result = false;
  EXPECT_FALSE(f.device.calibrate());
  EXPECT_FALSE(f.fake->last_calibrate_force);  // the default argument is false, as in CHAI3D
  EXPECT_EQ(f.fake->calibrate_calls, 2);
}

TEST(GravityCompensatedDeviceTest, ForwardsGetPosition) {
  Fixture f;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  EXPECT_TRUE(f.device.getPosition(position));
  EXPECT_EQ(position, f.fake->position);
  f.fake->position_result = false;
  EXPECT_FALSE(f.device.getPosition(position));
  EXPECT_EQ(f.fake->get_position_calls, 2u);
}

TEST(GravityCompensatedDeviceTest, ForwardsGetLinearVelocity) {
  Fixture f;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
  EXPECT_TRUE(f.device.getLinearVelocity(velocity));
  EXPECT_EQ(velocity, f.fake->velocity);
  f.fake->velocity_result = false;
  EXPECT_FALSE(f.device.getLinearVelocity(velocity));
  EXPECT_EQ(f.fake->get_velocity_calls, 2u);
}

TEST(GravityCompensatedDeviceTest, ForwardsGetUserSwitch) {
  Fixture f;
  bool pressed = false;
  EXPECT_TRUE(f.device.getUserSwitch(3, pressed));
  EXPECT_TRUE(pressed);
  EXPECT_EQ(f.fake->last_switch_index, 3);
  f.fake->switch_result = false;
  f.fake->switch_pressed = false;
  EXPECT_FALSE(f.device.getUserSwitch(1, pressed));
  EXPECT_FALSE(pressed);
  EXPECT_EQ(f.fake->last_switch_index, 1);
}

TEST(GravityCompensatedDeviceTest, ForwardsSpecifications) {
  Fixture f;
  EXPECT_EQ(&f.device.specifications(), &f.fake->specs);
  f.fake->specs.model_name = "renamed";
  EXPECT_EQ(f.device.specifications().model_name, "renamed");
}

TEST(GravityCompensatedDeviceTest, ForwardsSetForceUnchangedWithoutAMap) {
  Fixture f;
  const Eigen::Vector3d force(0.5, -1.25, 2.0);
  EXPECT_TRUE(f.device.setForce(force));
  EXPECT_EQ(f.fake->last_force, force);
  f.fake->set_force_result = false;
  EXPECT_FALSE(f.device.setForce(force));
  EXPECT_EQ(f.fake->set_force_calls, 2u);
  EXPECT_EQ(f.device.activeFault(), ServoFault::kWriteFailed);
}

TEST(GravityCompensatedDeviceTest, RefusesANullDeviceAndBadOptions) {
  EXPECT_THROW(GravityCompensatedDevice(nullptr), Error);
  auto fake = std::make_shared<RecordingDevice>();
  CompensationOptions options;
  options.servo_period_s = 0.0;
  EXPECT_THROW(GravityCompensatedDevice(fake, options), Error);
  options = CompensationOptions{};
  options.ramp_duration_s = -1.0;
  EXPECT_THROW(GravityCompensatedDevice(fake, options), Error);
  options = CompensationOptions{};
  options.outside_margin_m = NAN;
  EXPECT_THROW(GravityCompensatedDevice(fake, options), Error);
  options = CompensationOptions{};
  options.stale_tick_limit = -2;
  EXPECT_THROW(GravityCompensatedDevice(fake, options), Error);
}

// --- Compensation -----------------------------------------------------------------------------

TEST(GravityCompensatedDeviceTest, AddsTheInterpolatedGravityAtTheLatestPosition) {
  Fixture f;
  Eigen::Matrix3d gradient;
  gradient << 1.0, 2.0, 0.0, -3.0, 0.5, 1.0, 0.0, 4.0, -2.0;
  const Eigen::Vector3d offset(0.1, 0.2, -1.5);
  f.device.publishMap(makeMap(offset, gradient));
  const Eigen::Vector3d force(0.3, 0.0, -0.2);
  for (const Eigen::Vector3d& position :
       {Eigen::Vector3d(0.01, 0.02, -0.03), Eigen::Vector3d(-0.049, 0.0, 0.05),
        Eigen::Vector3d(0.0, 0.0, 0.0)}) {
    f.fake->position = position;
    EXPECT_TRUE(f.device.setForce(force));
    EXPECT_TRUE(f.fake->last_force.isApprox(force + offset + gradient * position, 1e-12))
        << f.fake->last_force.transpose();
  }
  EXPECT_EQ(f.device.compensationLevel(), 1.0);
}

TEST(GravityCompensatedDeviceTest, UsesTheServoThreadsOwnReadingWithoutReadingAgain) {
  Fixture f;
  f.device.publishMap(makeMap(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()));
  f.device.setForce(Eigen::Vector3d::Zero());  // this thread becomes the servo thread
  const std::uint64_t reads = f.fake->get_position_calls;

  // The application reads, then writes: one driver read per tick, and that reading is used even
  // if the driver would now answer something else.
  const Eigen::Vector3d read_position(0.01, 0.02, 0.03);
  f.fake->position = read_position;
  Eigen::Vector3d position;
  f.device.getPosition(position);
  f.fake->position = Eigen::Vector3d(-0.04, -0.04, -0.04);
  f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_EQ(f.fake->get_position_calls, reads + 1);
  EXPECT_TRUE(f.fake->last_force.isApprox(read_position, 1e-12));

  // No reading since the last tick: setForce reads the driver itself.
  f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_EQ(f.fake->get_position_calls, reads + 2);
  EXPECT_TRUE(f.fake->last_force.isApprox(f.fake->position, 1e-12));

  // A reading taken by another thread (a graphics loop) is forwarded but never used.
  f.fake->position = Eigen::Vector3d(0.02, 0.02, 0.02);
  std::thread([&] {
    Eigen::Vector3d elsewhere;
    f.device.getPosition(elsewhere);
  }).join();
  f.fake->position = Eigen::Vector3d(-0.01, 0.0, 0.01);
  f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_TRUE(f.fake->last_force.isApprox(f.fake->position, 1e-12));
}

TEST(GravityCompensatedDeviceTest, ClampsTheSumKeepingItsDirectionAndCountsClamps) {
  Fixture f;
  f.device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.0, -3.0)));
  const Eigen::Vector3d force(6.0, 0.0, -3.0);  // sum (6, 0, -6): |sum| = 8.49 N > 8 N
  EXPECT_TRUE(f.device.setForce(force));
  const Eigen::Vector3d sum(6.0, 0.0, -6.0);
  EXPECT_NEAR(f.fake->last_force.norm(), 8.0, 1e-12);
  EXPECT_NEAR(f.fake->last_force.normalized().dot(sum.normalized()), 1.0, 1e-12);
  EXPECT_EQ(f.device.clampCount(), 1u);
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(1.0, 0.0, 0.0)));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d(1.0, 0.0, -3.0));
  EXPECT_EQ(f.device.clampCount(), 1u);
  EXPECT_EQ(f.device.faultCount(), 0u);
}

// Invariant of tests/fuzz/servo_fuzzer.cpp: whatever finite force the application asks for, the
// device gets its limit along that direction. Squaring 1e300 N overflows; the force must not
// vanish (max / inf = 0) or become NaN.
TEST(GravityCompensatedDeviceTest, AForceWhoseSquareOverflowsIsClampedAlongItsDirection) {
  Fixture f;
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(1e300, -1e300, 0.0)));
  EXPECT_NEAR(f.fake->last_force.norm(), 8.0, 1e-12);
  EXPECT_NEAR(f.fake->last_force.normalized().dot(Eigen::Vector3d(1.0, -1.0, 0.0).normalized()),
              1.0, 1e-12);

  // The largest doubles plus the compensation: the sum stays finite (the map's estimates are
  // bounded by kMaxGravityEstimate_n) and is clamped like any other.
  f.device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.0, -kMaxGravityEstimate_n)));
  const double largest = std::numeric_limits<double>::max();
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(largest, largest, -largest)));
  EXPECT_TRUE(f.fake->last_force.allFinite()) << f.fake->last_force.transpose();
  EXPECT_NEAR(f.fake->last_force.norm(), 8.0, 1e-12);
  EXPECT_NEAR(f.fake->last_force.normalized().dot(Eigen::Vector3d(1.0, 1.0, -1.0).normalized()),
              1.0, 1e-12);
  EXPECT_EQ(f.device.clampCount(), 2u);
  EXPECT_EQ(f.device.faultCount(), 0u);
}

TEST(GravityCompensatedDeviceTest, RampsInWhenEnabledAndOutWhenDisabled) {
  CompensationOptions options = optionsWithRamp(10);
  options.enabled = false;
  Fixture f(options);
  const Eigen::Vector3d gravity(0.0, 0.0, -2.0);
  f.device.publishMap(makeMap(gravity));
  const Eigen::Vector3d force(0.5, 0.0, 0.0);
  for (int k = 0; k < 20; ++k) {  // the map fades in, but compensation is off: F only
    f.device.setForce(force);
    EXPECT_EQ(f.fake->last_force, force);
  }
  f.device.setCompensationEnabled(true);
  for (int k = 1; k <= 12; ++k) {
    f.device.setForce(force);
    const double level = std::min(k, 10) / 10.0;
    EXPECT_TRUE(f.fake->last_force.isApprox(force + level * gravity, 1e-12)) << "tick " << k;
    EXPECT_DOUBLE_EQ(f.device.compensationLevel(), level);
  }
  f.device.setCompensationEnabled(false);
  for (int k = 1; k <= 12; ++k) {
    f.device.setForce(force);
    const double level = std::max(10 - k, 0) / 10.0;
    EXPECT_TRUE(f.fake->last_force.isApprox(force + level * gravity, 1e-12)) << "tick " << k;
  }
}

TEST(GravityCompensatedDeviceTest, FadesFromOneMapToTheNext) {
  Fixture f(optionsWithRamp(4));
  const Eigen::Vector3d a(0.0, 0.0, -1.0);
  const Eigen::Vector3d b(0.0, 1.0, -3.0);
  f.device.publishMap(makeMap(a));
  for (int k = 0; k < 10; ++k) f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_TRUE(f.fake->last_force.isApprox(a));
  f.device.publishMap(makeMap(b));
  for (int k = 1; k <= 6; ++k) {
    f.device.setForce(Eigen::Vector3d::Zero());
    const double w = std::min(k, 4) / 4.0;
    EXPECT_TRUE(f.fake->last_force.isApprox((1.0 - w) * a + w * b, 1e-12)) << "tick " << k;
  }
  f.device.publishMap(nullptr);  // removing the map fades out too
  for (int k = 1; k <= 4; ++k) {
    f.device.setForce(Eigen::Vector3d::Zero());
    EXPECT_TRUE(f.fake->last_force.isApprox((1.0 - k / 4.0) * b, 1e-12) ||
                (k == 4 && f.fake->last_force.isZero()))
        << "tick " << k;
  }
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d::Zero());
}

TEST(GravityCompensatedDeviceTest, RefusesAMapForAnotherModelUnlessAllowed) {
  Fixture f;
  EXPECT_THROW(
      f.device.publishMap(makeMap(Eigen::Vector3d::Ones(), Eigen::Matrix3d::Zero(), "sim:omega")),
      Error);
  EXPECT_EQ(f.device.publishedMap(), nullptr);
  f.device.publishMap(makeMap(Eigen::Vector3d::Ones(), Eigen::Matrix3d::Zero(), "sim:omega"), true);
  EXPECT_NE(f.device.publishedMap(), nullptr);
  f.fake->specs.model_name.clear();  // a device not opened yet cannot be checked
  EXPECT_THROW(f.device.publishMap(makeMap(Eigen::Vector3d::Ones())), Error);
}

TEST(GravityCompensatedDeviceTest, ABadMapFileLeavesThePreviousMapInUse) {
  std::string pattern = (std::filesystem::temp_directory_path() / "autograv-gcd-XXXXXX").string();
  const std::filesystem::path folder = ::mkdtemp(pattern.data());
  const std::string path = (folder / "map.json").string();
  Fixture f;
  const auto good = makeMap(Eigen::Vector3d(0.0, 0.0, -1.0));
  f.device.publishMap(good);
  saveMap(*good, path);
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), {});
  }
  for (const std::string& corrupted : {text.substr(0, text.size() / 2), std::string("{}"),
                                       std::string(text).replace(text.find("-1.0"), 4, "-9.0")}) {
    std::ofstream(path, std::ios::trunc) << corrupted;
    EXPECT_THROW(f.device.publishMap(std::make_shared<const GravityMap>(loadMap(path))), Error);
    EXPECT_EQ(f.device.publishedMap(), good);
    f.device.setForce(Eigen::Vector3d::Zero());
    EXPECT_TRUE(f.fake->last_force.isApprox(Eigen::Vector3d(0.0, 0.0, -1.0), 1e-12));
  }
  std::filesystem::remove_all(folder);
}

// --- Faults -----------------------------------------------------------------------------------

TEST(GravityCompensatedDeviceTest, BadPositionsSendZeroAndRaiseAFault) {
  struct Case {
    const char* name;
    std::function<void(RecordingDevice&)> breakIt;
    ServoFault fault;
  };
  const Case cases[] = {
      {"read fails", [](RecordingDevice& d) { d.position_result = false; },
       ServoFault::kReadFailed},
      {"NaN", [](RecordingDevice& d) { d.position.y() = NAN; }, ServoFault::kNonFinitePosition},
      {"Inf", [](RecordingDevice& d) { d.position.z() = -INFINITY; },
       ServoFault::kNonFinitePosition},
      {"far outside", [](RecordingDevice& d) { d.position.x() = 0.05 + 0.0101; },
       ServoFault::kOutsideMap},
      {"no force limit", [](RecordingDevice& d) { d.specs.max_linear_force_n = 0.0; },
       ServoFault::kNoForceLimit},
  };
  for (const Case& c : cases) {
    Fixture f(optionsWithRamp(5));
    const Eigen::Vector3d gravity(0.0, 0.0, -2.0);
    f.device.publishMap(makeMap(gravity));
    const Eigen::Vector3d force(0.5, 0.5, 0.0);
    for (int k = 0; k < 10; ++k) EXPECT_TRUE(f.device.setForce(force));
    EXPECT_TRUE(f.fake->last_force.isApprox(force + gravity));
    const RecordingDevice healthy = *f.fake;
    c.breakIt(*f.fake);
    for (int k = 0; k < 3; ++k) {
      EXPECT_FALSE(f.device.setForce(force)) << c.name;
      EXPECT_EQ(f.fake->last_force, Eigen::Vector3d::Zero()) << c.name;
    }
    EXPECT_EQ(f.device.activeFault(), c.fault) << c.name;
    EXPECT_EQ(f.device.faultCount(c.fault), 3u) << c.name;
    EXPECT_EQ(f.device.faultCount(), 3u) << c.name;
    EXPECT_EQ(f.device.compensationLevel(), 0.0) << c.name;
    // Recovery: the application force at once, compensation ramping in again from zero.
    f.fake->position = healthy.position;
    f.fake->position_result = true;
    f.fake->specs = healthy.specs;
    for (int k = 1; k <= 5; ++k) {
      EXPECT_TRUE(f.device.setForce(force)) << c.name;
      EXPECT_TRUE(f.fake->last_force.isApprox(force + (k / 5.0) * gravity, 1e-12))
          << c.name << " tick " << k;
    }
    EXPECT_EQ(f.device.activeFault(), ServoFault::kNone) << c.name;
    EXPECT_EQ(f.device.lastFault(), c.fault) << c.name;
  }
}

TEST(GravityCompensatedDeviceTest, ANonFiniteApplicationForceIsNeverSent) {
  Fixture f;
  EXPECT_FALSE(f.device.setForce(Eigen::Vector3d(NAN, 0.0, 0.0)));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d::Zero());
  EXPECT_EQ(f.device.activeFault(), ServoFault::kNonFiniteForce);
}

TEST(GravityCompensatedDeviceTest, WithinTheMarginTheBoundaryValueIsUsed) {
  Fixture f;
  f.device.publishMap(makeMap(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()));
  f.fake->position = Eigen::Vector3d(0.059, 0.0, 0.0);  // 9 mm outside, margin 10 mm
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(f.fake->last_force.isApprox(Eigen::Vector3d(0.05, 0.0, 0.0), 1e-12));
}

TEST(GravityCompensatedDeviceTest, OutsideTheMapIsNoFaultWhileCompensationIsOff) {
  CompensationOptions options = optionsWithRamp(0);
  options.enabled = false;
  Fixture f(options);
  f.device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.0, -2.0)));
  f.fake->position = Eigen::Vector3d(0.5, 0.0, 0.0);
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(1.0, 0.0, 0.0)));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d(1.0, 0.0, 0.0));
}

TEST(GravityCompensatedDeviceTest, AWriteFailureIsCountedAndRestartsTheRamp) {
  Fixture f(optionsWithRamp(4));
  const Eigen::Vector3d gravity(0.0, 0.0, -2.0);
  f.device.publishMap(makeMap(gravity));
  for (int k = 0; k < 8; ++k) f.device.setForce(Eigen::Vector3d::Zero());
  f.fake->set_force_result = false;
  const std::uint64_t writes = f.fake->set_force_calls;
  EXPECT_FALSE(f.device.setForce(Eigen::Vector3d::Zero()));
  EXPECT_EQ(f.fake->set_force_calls, writes + 1);  // one attempt, no second write of zero
  EXPECT_EQ(f.device.faultCount(ServoFault::kWriteFailed), 1u);
  f.fake->set_force_result = true;
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(f.fake->last_force.isApprox(0.25 * gravity, 1e-12));
}

TEST(GravityCompensatedDeviceTest, AFrozenPositionUnderAChangingForceIsStale) {
  CompensationOptions options = optionsWithRamp(0);
  options.stale_tick_limit = 50;
  options.stale_force_change_n = 0.5;
  Fixture f(options);
  // Constant force and frozen position: a device at rest, never a fault.
  for (int k = 0; k < 500; ++k) EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(1.0, 0.0, 0.0)));
  // Changing force, frozen position: a fault once the run is longer than 50 ticks.
  f.fake->position.x() += 1e-6;
  int first_fault_tick = -1;
  for (int k = 0; k < 200; ++k) {
    const bool ok = f.device.setForce(Eigen::Vector3d(1.0 + 0.01 * k, 0.0, 0.0));
    if (!ok && first_fault_tick < 0) first_fault_tick = k;
    if (first_fault_tick >= 0) {
      EXPECT_FALSE(ok) << k;  // stays faulted while frozen
      EXPECT_EQ(f.fake->last_force, Eigen::Vector3d::Zero());
    }
  }
  EXPECT_EQ(first_fault_tick, 51);
  EXPECT_EQ(f.device.activeFault(), ServoFault::kStalePosition);
  // The position moves: healthy again.
  f.fake->position.x() += 1e-6;
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(3.0, 0.0, 0.0)));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d(3.0, 0.0, 0.0));
  // Small force changes (under 0.5 N) never trip it.
  for (int k = 0; k < 500; ++k) {
    EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(3.0 + 0.4 * std::sin(k), 0.0, 0.0)));
  }
}

TEST(GravityCompensatedDeviceTest, TheStaleCheckCanBeTurnedOff) {
  CompensationOptions options = optionsWithRamp(0);
  options.stale_tick_limit = 0;
  Fixture f(options);
  for (int k = 0; k < 1000; ++k) EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(0.001 * k, 0, 0)));
  EXPECT_EQ(f.device.faultCount(), 0u);
}

TEST(GravityCompensatedDeviceTest, FaultNamesAreStable) {
  EXPECT_STREQ(toString(ServoFault::kNone), "none");
  EXPECT_STREQ(toString(ServoFault::kStalePosition), "stale_position");
  EXPECT_STREQ(toString(ServoFault::kWriteFailed), "write_failed");
  EXPECT_STREQ(toString(static_cast<ServoFault>(200)), "unknown");
}

// --- Map lifetime and real-time safety --------------------------------------------------------

TEST(GravityCompensatedDeviceTest, OldMapsAreReleasedOnceTheServoThreadHasMovedOn) {
  Fixture f(optionsWithRamp(3));
  auto a = makeMap(Eigen::Vector3d(0.0, 0.0, -1.0));
  const std::weak_ptr<const GravityMap> weak_a = a;
  f.device.publishMap(std::move(a));
  EXPECT_FALSE(f.device.latestMapInUse());
  f.device.setForce(Eigen::Vector3d::Zero());
  f.device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.0, -2.0)));
  EXPECT_EQ(f.device.retainedMapCount(), 2u);
  EXPECT_FALSE(weak_a.expired());  // still fading in, then fading out: in use
  for (int k = 0; k < 2; ++k) f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_EQ(f.device.reclaimRetiredMaps(), 0u);  // first fade just finished, B not taken yet
  for (int k = 0; k < 2; ++k) f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_FALSE(f.device.latestMapInUse());
  EXPECT_FALSE(weak_a.expired());
  f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_TRUE(f.device.latestMapInUse());
  EXPECT_EQ(f.device.reclaimRetiredMaps(), 1u);
  EXPECT_TRUE(weak_a.expired());
  EXPECT_EQ(f.device.retainedMapCount(), 1u);
  EXPECT_TRUE(f.fake->last_force.isApprox(Eigen::Vector3d(0.0, 0.0, -2.0)));
}

TEST(GravityCompensatedDeviceTest, TheServoPathAllocatesNothing) {
  Fixture f(optionsWithRamp(20));
  f.device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.0, -1.0), Eigen::Matrix3d::Identity()));
  for (int k = 0; k < 30; ++k) f.device.setForce(Eigen::Vector3d::Zero());
  // Taken and faded to inside the counted loop.
  f.device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.2, -1.5)));
  Eigen::Vector3d position;
  Eigen::Vector3d velocity;
  bool pressed;
  testing::AllocationCounter counter;
  for (int k = 0; k < 20000; ++k) {
    f.fake->position = Eigen::Vector3d(0.04 * std::sin(0.01 * k), 0.0, 0.01);
    if (k == 5000) f.fake->position.x() = NAN;       // a fault
    if (k == 6000) f.fake->position_result = false;  // another
    if (k == 6001) f.fake->position_result = true;
    if (k % 3 == 0) f.device.getPosition(position);
    f.device.getLinearVelocity(velocity);
    f.device.getUserSwitch(0, pressed);
    f.device.setForce(Eigen::Vector3d(9.0 * std::cos(0.001 * k), 0.0, 0.0));
    if (k == 10000) f.device.setCompensationEnabled(false);
    if (k == 12000) f.device.setCompensationEnabled(true);
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_GT(f.device.clampCount(), 0u);
  EXPECT_EQ(f.device.faultCount(), 2u);
}

}  // namespace
}  // namespace autograv
