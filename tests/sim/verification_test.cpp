// verify as a measuring instrument: the residual force it reads is the map's error, not the
// friction and not the history of earlier releases.

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/device/gravity_compensated_device.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/verification.h"

namespace autograv::sim {
namespace {

std::shared_ptr<SimulatedDevice> openDevice(const std::string& name) {
  std::shared_ptr<SimulatedDevice> device = makeSimulatedDevice(name, 5);
  EXPECT_TRUE(device->open());
  EXPECT_TRUE(device->calibrate());
  return device;
}

// The ground truth at the vertices of a grid of the default size (`autograv calibrate`'s), every
// vertex shifted by `bias_n`. On 17 vertices per axis the interpolation error stays under 1 mN;
// on the default 5 it reaches several.
std::shared_ptr<const GravityMap> truthMap(const SimulatedDevice& device,
                                           const Eigen::Vector3d& bias_n, int resolution = 17) {
  const double side_m = 0.8 * 2.0 * device.specifications().workspace_radius_m / std::sqrt(3.0);
  const WorkspaceGrid grid(device.workspaceCenter_m(), side_m, resolution);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    auto& vertex = vertices[static_cast<std::size_t>(i)];
    vertex.gravity_n = device.trueGravity(grid.vertexPosition(i)) + bias_n;
    vertex.outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

VerificationOptions fewPoints(int points) {
  VerificationOptions options;
  options.points = points;
  options.seed = 3;
  options.compare_uncompensated = false;
  return options;
}

class VerificationTest : public ::testing::TestWithParam<std::string> {};

TEST_P(VerificationTest, AMapTenMillinewtonsTooStrongReadsTenMillinewtons) {
  auto device = openDevice(GetParam());
  const Eigen::Vector3d bias_n(0.0, 0.0, 0.010);  // pushes 10 mN too hard, upward
  const VerificationReport report =
      verifyMapOnSimulatedDevice(device, truthMap(*device, bias_n), fewPoints(4));
  ASSERT_EQ(report.ready_points, 4);
  ASSERT_EQ(report.valid_residuals, 4);
  for (const PointVerification& point : report.points) {
    const Eigen::Vector3d residual_n = point.residual.residual_force_n;
    // r = G - G_hat = -bias (plus the grid's interpolation error, under a millinewton).
    EXPECT_NEAR(residual_n.norm(), 0.010, 0.003) << residual_n.transpose();
    EXPECT_NEAR(residual_n.z(), -0.010, 0.003) << residual_n.transpose();
    EXPECT_NEAR(point.truth_error_n, 0.010, 0.001);
    EXPECT_GT(point.residual.holding_friction_n, 0.0);
  }
  const AccuracyReport accuracy = measureAccuracy(*truthMap(*device, bias_n), *device, 200);
  EXPECT_NEAR(accuracy.max_error_n, 0.010, 1e-9) << "the vertices hold the truth plus the bias";
  EXPECT_NEAR(accuracy.rms_residual_n, 0.010, 0.001);
}

TEST_P(VerificationTest, TheTrueFieldReadsNearZero) {
  auto device = openDevice(GetParam());
  const VerificationReport report =
      verifyMapOnSimulatedDevice(device, truthMap(*device, Eigen::Vector3d::Zero()), fewPoints(4));
  ASSERT_EQ(report.valid_residuals, 4);
  EXPECT_LT(report.residual_force_n.max, 0.003);
  EXPECT_LT(report.truth_error_n.max, 0.001);
}

// On a coarse grid the map's own interpolation error is several millinewtons somewhere; what
// verify reads is that error, vector for vector, not zero and not the friction. The probe reads
// it over a few millimetres around the point, where this error changes, and through the arm's
// joint friction, hence the wider tolerance than the constant bias gets.
TEST_P(VerificationTest, TheResidualIsTheMapsErrorOnACoarseGrid) {
  auto device = openDevice(GetParam());
  const VerificationReport report = verifyMapOnSimulatedDevice(
      device, truthMap(*device, Eigen::Vector3d::Zero(), 3), fewPoints(6));
  ASSERT_EQ(report.valid_residuals, 6);
  EXPECT_GT(report.truth_error_n.max, 0.003) << "the grid should be coarse enough to matter";
  for (const PointVerification& point : report.points) {
    const Eigen::Vector3d true_residual_n = point.true_gravity_n - point.map_gravity_n;
    EXPECT_LT((point.residual.residual_force_n - true_residual_n).norm(), 0.005)
        << "measured " << point.residual.residual_force_n.transpose() << ", true "
        << true_residual_n.transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(SimulatedDevices, VerificationTest,
                         ::testing::ValuesIn(simulatedDeviceNames()),
                         [](const auto& info) { return info.param.substr(4); });

// A map far off makes releases fly out of the grid; every later point must still start held
// still at full compensation.
TEST(VerificationHistoryTest, AReleaseThatLeavesTheGridDoesNotSpoilTheNextPoint) {
  auto device = openDevice("sim:omni");
  const Eigen::Vector3d bias_n(0.0, 0.0, 0.2);
  VerificationOptions options = fewPoints(3);
  options.release_s = 2.0;
  const VerificationReport report =
      verifyMapOnSimulatedDevice(device, truthMap(*device, bias_n), options);
  double farthest_m = 0.0;
  for (const PointVerification& point : report.points) {
    farthest_m = std::max(farthest_m, point.release.max_excursion_m);
  }
  EXPECT_GT(farthest_m, 0.5 * truthMap(*device, bias_n)->grid().size_m().minCoeff())
      << "the releases should have left the grid";
  ASSERT_EQ(report.ready_points, 3);
  for (const PointVerification& point : report.points) {
    EXPECT_TRUE(point.residual.valid);
    EXPECT_NEAR(point.residual.residual_force_n.z(), -0.2, 0.01);
    EXPECT_FALSE(point.release.stuck);
  }
}

TEST(VerificationServoPathTest, ProbesAndReleasesAllocateNothing) {
  auto device = openDevice("sim:omega");
  const auto map = truthMap(*device, Eigen::Vector3d::Zero());
  CompensationOptions compensation;
  compensation.ramp_duration_s = 0.0;
  GravityCompensatedDevice decorated(device, compensation);
  decorated.publishMap(map);
  SimulatedTickSource ticks(*device, 1e-3, SimulatedTickSource::Mode::kAsFastAsPossible);
  const Eigen::Vector3d point_m = map->grid().center_m();
  device->resetState(point_m);
  ResidualProbeOptions probe;
  probe.retreat_s = 0.3;
  probe.approach_s = 0.5;

  testing::AllocationCounter counter;
  const ResidualMeasurement residual = measureResidualForce(decorated, ticks, point_m, 0.2, probe);
  const ReleaseMeasurement release = measureRelease(decorated, ticks, 0.2, 1e-4);
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(residual.valid);
  EXPECT_TRUE(release.valid);
}

TEST(VerificationPercentilesTest, MedianNinetiethPercentileAndMaximum) {
  const Percentiles odd = percentiles({3.0, 1.0, 2.0});
  EXPECT_EQ(odd.median, 2.0);
  EXPECT_EQ(odd.p90, 3.0);
  EXPECT_EQ(odd.max, 3.0);
  std::vector<double> ten;
  for (int i = 10; i >= 1; --i) ten.push_back(i);
  const Percentiles even = percentiles(ten);
  EXPECT_EQ(even.median, 5.5);
  EXPECT_EQ(even.p90, 9.0);
  EXPECT_EQ(even.max, 10.0);
  EXPECT_EQ(percentiles({}).max, 0.0);
}

}  // namespace
}  // namespace autograv::sim
