// A session of application use: the scripted hand and scene, and the scores of a map of the
// device's own field while its motors do not warm, and while they do.
#include "autograv/sim/session_workload.h"

#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/sim/procedures.h"
#include "field_map.h"

namespace autograv::sim {
namespace {

/// The device's field at the vertices of a 9x9x9 grid over its workspace: as right as a map on
/// that grid can be.
std::shared_ptr<const GravityMap> truthMap(const SimulatedDevice& device) {
  const WorkspaceFit fit = fitGridToDevice(device);
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  return testing::fieldMap(
      WorkspaceGrid(fit.center_m, fit.size_m, Eigen::Vector3i::Constant(9)),
      [&device](const Eigen::Vector3d& at_m) { return device.trueGravity(at_m); }, metadata);
}

SessionWorkloadOptions threeMinutes() {
  SessionWorkloadOptions options;
  options.minutes = 3.0;
  options.field_samples = 4000;
  return options;
}

TEST(SessionWorkloadTest, OnMotorsThatNeverWarmTheScoreNeverMoves) {
  auto device = makeSimulatedDevice("sim:omega", 2);
  device->open();
  device->resetState(device->workspaceCenter_m());
  const auto map = truthMap(*device);
  int calls = 0;
  const SessionWorkloadResult result =
      runSessionWorkload(*device, map, threeMinutes(), [&calls](const SessionSample&) { ++calls; });
  ASSERT_EQ(result.samples.size(), 4u);  // minutes 0, 1, 2 and 3
  EXPECT_EQ(calls, 4);
  EXPECT_NEAR(result.samples.back().minute, 3.0, 1e-6);
  for (const SessionSample& sample : result.samples) {
    EXPECT_EQ(sample.field.p90_rel, result.samples.front().field.p90_rel);
    EXPECT_EQ(sample.lowest_gain_factor, 1.0);
  }
  EXPECT_LT(result.samples.front().field.p90_rel, 0.002);
  // The hand let go and the scene pushed, and the compensated stylus never needed the limit.
  EXPECT_GE(result.releases, 3u);
  EXPECT_GE(result.contacts, 1u);
  EXPECT_EQ(result.force_limit_ticks, 0u);
  EXPECT_GT(result.samples.back().path_p90_rel, 0.0);
}

TEST(SessionWorkloadTest, OnMotorsThatWarmTheSameMapDriftsAsTheWindingsHeat) {
  SimulatedUnit unit;
  unit.thermal.enabled = true;
  auto device = makeSimulatedDevice("sim:omega", 2, FrictionLevel::kTypical, unit);
  device->open();
  device->resetState(device->workspaceCenter_m());
  const auto map = truthMap(*device);  // made while the motors are at the reference
  const SessionWorkloadResult result = runSessionWorkload(*device, map, threeMinutes());
  ASSERT_EQ(result.samples.size(), 4u);
  const SessionSample& first = result.samples.front();
  const SessionSample& last = result.samples.back();
  EXPECT_DOUBLE_EQ(first.hottest_winding_c, unit.thermal.ambient_c);
  EXPECT_GT(last.hottest_winding_c, unit.thermal.ambient_c + 2.0);
  EXPECT_LT(last.lowest_gain_factor, 1.0);
  EXPECT_GT(last.field.p90_rel, first.field.p90_rel + 0.0005);
}

TEST(SessionWorkloadTest, RefusesASessionItCannotRun) {
  auto device = makeSimulatedDevice("sim:omega", 2);
  device->open();
  const auto map = truthMap(*device);
  SessionWorkloadOptions options = threeMinutes();
  options.minutes = 0.0;
  EXPECT_THROW(runSessionWorkload(*device, map, options), Error);
  EXPECT_THROW(runSessionWorkload(*device, nullptr, threeMinutes()), Error);
  device->injectFault(DeviceFault::kStopsAnswering);
  EXPECT_THROW(runSessionWorkload(*device, map, threeMinutes()), Error);
}

}  // namespace
}  // namespace autograv::sim
