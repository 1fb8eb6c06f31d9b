// The decorator on the simulated devices: a map of the ground-truth gravity at the vertices of a
// 5x5x5 grid must hold a released end-effector far better than no compensation, without ever
// commanding more than the device's maximum force, and the simulated drivers' faults must reach
// the actuators as zero force.

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/forwarding_device.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/simulated_driver.h"
#include "field_map.h"

namespace autograv {
namespace {

constexpr double kPeriod = 1e-3;
constexpr double kTwoPi = 6.283185307179586;

// The simulation advances one period per tick: the decorator's clock must follow it, not the
// wall clock.
CompensationOptions simulatedTime() {
  CompensationOptions options;
  options.clock = std::make_shared<FixedPeriodServoClock>(kPeriod);
  return options;
}

std::shared_ptr<sim::SimulatedDevice> openDevice(const std::string& name) {
  std::shared_ptr<sim::SimulatedDevice> device = sim::makeSimulatedDevice(name, 3);
  EXPECT_TRUE(device->open());
  EXPECT_TRUE(device->calibrate());
  return device;
}

// The grid `autograv calibrate` uses by default (80 % of the cube inscribed in the workspace
// sphere, 5 per axis), holding the true gravity at every vertex: the best map a calibration
// could produce on that grid.
std::shared_ptr<const GravityMap> truthMap(const sim::SimulatedDevice& device) {
  const double side_m = 0.8 * 2.0 * device.specifications().workspace_radius_m / std::sqrt(3.0);
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  return testing::fieldMap(
      WorkspaceGrid(device.workspaceCenter_m(), side_m, 5),
      [&device](const Eigen::Vector3d& x) { return device.trueGravity(x); }, std::move(metadata));
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Releases the end-effector at rest at `start_m` with zero application force for 1 s.
double drift_m(sim::SimulatedDevice& simulated, HapticDevice& device,
               const Eigen::Vector3d& start_m, double& max_force_n) {
  // A force reaches the actuators one servo period after setForce: send this run's first command
  // there before the end-effector is put at rest, so that the last run's is not still acting.
  Eigen::Vector3d position;
  simulated.resetState(start_m);
  device.getPosition(position);
  device.setForce(Eigen::Vector3d::Zero());
  simulated.advance(kPeriod);
  simulated.resetState(start_m);
  simulated.hand().release();
  for (int k = 0; k < 1000; ++k) {
    device.getPosition(position);
    device.setForce(Eigen::Vector3d::Zero());
    max_force_n = std::max(max_force_n, simulated.appliedForce_n().norm());
    simulated.advance(kPeriod);
  }
  return (simulated.truePosition_m() - start_m).norm();
}

class ReleaseTest : public ::testing::TestWithParam<const char*> {};

TEST_P(ReleaseTest, ATruthMapHoldsTheEndEffectorTenTimesBetterThanNothing) {
  auto simulated = openDevice(GetParam());
  const auto map = truthMap(*simulated);
  CompensationOptions options = simulatedTime();
  options.ramp_duration_s = 0.0;
  GravityCompensatedDevice decorated(simulated, options);
  decorated.publishMap(map);

  sim::Random random(11);
  std::vector<double> on;
  std::vector<double> off;
  double max_force_on_n = 0.0;
  double max_force_off_n = 0.0;
  const WorkspaceGrid& grid = map->grid();
  for (int i = 0; i < 20; ++i) {
    Eigen::Vector3d start;
    for (int axis = 0; axis < 3; ++axis) {
      start[axis] = grid.minCorner_m()[axis] + random.uniform() * grid.size_m()[axis];
    }
    on.push_back(drift_m(*simulated, decorated, start, max_force_on_n));
    off.push_back(drift_m(*simulated, *simulated, start, max_force_off_n));
  }
  RecordProperty("drift_median_mm", std::to_string(median(on) * 1e3));
  RecordProperty("drift_off_median_mm", std::to_string(median(off) * 1e3));
  EXPECT_GT(median(off), 0.01) << "without compensation the end-effector must fall";
  EXPECT_LE(median(on), 0.1 * median(off))
      << "on " << median(on) * 1e3 << " mm, off " << median(off) * 1e3 << " mm";
  EXPECT_LE(max_force_on_n, simulated->specifications().max_linear_force_n);
  EXPECT_EQ(max_force_off_n, 0.0);
  EXPECT_EQ(decorated.faultCount(), 0u) << toString(decorated.lastFault());
  EXPECT_EQ(decorated.clampCount(), 0u);
}

INSTANTIATE_TEST_SUITE_P(SimulatedDevices, ReleaseTest,
                         ::testing::Values("sim:omega", "sim:omni", "sim:falcon"),
                         [](const auto& info) {
                           return std::string(info.param).substr(4);  // "omega", "omni", ...
                         });

// A simulated driver's faults never reach the actuators: zero force, a fault the application can
// read, and compensation back (ramping) once the driver heals.
TEST(GravityCompensatedDeviceSimTest, DriverFaultsSendZeroForce) {
  struct Case {
    sim::DeviceFault injected;
    ServoFault expected;
  };
  for (const Case& c : {Case{sim::DeviceFault::kNanPosition, ServoFault::kNonFinitePosition},
                        Case{sim::DeviceFault::kStopsAnswering, ServoFault::kReadFailed}}) {
    auto simulated = openDevice("sim:omni");
    const auto map = truthMap(*simulated);
    CompensationOptions options = simulatedTime();
    options.ramp_duration_s = 0.05;
    GravityCompensatedDevice decorated(simulated, options);
    decorated.publishMap(map);
    simulated->resetState(map->grid().center_m());
    simulated->hand().grab(map->grid().center_m());
    Eigen::Vector3d position;
    for (int k = 0; k < 100; ++k) {
      decorated.getPosition(position);
      EXPECT_TRUE(decorated.setForce(Eigen::Vector3d::Zero()));
      simulated->advance(kPeriod);
    }
    EXPECT_GT(simulated->appliedForce_n().norm(), 0.1);
    simulated->injectFault(c.injected);
    for (int k = 0; k < 10; ++k) {
      decorated.getPosition(position);
      EXPECT_FALSE(decorated.setForce(Eigen::Vector3d::Zero()));
      simulated->advance(kPeriod);
    }
    EXPECT_EQ(decorated.activeFault(), c.expected);
    if (c.injected != sim::DeviceFault::kStopsAnswering) {
      EXPECT_EQ(simulated->appliedForce_n(), Eigen::Vector3d::Zero());
    }
    simulated->injectFault(sim::DeviceFault::kNone);
    decorated.getPosition(position);
    EXPECT_TRUE(decorated.setForce(Eigen::Vector3d::Zero()));
    simulated->advance(kPeriod);
    EXPECT_NEAR(decorated.compensationLevel(), 0.02, 1e-12);  // 1 of 50 ramp ticks
  }
}

// --- On every simulated device: the application in the whole workspace ---------------------

/// Forwards to a simulated device and keeps the force last commanded: what the decorator sent,
/// before the simulated actuators' delay, quantization and saturation.
class CommandRecorder final : public ForwardingDevice {
 public:
  explicit CommandRecorder(std::shared_ptr<sim::SimulatedDevice> device)
      : ForwardingDevice(std::move(device)) {}
  bool setForce(const Eigen::Vector3d& force_n) override {
    last_force_n = force_n;
    return ForwardingDevice::setForce(force_n);
  }
  Eigen::Vector3d last_force_n = Eigen::Vector3d::Constant(NAN);
};

class SimulatedDeviceTest : public ::testing::TestWithParam<std::string> {
 protected:
  void SetUp() override {
    simulated_ = openDevice(GetParam());
    recorder_ = std::make_shared<CommandRecorder>(simulated_);
    map_ = truthMap(*simulated_);
    CompensationOptions options = simulatedTime();
    options.ramp_duration_s = 0.1;
    decorated_ = std::make_unique<GravityCompensatedDevice>(recorder_, options);
    decorated_->publishMap(map_);
    simulated_->resetState(map_->grid().center_m());
    simulated_->hand().grab(map_->grid().center_m());
  }

  /// One servo tick of an application rendering `force_n`; returns setForce's answer and the
  /// position the application read.
  bool tick(const Eigen::Vector3d& force_n, Eigen::Vector3d& position_m) {
    decorated_->getPosition(position_m);
    const bool ok = decorated_->setForce(force_n);
    simulated_->advance(kPeriod);
    if (position_m == last_position_m_) {
      ++still_ticks_;
      longest_still_ticks_ = std::max(longest_still_ticks_, still_ticks_);
    } else {
      still_ticks_ = 0;
    }
    last_position_m_ = position_m;
    return ok;
  }

  /// Runs `seconds` of an application whose force depends on time only; false on the first fault.
  bool run(double seconds, const std::function<Eigen::Vector3d(double)>& force_at_s) {
    Eigen::Vector3d position_m;
    const int ticks = static_cast<int>(std::lround(seconds / kPeriod));
    for (int k = 0; k < ticks; ++k) {
      if (!tick(force_at_s(k * kPeriod), position_m)) return false;
    }
    return true;
  }

  std::shared_ptr<sim::SimulatedDevice> simulated_;
  std::shared_ptr<CommandRecorder> recorder_;
  std::shared_ptr<const GravityMap> map_;
  std::unique_ptr<GravityCompensatedDevice> decorated_;
  Eigen::Vector3d last_position_m_ = Eigen::Vector3d::Constant(NAN);
  int still_ticks_ = 0;
  int longest_still_ticks_ = 0;  ///< Longest run of bit-identical readings. Unit: [ticks]
};

// A hand carries the end-effector 25 mm beyond the map through a 1.5 N wall the application
// renders there: the wall's force plus the boundary's compensation are commanded to the device on
// every tick, and "outside" is a status, not a fault.
TEST_P(SimulatedDeviceTest, AWallOutsideTheMapReachesTheDeviceOnEveryTick) {
  ASSERT_TRUE(run(0.2, [](double) { return Eigen::Vector3d::Zero(); }));  // the map fades in
  ASSERT_TRUE(decorated_->latestMapInUse());
  const WorkspaceGrid& grid = map_->grid();
  const double wall_x_m = grid.minCorner_m().x() + grid.size_m().x();  // the map's +x face
  Eigen::Vector3d goal_m = grid.center_m();
  goal_m.x() = wall_x_m + 0.027;  // the hand's spring gives ~2 mm to the wall's 1.5 N
  simulated_->hand().moveTo(goal_m, 0.05);
  Eigen::Vector3d position_m;
  double farthest_outside_m = 0.0;
  int outside_ticks = 0;
  for (int k = 0; k < 2500; ++k) {
    decorated_->getPosition(position_m);
    const Eigen::Vector3d wall_n(position_m.x() > wall_x_m ? -1.5 : 0.0, 0.0, 0.0);
    ASSERT_TRUE(decorated_->setForce(wall_n)) << GetParam() << " tick " << k;
    const double level = decorated_->compensationLevel();
    const Eigen::Vector3d expected_n = wall_n + level * map_->gravityAt(position_m);
    ASSERT_TRUE(recorder_->last_force_n.isApprox(expected_n, 1e-9))
        << GetParam() << " tick " << k << ": sent " << recorder_->last_force_n.transpose()
        << ", expected " << expected_n.transpose();
    farthest_outside_m = std::max(farthest_outside_m, position_m.x() - wall_x_m);
    if (decorated_->outsideMap()) ++outside_ticks;
    simulated_->advance(kPeriod);
  }
  EXPECT_GE(farthest_outside_m, 0.020) << GetParam();
  EXPECT_LE(farthest_outside_m, 0.030) << GetParam();
  EXPECT_GT(outside_ticks, 500) << GetParam();
  EXPECT_EQ(decorated_->outsideMapTickCount(), static_cast<std::uint64_t>(outside_ticks));
  EXPECT_EQ(decorated_->faultCount(), 0u) << toString(decorated_->lastFault());
  EXPECT_EQ(decorated_->compensationLevel(), 1.0);
}

// A hand gripping at human stiffness while the application plays a vibration: the readings may
// stay still for long stretches, yet that is no frozen driver.
TEST_P(SimulatedDeviceTest, AHandGrippingThroughAVibrationIsNoFrozenDriver) {
  int longest_still_ticks = 0;
  for (const double stiffness_n_per_m : {500.0, 3000.0}) {
    for (const double frequency_hz : {20.0, 70.0, 250.0}) {
      SetUp();
      simulated_->hand().stiffness_n_per_m = stiffness_n_per_m;
      const bool ok = run(1.5, [&](double t_s) {
        return Eigen::Vector3d(0.5 * std::sin(kTwoPi * frequency_hz * t_s), 0.0, 0.0);
      });
      EXPECT_TRUE(ok) << GetParam() << " " << stiffness_n_per_m << " N/m, " << frequency_hz
                      << " Hz: " << toString(decorated_->lastFault());
      longest_still_ticks = std::max(longest_still_ticks, longest_still_ticks_);
    }
  }
  RecordProperty("longest_still_ticks", longest_still_ticks);
}

// Released, pushed into its end stop by a force that changes (1.5 +- 1 N at 1 Hz, and +-0.5 N at
// 30 Hz on top): still, but not frozen.
TEST_P(SimulatedDeviceTest, RestingOnTheEndStopUnderAChangingForceIsNoFrozenDriver) {
  simulated_->hand().release();
  const bool ok = run(3.0, [](double t_s) {
    const double push_n = 1.5 + std::sin(kTwoPi * 1.0 * t_s) + 0.5 * std::sin(kTwoPi * 30.0 * t_s);
    return Eigen::Vector3d(push_n, 0.0, 0.0);
  });
  EXPECT_TRUE(ok) << GetParam() << ": " << toString(decorated_->lastFault());
  EXPECT_TRUE(simulated_->endStopHit()) << GetParam();
  RecordProperty("longest_still_ticks", longest_still_ticks_);
}

// A driver whose readings stop while the end-effector is free and the application's force keeps
// changing (+-1 N at 5 Hz) is caught within 0.3 s, and the actuators get zero.
TEST_P(SimulatedDeviceTest, AFrozenDriverOnAFreeDeviceIsCaughtWithin300Ms) {
  const auto force_at_s = [](double t_s) {
    return Eigen::Vector3d(std::sin(kTwoPi * 5.0 * t_s), 0.0, 0.0);
  };
  ASSERT_TRUE(run(0.3, force_at_s));  // held while compensation ramps in
  simulated_->hand().release();
  ASSERT_TRUE(run(0.2, force_at_s)) << GetParam() << ": a free device is no frozen driver";
  simulated_->injectFault(sim::DeviceFault::kFrozenPosition);
  Eigen::Vector3d position_m;
  int caught_tick = -1;
  for (int k = 0; k < 1000 && caught_tick < 0; ++k) {
    if (!tick(force_at_s(0.5 + k * kPeriod), position_m)) caught_tick = k;
  }
  EXPECT_GE(caught_tick, 100) << GetParam();  // frozen_window_s
  EXPECT_LE(caught_tick, 300) << GetParam();
  EXPECT_EQ(decorated_->activeFault(), ServoFault::kStalePosition);
  EXPECT_EQ(recorder_->last_force_n, Eigen::Vector3d::Zero());
  RecordProperty("caught_after_ms", caught_tick);
}

INSTANTIATE_TEST_SUITE_P(AllSimulatedDevices, SimulatedDeviceTest,
                         ::testing::ValuesIn(sim::simulatedDeviceNames()),
                         [](const auto& info) { return info.param.substr(4); });

}  // namespace
}  // namespace autograv
