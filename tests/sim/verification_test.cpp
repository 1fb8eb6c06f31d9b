// verify as a measuring instrument: the residual force it reads is the map's error, not the
// friction and not the history of earlier releases; and as a driver of someone's device: it
// carries the device itself, gently, only where the map's workspace says the device can go.

#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/device_specifications.h"
#include "autograv/device/forwarding_device.h"
#include "autograv/device/servo_clock.h"
#include "autograv/maintenance/map_verification.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/vertex_fill.h"
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

// The device's reachable workspace as an exploration would find it, taken from the simulator's
// truth (a test fixture: verify itself never sees the truth): along 26 directions from the
// workspace centre, the distance to the first unreachable point.
ExploredWorkspace truthWorkspace(const SimulatedDevice& device) {
  const Eigen::Vector3d center_m = device.workspaceCenter_m();
  std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(26);
  std::vector<double> radii_m;
  for (const Eigen::Vector3d& u : directions) {
    double inside_m = 0.0;
    double outside_m = 2.0 * device.specifications().workspace_radius_m;
    for (int i = 0; i < 40; ++i) {
      const double middle_m = 0.5 * (inside_m + outside_m);
      (device.isReachable(center_m + middle_m * u) ? inside_m : outside_m) = middle_m;
    }
    radii_m.push_back(inside_m);
  }
  return ExploredWorkspace(center_m, std::move(directions), std::move(radii_m));
}

// The ground truth at the vertices of a grid around the device's workspace, every vertex shifted
// by `bias_n`, the vertices out of reach solved from the others, the workspace saved in the map.
// On 17 vertices per axis the interpolation error stays near a millinewton; on 3, it reaches
// several.
std::shared_ptr<const GravityMap> truthMap(const SimulatedDevice& device,
                                           const Eigen::Vector3d& bias_n, int resolution = 17) {
  const ExploredWorkspace workspace = truthWorkspace(device);
  const WorkspaceGrid grid = gridAroundWorkspace(workspace, Eigen::Vector3i::Constant(resolution));
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    auto& vertex = vertices[static_cast<std::size_t>(i)];
    if (device.isReachable(grid.vertexPosition(i))) {
      vertex.gravity_n = device.trueGravity(grid.vertexPosition(i)) + bias_n;
      vertex.outcome = VertexOutcome::kConverged;
    } else {
      vertex.outcome =
          VertexOutcome::kUnreachable;  // solved from the others, as a calibration does
    }
  }
  fillUnreachableVertices(grid, vertices);
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  metadata.workspace = workspace;
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

VerificationOptions fewPoints(int points) {
  VerificationOptions options;
  options.points = points;
  options.seed = 3;
  options.compare_uncompensated = false;
  options.release.catch_drift_m = 0.003;
  return options;
}

// Heavy (a few minutes of probing per device): tests/run.sh keeps SimulatedDevices/ out of its
// ASan stage.
class VerificationTest : public ::testing::TestWithParam<std::string> {};

TEST_P(VerificationTest, AMapTenMillinewtonsTooStrongReadsTenMillinewtons) {
  auto device = openDevice(GetParam());
  const Eigen::Vector3d bias_n(0.0, 0.0, 0.010);  // pushes 10 mN too hard, upward
  const auto map = truthMap(*device, bias_n);
  const VerificationReport report = verifyMapOnSimulatedDevice(device, map, fewPoints(4));
  ASSERT_EQ(report.ready_points, 4);
  ASSERT_EQ(report.valid_residuals, 4);
  for (const PointVerification& point : report.points) {
    const Eigen::Vector3d residual_n = point.residual.residual_force_n;
    // r = G - G_hat = -bias (plus the grid's interpolation error, about a millinewton).
    EXPECT_NEAR(residual_n.norm(), 0.010, 0.003) << residual_n.transpose();
    EXPECT_NEAR(residual_n.z(), -0.010, 0.003) << residual_n.transpose();
    EXPECT_NEAR(point.truth_error_n, 0.010, 0.002);
    EXPECT_GT(point.residual.holding_friction_n, 0.0);
  }
}

