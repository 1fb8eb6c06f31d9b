#include "autograv/compensation/gravity_compensated_device.h"

#include <cmath>
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
#include "field_map.h"
#include "forwarding_checks.h"
#include "recording_device.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

using testing::RecordingDevice;

constexpr double kPeriod = 1e-3;
constexpr double kTwoPi = 6.283185307179586;

// A map over a 0.1 m cube centred at the origin holding G(X) = offset + gradient X at its
// vertices; trilinear interpolation reproduces an affine field exactly.
std::shared_ptr<const GravityMap> makeMap(const Eigen::Vector3d& offset,
                                          const Eigen::Matrix3d& gradient = Eigen::Matrix3d::Zero(),
                                          const std::string& model = "fake:recording") {
  MapMetadata metadata;
  metadata.device_model = model;
  metadata.created_utc = "2026-11-23T13:25:00Z";
  return testing::fieldMap(
      WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 3),
      [&](const Eigen::Vector3d& x) -> Eigen::Vector3d { return offset + gradient * x; },
      std::move(metadata));
}

// A loop at exactly 1 / kPeriod: each setForce reads the clock once and the first tick counts
// for nothing, so a ramp of `ticks` periods is complete on the (ticks + 1)-th tick after open.
CompensationOptions optionsWithRamp(int ticks) {
  CompensationOptions options;
  options.clock = std::make_shared<FixedPeriodServoClock>(kPeriod);
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
  testing::expectForwardsOpen(f.device, *f.fake);
}

TEST(GravityCompensatedDeviceTest, ForwardsClose) {
  Fixture f;
  testing::expectForwardsClose(f.device, *f.fake);
}

TEST(GravityCompensatedDeviceTest, ForwardsCalibrateAndItsFlag) {
  Fixture f;
  testing::expectForwardsCalibrateAndItsFlag(f.device, *f.fake);
}

TEST(GravityCompensatedDeviceTest, ForwardsGetPosition) {
  Fixture f;
  testing::expectForwardsGetPosition(f.device, *f.fake);
}

TEST(GravityCompensatedDeviceTest, ForwardsGetLinearVelocity) {
  Fixture f;
  testing::expectForwardsGetLinearVelocity(f.device, *f.fake);
}

TEST(GravityCompensatedDeviceTest, ForwardsGetUserSwitch) {
  Fixture f;
  testing::expectForwardsGetUserSwitch(f.device, *f.fake);
}

TEST(GravityCompensatedDeviceTest, ForwardsSpecifications) {
  Fixture f;
  testing::expectForwardsSpecifications(f.device, *f.fake);
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
  const std::function<void(CompensationOptions&)> spoilers[] = {
      [](CompensationOptions& o) { o.max_tick_interval_s = 0.0; },
      [](CompensationOptions& o) { o.ramp_duration_s = -1.0; },
      [](CompensationOptions& o) { o.outside_margin_m = NAN; },
      [](CompensationOptions& o) { o.frozen_window_s = -0.1; },
      [](CompensationOptions& o) { o.frozen_hand_stiffness_n_per_m = INFINITY; },
      [](CompensationOptions& o) { o.motor_time_constant_s = 0.0; },
      [](CompensationOptions& o) { o.initial_thermal_load = -0.1; },
      [](CompensationOptions& o) { o.initial_thermal_load = NAN; },
  };
  for (const auto& spoil : spoilers) {
    CompensationOptions options;
    spoil(options);
    EXPECT_THROW(GravityCompensatedDevice(fake, options), Error);
  }
  EXPECT_THROW(FixedPeriodServoClock(0.0), Error);
}

TEST(GravityCompensatedDeviceTest, ThermalLoadIsTheSquaredForceOverTheRatingOverTheMotorsTime) {
  CompensationOptions options = optionsWithRamp(0);
  options.motor_time_constant_s = 1.0;
  Fixture f(options);
  const Eigen::Vector3d force(0.0, 0.6, 0.8);  // 1 N against the fake's 2 N rating (8 N / 4)
  EXPECT_TRUE(f.device.setForce(force));
  EXPECT_EQ(f.device.thermalLoad(), 0.0) << "no rating is known before open()";
  ASSERT_TRUE(f.device.open());
  const auto run = [&f, &force](int ticks) {
    for (int tick = 0; tick < ticks; ++tick) f.device.setForce(force);
  };
  run(1001);  // the first tick counts for nothing; then one time constant
  EXPECT_NEAR(f.device.thermalLoad(), 0.25 * (1.0 - std::exp(-1.0)), 0.002);
  run(9000);
  EXPECT_NEAR(f.device.thermalLoad(), 0.25, 0.001);
  // Forces that never reach the motors heat nothing: the load falls as a motor cools.
  f.fake->set_force_result = false;
  run(1001);
  EXPECT_NEAR(f.device.thermalLoad(), 0.25 * std::exp(-1.0), 0.002);
}

