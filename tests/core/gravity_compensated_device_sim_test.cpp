// The decorator on the simulated devices: a map of the ground-truth gravity at the vertices of a
// 5x5x5 grid must hold a released end-effector far better than no compensation, without ever
// commanding more than the device's maximum force, and the simulated drivers' faults must reach
// the actuators as zero force.

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/device/gravity_compensated_device.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv {
namespace {

constexpr double kPeriod = 1e-3;

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
  const WorkspaceGrid grid(device.workspaceCenter_m(), side_m, 5);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n = device.trueGravity(grid.vertexPosition(i));
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
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
  CompensationOptions options;
  options.servo_period_s = kPeriod;
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
      start[axis] = grid.minCorner_m()[axis] + random.uniform() * grid.side_m();
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
    CompensationOptions options;
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

TEST(GravityCompensatedDeviceSimTest, AFrozenDriverUnderAChangingForceIsCaught) {
  auto simulated = openDevice("sim:omega");
  CompensationOptions options;
  options.stale_tick_limit = 100;
  options.stale_force_change_n = 0.5;
  GravityCompensatedDevice decorated(simulated, options);
  decorated.publishMap(truthMap(*simulated));
  simulated->resetState(simulated->workspaceCenter_m());
  simulated->hand().grab(simulated->workspaceCenter_m());
  Eigen::Vector3d position;
  for (int k = 0; k < 600; ++k) {  // ramp in, with the hand holding
    decorated.getPosition(position);
    decorated.setForce(Eigen::Vector3d::Zero());
    simulated->advance(kPeriod);
  }
  EXPECT_EQ(decorated.faultCount(), 0u);
  simulated->injectFault(sim::DeviceFault::kFrozenPosition);
  int fault_tick = -1;
  for (int k = 0; k < 400 && fault_tick < 0; ++k) {
    decorated.getPosition(position);
    // An application rendering a growing force (a spring being stretched, say).
    if (!decorated.setForce(Eigen::Vector3d(0.0, 0.005 * k, 0.0))) fault_tick = k;
    simulated->advance(kPeriod);
  }
  EXPECT_GT(fault_tick, 100);
  EXPECT_LE(fault_tick, 102);
  EXPECT_EQ(decorated.activeFault(), ServoFault::kStalePosition);
  EXPECT_EQ(simulated->appliedForce_n(), Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace autograv