TEST_P(VerificationTest, TheTrueFieldReadsNearZero) {
  auto device = openDevice(GetParam());
  const VerificationReport report =
      verifyMapOnSimulatedDevice(device, truthMap(*device, Eigen::Vector3d::Zero()), fewPoints(4));
  ASSERT_EQ(report.valid_residuals, 4);
  // What the probe reads on a perfect map: encoder counts, cogging, shortened approaches near
  // the stops.
  EXPECT_LT(report.residual_force_n.max, 0.005);
  EXPECT_LT(report.truth_error_n.max, 0.002);
}

// On a coarse grid (3 vertices over the workspace's box) the map's own interpolation error is
// tens of millinewtons; what verify reads is that error, vector for vector, not zero and not the
// friction. The probe reads it over the millimetres around the point its approaches span, where
// this error changes fast (most of all near the stops, where their approaches are shortened),
// and through the arm's joint friction: hence 5 mN plus a tenth of the error.
TEST_P(VerificationTest, TheResidualIsTheMapsErrorOnACoarseGrid) {
  auto device = openDevice(GetParam());
  const VerificationReport report = verifyMapOnSimulatedDevice(
      device, truthMap(*device, Eigen::Vector3d::Zero(), 3), fewPoints(6));
  ASSERT_EQ(report.valid_residuals, 6);
  EXPECT_GT(report.truth_error_n.max, 0.003) << "the grid should be coarse enough to matter";
  for (const PointVerification& point : report.points) {
    const Eigen::Vector3d true_residual_n = point.true_gravity_n - point.map_gravity_n;
    EXPECT_LT((point.residual.residual_force_n - true_residual_n).norm(),
              0.005 + 0.1 * true_residual_n.norm())
        << "measured " << point.residual.residual_force_n.transpose() << ", true "
        << true_residual_n.transpose();
  }
}

// No hand: the simulated hand never takes the stylus; the device carries itself everywhere,
// under the continuous rating but for transients, never at its limit, and nothing is clamped.
// With compensation off the stylus falls, and is caught within a few millimetres.
TEST_P(VerificationTest, TheDeviceCarriesItselfGentlyAndCatchesItsFalls) {
  auto device = openDevice(GetParam());
  VerificationOptions options = fewPoints(4);
  options.compare_uncompensated = true;
  const VerificationReport report =
      verifyMapOnSimulatedDevice(device, truthMap(*device, Eigen::Vector3d::Zero()), options);
  EXPECT_FALSE(device->hand().holding());
  EXPECT_EQ(report.reached_points, 4);
  EXPECT_EQ(report.ready_points, 4);
  EXPECT_EQ(report.caught_releases, 0) << "the true field holds a released stylus still";
  const DeviceSpecifications& specs = device->specifications();
  const double continuous_n = continuousForceRating_n(specs);
  EXPECT_DOUBLE_EQ(report.continuous_force_rating_n, continuous_n);
  EXPECT_LT(report.max_force_sent_n, 0.5 * specs.max_linear_force_n);
  EXPECT_EQ(report.force_limit_ticks, 0u);
  EXPECT_EQ(report.clamp_count, 0u);
  EXPECT_LE(report.seconds_above_continuous_force, 0.05 * report.seconds);
  for (const PointVerification& point : report.points) {
    // Compensation off: it fell (or a joint's friction held it), and the catch kept it within
    // the catch distance plus what the damping needs to stop it.
    EXPECT_LT(point.release_uncompensated.max_excursion_m, 0.003 + 0.003);
    // A caught release went past the catch distance.
    EXPECT_TRUE(!point.release_uncompensated.caught || point.release_uncompensated.drift_m > 0.003)
        << point.release_uncompensated.drift_m;
  }
  EXPECT_GT(report.drift_uncompensated_m.max, 10.0 * report.drift_m.max)
      << "with compensation off the stylus should go much farther";
}