TEST(GravityCompensatedDeviceTest, AMapsThermalCorrectionGivesBackWhatWarmMotorsLose) {
  CompensationOptions options = optionsWithRamp(0);
  options.motor_time_constant_s = 1.0;
  Fixture f(options);
  ASSERT_TRUE(f.device.open());
  const Eigen::Vector3d gravity(0.0, 0.0, -1.0);  // half the fake's 2 N rating
  MapMetadata metadata;
  metadata.device_model = "fake:recording";
  metadata.created_utc = "2026-12-07T22:00:00Z";
  metadata.thermal_drift.gain_loss_per_load = 0.3;
  metadata.thermal_drift.points = 3;
  f.device.publishMap(testing::fieldMap(
      WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 3),
      [&](const Eigen::Vector3d&) -> Eigen::Vector3d { return gravity; }, std::move(metadata)));
  const Eigen::Vector3d none = Eigen::Vector3d::Zero();
  f.device.setForce(none);
  EXPECT_EQ(f.fake->last_force, gravity) << "cold motors: the map as it is";
  for (int tick = 0; tick < 10000; ++tick) f.device.setForce(none);
  // Ten time constants: the load settles where the force it sends holds it,
  // L (1 - 0.3 L)^2 = |G|^2 / 4, about 0.305.
  const double load = f.device.thermalLoad();
  EXPECT_NEAR(load * std::pow(1.0 - 0.3 * load, 2), 0.25, 1e-3);
  // The scale follows the load in steps of 1e-4 of load (MapFade::kThermalLoadStep): within
  // 0.3 * 1e-4 / (1 - 0.3 L)^2 of the exact one, 4e-5 N here.
  EXPECT_NEAR(f.fake->last_force.z(), gravity.z() / (1.0 - 0.3 * load), 4e-5);
  EXPECT_GT(f.fake->last_force.norm(), 1.09 * gravity.norm()) << "9 % less torque at 0.3 load";
}

TEST(GravityCompensatedDeviceTest, MotorsWarmFromACalibrationStartAtItsLoadAndCool) {
  CompensationOptions options = optionsWithRamp(0);
  options.motor_time_constant_s = 1.0;
  options.initial_thermal_load = 0.2;
  Fixture f(options);
  EXPECT_EQ(f.device.thermalLoad(), 0.2);
  ASSERT_TRUE(f.device.open());
  for (int tick = 0; tick < 1001; ++tick) f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_NEAR(f.device.thermalLoad(), 0.2 * std::exp(-1.0), 0.002) << "no force: they cool";
}