INSTANTIATE_TEST_SUITE_P(SimulatedDevices, VerificationTest,
                         ::testing::ValuesIn(simulatedDeviceNames()),
                         [](const auto& info) { return info.param.substr(4); });

// A device that says nothing of a simulation: verify drives it from driver data alone, and
// reports no truth.
class DriverOnly final : public ForwardingDevice {
 public:
  explicit DriverOnly(std::shared_ptr<HapticDevice> inner) : ForwardingDevice(std::move(inner)) {}
};

TEST(VerificationDriverDataTest, RunsOnADeviceThatIsOnlyADriver) {
  auto simulated = openDevice("sim:omega");
  const auto map = truthMap(*simulated, Eigen::Vector3d(0.0, 0.0, 0.010));
  auto driver = std::make_shared<DriverOnly>(simulated);
  SimulatedTickSource ticks(*simulated, 1e-3, SimulatedTickSource::Mode::kAsFastAsPossible);
  autograv::VerificationOptions options = fewPoints(2);
  options.probe.approaches_per_side = 1;
  options.compensation.clock = std::make_shared<FixedPeriodServoClock>(1e-3);
  const autograv::VerificationReport report = verifyMap(driver, ticks, map, options);
  EXPECT_FALSE(report.has_truth);
  EXPECT_TRUE(report.points_from_workspace);
  ASSERT_EQ(report.valid_residuals, 2);
  for (const PointVerification& point : report.points) {
    EXPECT_NEAR(point.residual.residual_force_n.z(), -0.010, 0.004);
    EXPECT_EQ(point.truth_error_n, 0.0);
  }
  EXPECT_EQ(report.clamp_count, 0u);
  EXPECT_FALSE(simulated->hand().holding());
}

// A map far off makes every compensated release slide away: each is caught within a few
// millimetres, and every later point still starts held still at full compensation.
TEST(VerificationHistoryTest, ACaughtReleaseDoesNotSpoilTheNextPoint) {
  auto device = openDevice("sim:omni");
  const Eigen::Vector3d bias_n(0.0, 0.0, 0.15);  // twice the breakaway force
  VerificationOptions options = fewPoints(3);
  options.probe.approaches_per_side = 1;
  options.release.duration_s = 2.0;
  const VerificationReport report =
      verifyMapOnSimulatedDevice(device, truthMap(*device, bias_n), options);
  ASSERT_EQ(report.ready_points, 3);
  EXPECT_EQ(report.caught_releases, 3);
  for (const PointVerification& point : report.points) {
    EXPECT_TRUE(point.residual.valid);
    EXPECT_NEAR(point.residual.residual_force_n.z(), -0.15, 0.01);
    EXPECT_TRUE(point.release.caught);
    EXPECT_FALSE(point.release.stuck);
    EXPECT_LT(point.release.caught_after_s, 0.5) << "0.15 N too much lifts it at once";
    EXPECT_LT(point.release.max_excursion_m, 0.006);
  }
  EXPECT_EQ(report.force_limit_ticks, 0u);
  EXPECT_EQ(report.clamp_count, 0u);
}

// A map of schema 1 or 2 knows no workspace: its grid's box is sampled, a margin inside; the
// points beyond the stops are found from driver data (the carry is blocked) and skipped, and
// the device never pushes into the stop for long.
TEST(VerificationHistoryTest, AMapWithoutAWorkspaceSkipsThePointsItCannotReach) {
  auto device = openDevice("sim:omni");
  const auto with_workspace = truthMap(*device, Eigen::Vector3d::Zero(), 9);
  MapMetadata metadata = with_workspace->metadata();
  metadata.workspace = ExploredWorkspace();
  const auto map = std::make_shared<const GravityMap>(with_workspace->grid(),
                                                      with_workspace->vertices(), metadata);
  VerificationOptions options = fewPoints(12);
  options.probe.approaches_per_side = 1;
  const VerificationReport report = verifyMapOnSimulatedDevice(device, map, options);
  EXPECT_FALSE(report.points_from_workspace);
  EXPECT_GT(report.unreachable_points, 0) << "the box should poke out of the workspace";
  int agree = 0;
  for (const PointVerification& point : report.points) {
    EXPECT_TRUE(with_workspace->grid().contains(point.point_m));
    if (point.truly_reachable) {
      EXPECT_TRUE(point.reached) << point.point_m.transpose();
    }
    agree += point.reached == point.truly_reachable;
  }
  EXPECT_GE(agree, 11) << "a blocked carry should mean a point out of reach";
  EXPECT_EQ(report.force_limit_ticks, 0u);
  EXPECT_LT(report.max_force_sent_n, device->specifications().max_linear_force_n);
  EXPECT_EQ(report.clamp_count, 0u);
}

TEST(VerificationPointsTest, UniformOverTheWorkspaceAndOutsideTheGridToo) {
  // A workspace of radius 50 mm around the origin, and a grid that covers only its lower half.
  const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(26);
  const ExploredWorkspace workspace(Eigen::Vector3d::Zero(), directions,
                                    std::vector<double>(directions.size(), 0.05));
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, -0.025), Eigen::Vector3d(0.1, 0.1, 0.05),
                           Eigen::Vector3i::Constant(3));
  constexpr int kCount = 4000;
  const std::vector<Eigen::Vector3d> points =
      drawVerificationPoints(grid, workspace, kCount, 7, 0.004);
  ASSERT_EQ(points.size(), static_cast<std::size_t>(kCount));
  std::array<int, 8> octants{};
  int outside_grid = 0;
  for (const Eigen::Vector3d& p : points) {
    EXPECT_TRUE(workspace.contains(p, 0.004)) << p.transpose();
    outside_grid += !grid.contains(p);
    ++octants[static_cast<std::size_t>((p.x() > 0) + 2 * (p.y() > 0) + 4 * (p.z() > 0))];
  }
  // Half the workspace lies above the grid; each octant holds an eighth (4 sigma: 88 points).
  EXPECT_NEAR(outside_grid, kCount / 2, 130);
  for (int count : octants) EXPECT_NEAR(count, kCount / 8, 88);
  // Reaching the boundary: some points lie within 2 mm of the margin.
  int near_boundary = 0;
  for (const Eigen::Vector3d& p : points) near_boundary += workspace.depth_m(p) < 0.006;
  EXPECT_GT(near_boundary, kCount / 20);
  // The same seed gives the same points; another gives others.
  EXPECT_EQ(drawVerificationPoints(grid, workspace, 5, 7, 0.004)[4], points[4]);
  EXPECT_NE(drawVerificationPoints(grid, workspace, 5, 8, 0.004)[4], points[4]);
}

TEST(VerificationPointsTest, WithoutAWorkspaceTheGridsBoxShrunkByTheMargin) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.05, 0.04, 0.03), Eigen::Vector3d(0.1, 0.08, 0.06),
                           Eigen::Vector3i::Constant(3));
  const std::vector<Eigen::Vector3d> points =
      drawVerificationPoints(grid, ExploredWorkspace(), 500, 1, 0.004);
  Eigen::Vector3d low = Eigen::Vector3d::Constant(1.0), high = Eigen::Vector3d::Constant(-1.0);
  for (const Eigen::Vector3d& p : points) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  EXPECT_GE(low.minCoeff(), 0.004);
  EXPECT_LE((Eigen::Vector3d(0.1, 0.08, 0.06) - high).maxCoeff(), 0.006);
  EXPECT_GE((Eigen::Vector3d(0.1, 0.08, 0.06) - high).minCoeff(), 0.004);
  EXPECT_THROW(drawVerificationPoints(grid, ExploredWorkspace(), 5, 1, 0.031), Error);
  EXPECT_THROW(drawVerificationPoints(grid, ExploredWorkspace(), 0, 1, 0.004), Error);
}