TEST(GravityCompensatedDeviceTest, AMapWithoutAThermalCorrectionSendsItsValuesWhateverTheLoad) {
  CompensationOptions options = optionsWithRamp(0);
  options.motor_time_constant_s = 0.1;
  Fixture f(options);
  ASSERT_TRUE(f.device.open());
  const Eigen::Vector3d offset(0.0, 0.0, -1.6);
  f.device.publishMap(makeMap(offset));
  for (int tick = 0; tick < 2000; ++tick) f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_NEAR(f.device.thermalLoad(), 0.64, 1e-3);
  EXPECT_EQ(f.fake->last_force, offset);
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
    EXPECT_NEAR(f.device.compensationLevel(), level, 1e-12);
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
  const testing::ScratchFolder folder("gcd");
  const std::string path = folder.file("map.json");
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

TEST(GravityCompensatedDeviceTest, WithinTheMarginTheMapIsExtended) {
  Fixture f;
  f.device.publishMap(makeMap(Eigen::Vector3d::Zero(), Eigen::Matrix3d::Identity()));
  f.fake->position = Eigen::Vector3d(0.059, 0.0, 0.0);  // 9 mm outside, margin 10 mm
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(f.fake->last_force.isApprox(Eigen::Vector3d(0.059, 0.0, 0.0), 1e-12));
  EXPECT_FALSE(f.device.outsideMap());
}

// Outside the map the application's force passes and compensation goes on with the map extended
// linearly for one cell (50 mm here), then held: continuous across the boundary, bounded, and
// reported as a status, never a fault.
TEST(GravityCompensatedDeviceTest, OutsideTheMapTheForcePassesWithTheMapExtendedThenHeld) {
  Fixture f;
  const Eigen::Vector3d offset(0.0, 0.0, -2.0);
  f.device.publishMap(makeMap(offset, Eigen::Matrix3d::Identity()));  // grid: +-0.05 m
  const Eigen::Vector3d wall(-1.5, 0.0, 0.0);
  Eigen::Vector3d previous_force = Eigen::Vector3d::Zero();
  double largest_step_n = 0.0;
  for (int k = 0; k <= 400; ++k) {  // from the centre to 0.35 m outside, 1 mm per tick
    f.fake->position = Eigen::Vector3d(0.001 * k, 0.0, 0.01);
    ASSERT_TRUE(f.device.setForce(wall)) << k;
    const Eigen::Vector3d expected =
        wall + offset + Eigen::Vector3d(std::min(0.001 * k, 0.10), 0.0, 0.01);
    EXPECT_TRUE(f.fake->last_force.isApprox(expected, 1e-12)) << k;
    EXPECT_EQ(f.device.outsideMap(), 0.001 * k > 0.05 + 0.01 + 1e-9) << k;
    if (k > 0)
      largest_step_n = std::max(largest_step_n, (f.fake->last_force - previous_force).norm());
    previous_force = f.fake->last_force;
  }
  EXPECT_LE(largest_step_n, 0.001 + 1e-12);  // the gradient times one 1 mm step: no jump
  EXPECT_EQ(f.device.faultCount(), 0u);
  EXPECT_EQ(f.device.outsideMapTickCount(), 400u - 60u);
  f.fake->position = Eigen::Vector3d(0.0, 0.0, 0.0);
  EXPECT_TRUE(f.device.setForce(wall));
  EXPECT_FALSE(f.device.outsideMap());
  EXPECT_EQ(f.device.compensationLevel(), 1.0);  // never restarted
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

// The frozen-driver rule on a scripted device whose readings never change (see the class
// comment): the push must swing both ways along an axis, past the threshold, for a window.
CompensationOptions frozenOptions() {
  CompensationOptions options = optionsWithRamp(0);
  options.frozen_window_s = 0.1;
  options.frozen_force_floor_n = 0.2;
  return options;
}

// Teaches the decorator a 10 um encoder (threshold max(0.2, 5000 * 3 * 1e-5 / 2) = 0.2 N), then
// holds the reading still.
void learnTenMicrometres(Fixture& f) {
  f.device.setForce(Eigen::Vector3d::Zero());
  f.fake->position.x() += 1e-5;
  f.device.setForce(Eigen::Vector3d::Zero());
  EXPECT_NEAR(f.device.positionResolution_m(), 1e-5, 1e-12);
}

TEST(GravityCompensatedDeviceTest, APushSwingingBothWaysOnFrozenReadingsIsAFrozenDriver) {
  Fixture f(frozenOptions());
  learnTenMicrometres(f);
  int first_fault_tick = -1;
  int released_after_fault = 0;     // ticks after the first fault that sent a force anyway
  for (int k = 1; k <= 400; ++k) {  // +-1 N at 5 Hz
    const bool ok = f.device.setForce(Eigen::Vector3d(std::sin(kTwoPi * 5.0 * k * kPeriod), 0, 0));
    if (!ok && first_fault_tick < 0) first_fault_tick = k;
    const bool sent = ok || f.fake->last_force != Eigen::Vector3d::Zero();
    released_after_fault += first_fault_tick >= 0 && sent ? 1 : 0;
  }
  EXPECT_EQ(released_after_fault, 0);  // stays caught while frozen
  // Up past 0.2 N within the first quarter period, down past -0.2 N in the second half: caught
  // in the third quarter (filter lag included), well within 0.3 s.
  EXPECT_GE(first_fault_tick, 100);
  EXPECT_LE(first_fault_tick, 180);
  EXPECT_EQ(f.device.activeFault(), ServoFault::kStalePosition);
  f.fake->position.x() += 1e-5;  // the readings move again: healthy at once
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(3.0, 0.0, 0.0)));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d(3.0, 0.0, 0.0));
}