TEST(VerificationServoPathTest, CarriesProbesAndReleasesAllocateNothing) {
  auto device = openDevice("sim:omega");
  const auto map = truthMap(*device, Eigen::Vector3d(0.0, 0.0, 0.1));
  CompensationOptions compensation;
  compensation.ramp_duration_s = 0.0;
  GravityCompensatedDevice decorated(device, compensation);
  decorated.publishMap(map);
  SimulatedTickSource ticks(*device, 1e-3, SimulatedTickSource::Mode::kAsFastAsPossible);
  const Eigen::Vector3d point_m = map->metadata().workspace.center_m();
  device->resetState(point_m + Eigen::Vector3d(0.01, 0.0, 0.0));
  ResidualProbeOptions probe;
  probe.retreat_s = 0.3;
  probe.approach_s = 0.5;
  probe.keep_inside = map->metadata().workspace;
  probe.limit.max_effort_n = 0.3;
  CarryOptions carry;
  carry.keep_inside = map->metadata().workspace;
  ReleaseOptions release;
  release.duration_s = 0.5;
  release.catch_drift_m = 0.002;
  release.catch_inside = map->metadata().workspace;

  testing::AllocationCounter counter;
  const CarryOutcome carried = carryTo(decorated, ticks, point_m, 0.2, carry);
  const ResidualMeasurement residual = measureResidualForce(decorated, ticks, point_m, 0.2, probe);
  // 0.1 N too much compensation: the release rises and is caught.
  const ReleaseMeasurement released = measureRelease(decorated, ticks, release);
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(carried.reached);
  EXPECT_TRUE(residual.valid);
  EXPECT_TRUE(released.valid);
  EXPECT_TRUE(released.caught);
}

TEST(VerificationCarryTest, ABlockedPathStopsWithinAFewMillimetresOfTheStop) {
  auto device = openDevice("sim:omni");
  const auto map = truthMap(*device, Eigen::Vector3d::Zero(), 9);
  CompensationOptions compensation;
  compensation.ramp_duration_s = 0.0;
  compensation.clock = std::make_shared<FixedPeriodServoClock>(1e-3);
  GravityCompensatedDevice decorated(device, compensation);
  decorated.publishMap(map);
  SimulatedTickSource ticks(*device, 1e-3, SimulatedTickSource::Mode::kAsFastAsPossible);
  const ExploredWorkspace& workspace = map->metadata().workspace;
  const Eigen::Vector3d center_m = workspace.center_m();
  device->resetState(center_m);
  // Straight down, 5 cm beyond the stop, with no workspace to keep the path in.
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d beyond_m = center_m + (workspace.boundaryDistance_m(down) + 0.05) * down;
  CarryOptions carry;
  carry.limit.max_effort_n = 0.3;
  const CarryOutcome outcome = carryTo(decorated, ticks, beyond_m, 0.05, carry);
  EXPECT_FALSE(outcome.reached);
  EXPECT_TRUE(outcome.read_ok);
  EXPECT_TRUE(device->endStopHit()) << "it went down to the stop";
  EXPECT_LT(outcome.seconds, 3.0) << "the stop is recognised, not pushed against";
  // It ends held just off where the stop held it: the force beyond compensation is what holds a
  // still end-effector against friction, nothing that presses on.
  Eigen::Vector3d at_m;
  ASSERT_TRUE(decorated.getPosition(at_m));
  const Eigen::Vector3d pressing_n = device->appliedForce_n() - map->gravityAt(at_m);
  EXPECT_LT(pressing_n.norm(), 0.078) << "at most the breakaway force; " << pressing_n.transpose();
  EXPECT_EQ(decorated.clampCount(), 0u);
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