TEST(GravityCompensatedDeviceTest, APushThatOnlyChangesInSizeIsNeverAFrozenDriver) {
  Fixture f(frozenOptions());
  learnTenMicrometres(f);
  // Into a stop along -z: 0.5 to 3.5 N, slowly and quickly, with a sideways wobble of 0.4 N.
  for (int k = 1; k <= 5000; ++k) {
    const double t_s = k * kPeriod;
    const Eigen::Vector3d push(0.4 * std::sin(kTwoPi * 3.0 * t_s), 0.0,
                               -2.0 - 1.5 * std::sin(kTwoPi * (k < 2500 ? 0.5 : 8.0) * t_s));
    ASSERT_TRUE(f.device.setForce(push)) << k;
  }
  EXPECT_EQ(f.device.faultCount(), 0u);
}

TEST(GravityCompensatedDeviceTest, AVibrationOnFrozenReadingsIsNeverAFrozenDriver) {
  for (const double frequency_hz : {20.0, 50.0, 120.0, 250.0}) {
    Fixture f(frozenOptions());
    learnTenMicrometres(f);
    for (int k = 1; k <= 3000; ++k) {
      const double vibration_n = 0.5 * std::sin(kTwoPi * frequency_hz * k * kPeriod);
      ASSERT_TRUE(f.device.setForce(Eigen::Vector3d(vibration_n, 0.0, 0.0)))
          << frequency_hz << " Hz, tick " << k;
    }
  }
}

TEST(GravityCompensatedDeviceTest, BeforeAnyStepTheThresholdAssumesACoarseEncoder) {
  Fixture f(frozenOptions());
  // Resolution unknown (1e-4 m): threshold 5000 * 3 * 1e-4 / 2 = 0.75 N. A +-0.6 N swing is no
  // evidence yet, a +-1 N swing is.
  for (int k = 1; k <= 1000; ++k) {
    ASSERT_TRUE(
        f.device.setForce(Eigen::Vector3d(0.6 * std::sin(kTwoPi * 2.0 * k * kPeriod), 0, 0)));
  }
  bool caught = false;
  for (int k = 1; k <= 1000 && !caught; ++k) {
    caught = !f.device.setForce(Eigen::Vector3d(std::sin(kTwoPi * 2.0 * k * kPeriod), 0, 0));
  }
  EXPECT_TRUE(caught);
}

TEST(GravityCompensatedDeviceTest, TheFrozenDriverCheckCanBeTurnedOff) {
  CompensationOptions options = frozenOptions();
  options.frozen_window_s = 0.0;
  Fixture f(options);
  for (int k = 0; k < 1000; ++k) {
    EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(3.0 * std::sin(0.01 * k), 0, 0)));
  }
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
  f.device.setForce(Eigen::Vector3d::Zero());  // the loop runs: every later tick is one period
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

// The new paths: the wall clock, the first map fading in, positions outside the map and a frozen
// driver being caught and healing (caught with the fixed-period clock; with the wall clock the
// loop is too fast for the window, but runs every other path).
TEST(GravityCompensatedDeviceTest, TheServoPathAllocatesNothingOutsideTheMapOrFrozen) {
  for (const bool wall_clock : {true, false}) {
    auto fake = std::make_shared<RecordingDevice>();
    CompensationOptions options;
    if (!wall_clock) options.clock = std::make_shared<FixedPeriodServoClock>(kPeriod);
    options.ramp_duration_s = 0.002;
    GravityCompensatedDevice device(fake, options);
    device.setForce(Eigen::Vector3d::Zero());
    device.publishMap(makeMap(Eigen::Vector3d(0.0, 0.0, -1.0), Eigen::Matrix3d::Identity()));
    testing::AllocationCounter counter;
    for (int k = 0; k < 20000; ++k) {
      if (k % 4000 < 2000) {
        fake->position = Eigen::Vector3d(0.2 * std::sin(0.001 * k), 1e-5 * (k % 7), 0.01);
      }  // else frozen
      device.setForce(Eigen::Vector3d(std::sin(0.05 * k), 0.0, 0.0));
    }
    EXPECT_EQ(counter.count(), 0u) << wall_clock;
    EXPECT_GT(device.outsideMapTickCount(), 0u) << wall_clock;
    // On the fixed-period clock the frozen stretches are long enough to be caught.
    EXPECT_TRUE(wall_clock || device.faultCount(ServoFault::kStalePosition) > 0u) << wall_clock;
  }
}

}  // namespace
}  // namespace autograv
