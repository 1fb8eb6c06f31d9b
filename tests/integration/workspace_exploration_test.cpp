// The workspace exploration on the simulated devices: how close the explored boundary comes to
// what the device really reaches (ground truth, for scoring only), and what it costs the device.
#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/simulated_device.h"

namespace autograv {
namespace {

// Distance from `center_m` along `u` to the last reachable point, in 0.5 mm steps.
double trueReach_m(const sim::SimulatedDevice& device, const Eigen::Vector3d& center_m,
                   const Eigen::Vector3d& u) {
  double reach = 0.0;
  for (double t = 0.0; t < 0.3; t += 5e-4) {
    if (!device.isReachable(center_m + t * u)) break;
    reach = t;
  }
  return reach;
}

// Opens `name`, initializes it at its workspace's centre with the simulated hand and explores it
// with `options`; `device` keeps the simulation for scoring.
void exploreFromTheCentre(const std::string& name, sim::FrictionLevel friction,
                          const WorkspaceExplorer::Options& options,
                          std::unique_ptr<sim::SimulatedDevice>& device,
                          sim::ExplorationResult& result) {
  device = sim::makeSimulatedDevice(name, 1, friction);
  ASSERT_TRUE(device->open() && device->calibrate());
  EstimationParameters parameters;
  parameters.k0_n_per_m = defaultInitializationStiffness(device->specifications());
  const sim::InitializationResult init =
      sim::initializeWithSimulatedHand(*device, parameters, device->workspaceCenter_m());
  ASSERT_TRUE(init.ok) << init.message;
  result = sim::exploreWorkspace(*device, parameters, init, options);
  ASSERT_FALSE(result.workspace.empty());
}

// Every simulated device at typical and at high friction: at high friction the initialization
// leaves G_hat_0 off by about 0.1 N on sim:omni, and static friction holds the end-effector at
// the start of the first probes.
class WorkspaceExplorationTest
    : public ::testing::TestWithParam<std::tuple<std::string, sim::FrictionLevel>> {};

TEST_P(WorkspaceExplorationTest, FindsTheStopsGentlyAndQuickly) {
  // The radial probes (the boundary probes after them: BoundaryProbeTest).
  WorkspaceExplorer::Options radial_only;
  radial_only.boundary_directions = 0;
  std::unique_ptr<sim::SimulatedDevice> device;
  sim::ExplorationResult result;
  ASSERT_NO_FATAL_FAILURE(exploreFromTheCentre(std::get<0>(GetParam()), std::get<1>(GetParam()),
                                               radial_only, device, result));
  const ExploredWorkspace& workspace = result.workspace;
  std::vector<double> errors;
  for (std::size_t i = 0; i < workspace.directions().size(); ++i) {
    const Eigen::Vector3d& u = workspace.directions()[i];
    errors.push_back(workspace.radii_m()[i] - trueReach_m(*device, workspace.center_m(), u));
  }
  std::sort(errors.begin(), errors.end());
  const double median_m = errors[errors.size() / 2];
  RecordProperty("reach_error_median_mm", std::to_string(median_m * 1e3));
  RecordProperty("reach_error_max_mm", std::to_string(errors.back() * 1e3));
  RecordProperty("exploration_s", std::to_string(result.seconds));
  // Every direction ends at the stop: within a few millimetres of where the device really stops
  // (a rubber stop yields to the probe a little; the soft joint limits of the arms more: the
  // 60 mm/s probe sinks a median 2.1-2.2 mm into sim:falcon's, 1.8 mm at 40 mm/s).
  EXPECT_NEAR(median_m, 0.0, 2.5e-3);
  EXPECT_GT(errors.front(), -3e-3);
  EXPECT_LT(errors.back(), 8e-3);
  // Gently: recognised within 100 ms, never at the force limit, almost never above the
  // continuous rating, and in well under a minute.
  EXPECT_LE(result.longest_recognition_s, 0.1);
  EXPECT_EQ(result.saturation_count, 0u);
  EXPECT_LT(result.peak_force_n, 0.9 * device->specifications().max_linear_force_n);
  EXPECT_LT(result.seconds_above_continuous_force, 0.05 * result.seconds);
  EXPECT_LT(result.seconds, 60.0);
}

INSTANTIATE_TEST_SUITE_P(
    SimulatedDevices, WorkspaceExplorationTest,
    ::testing::Combine(::testing::Values("sim:omega", "sim:omni", "sim:falcon"),
                       ::testing::Values(sim::FrictionLevel::kTypical, sim::FrictionLevel::kHigh)),
    [](const auto& info) {
      return std::get<0>(info.param).substr(4) + "_" + toString(std::get<1>(info.param));
    });

TEST(InitializationClearanceTest, AnInitializationOnAStopIsRefusedFromDriverDataAlone) {
  // The hand lets go 1 mm above sim:omega's lower stop: the end-effector settles on it.
  auto device = sim::makeSimulatedDevice("sim:omega", 1, sim::FrictionLevel::kTypical);
  ASSERT_TRUE(device->open() && device->calibrate());
  sim::CalibrationRunOptions run;
  run.parameters.k0_n_per_m = defaultInitializationStiffness(device->specifications());
  run.grid_from_workspace = true;
  const double radius_m = device->specifications().workspace_radius_m;
  run.initialization_center_m =
      device->workspaceCenter_m() - Eigen::Vector3d(0.0, 0.0, radius_m - 0.001);
  try {
    sim::runSimulatedCalibration(*device, run);
    FAIL() << "a calibration initialized on a stop ran";
  } catch (const Error& error) {
    // The exploration's probes met the stop right under the settled point.
    const std::string message = error.what();
    EXPECT_NE(message.find("from a stop the exploration found"), std::string::npos) << message;
  }
  // Where the exploration saw room all round, nothing is said.
  const ExploredWorkspace roomy(Eigen::Vector3d::Zero(), ExploredWorkspace::probeDirections(26),
                                std::vector<double>(26, 0.05));
  EXPECT_TRUE(initializationClearanceProblem(roomy, Eigen::Vector3d::Zero()).empty());
  EXPECT_FALSE(initializationClearanceProblem(roomy, Eigen::Vector3d(0.0, 0.0, -0.047)).empty());
  EXPECT_TRUE(initializationClearanceProblem(ExploredWorkspace{}, Eigen::Vector3d::Zero()).empty());
}

// Share of `samples` reachable points (uniform, seeded) that lie more than 2 mm beyond the
// explored boundary: where the map can only extrapolate.
double shareBeyondBoundary(const sim::SimulatedDevice& device, const ExploredWorkspace& workspace,
                           int samples) {
  std::mt19937_64 random(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double half_box_m = 2.0 * device.specifications().workspace_radius_m;
  int reachable = 0;
  int beyond = 0;
  while (reachable < samples) {
    const Eigen::Vector3d point =
        device.workspaceCenter_m() +
        half_box_m * Eigen::Vector3d(unit(random), unit(random), unit(random));
    if (!device.isReachable(point)) continue;
    ++reachable;
    if (workspace.depth_m(point) < -2e-3) ++beyond;
  }
  return static_cast<double>(beyond) / samples;
}

TEST(BoundaryProbeTest, BoundaryProbesFollowTheCornersBetweenTheRadialStops) {
  // sim:omni's workspace is a slab of a spherical shell: the radial stops' triangles cut its
  // corners. The boundary probes start just inside those triangles and find the stops beyond.
  const auto explore = [](int boundary_directions, sim::ExplorationResult& result,
                          std::unique_ptr<sim::SimulatedDevice>& device) {
    WorkspaceExplorer::Options options;
    options.boundary_directions = boundary_directions;
    options.boundary_candidates = 50;  // every candidate of a 50-direction spread
    options.boundary_bulge_m = 0.0;
    exploreFromTheCentre("sim:omni", sim::FrictionLevel::kTypical, options, device, result);
  };
  std::unique_ptr<sim::SimulatedDevice> radial_device, refined_device;
  sim::ExplorationResult radial, refined;
  ASSERT_NO_FATAL_FAILURE(explore(0, radial, radial_device));
  ASSERT_NO_FATAL_FAILURE(explore(50, refined, refined_device));
  ASSERT_EQ(radial.workspace.directions().size(), 26u);
  // The 50-direction spread less the few that repeat a radial direction.
  EXPECT_GT(refined.workspace.directions().size(), 60u);
  // The radial directions come first and find the same stops.
  for (std::size_t i = 0; i < 26; ++i) {
    EXPECT_NEAR(refined.workspace.radii_m()[i], radial.workspace.radii_m()[i], 1e-4) << i;
  }
  // Every boundary probe ends at the stop too, as gently as the radial ones.
  std::vector<double> errors;
  for (std::size_t i = 26; i < refined.workspace.directions().size(); ++i) {
    const Eigen::Vector3d& u = refined.workspace.directions()[i];
    errors.push_back(refined.workspace.radii_m()[i] -
                     trueReach_m(*refined_device, refined.workspace.center_m(), u));
  }
  std::sort(errors.begin(), errors.end());
  EXPECT_NEAR(errors[errors.size() / 2], 0.0, 2.5e-3);
  EXPECT_GT(errors.front(), -3e-3);
  EXPECT_LT(errors.back(), 8e-3);
  EXPECT_LE(refined.longest_recognition_s, 0.1);
  EXPECT_EQ(refined.saturation_count, 0u);
  EXPECT_LT(refined.seconds_above_continuous_force, 0.05 * refined.seconds);
  // Each boundary probe costs less than a radial one: it starts a centimetre from the stop.
  const double radial_per_direction_s = radial.seconds / 26.0;
  const double boundary_per_direction_s =
      (refined.seconds - radial.seconds) /
      static_cast<double>(refined.workspace.directions().size() - 26);
  RecordProperty("radial_s_per_direction", std::to_string(radial_per_direction_s));
  RecordProperty("boundary_s_per_direction", std::to_string(boundary_per_direction_s));
  EXPECT_LT(boundary_per_direction_s, radial_per_direction_s);
  // And the boundary now holds what the hand can reach: far fewer reachable points lie beyond.
  const double radial_beyond = shareBeyondBoundary(*radial_device, radial.workspace, 4000);
  const double refined_beyond = shareBeyondBoundary(*refined_device, refined.workspace, 4000);
  RecordProperty("share_beyond_radial", std::to_string(radial_beyond));
  RecordProperty("share_beyond_refined", std::to_string(refined_beyond));
  EXPECT_GT(radial_beyond, 0.08);
  EXPECT_LT(refined_beyond, 0.5 * radial_beyond);
}

TEST(BoundaryProbeTest, BoundaryProbesGoWhereTheRadialTrianglesCutMostOff) {
  // sim:omni explored with 40 boundary probes, chosen among about 86 candidates
  // from the radial stops alone. Where it probed, the true boundary lay further beyond the
  // radial stops' triangles than where it did not (ground truth, for scoring only). At high
  // friction too, where a probe that static friction holds at its start is left out rather than
  // taken for a stop.
  for (const sim::FrictionLevel friction :
       {sim::FrictionLevel::kTypical, sim::FrictionLevel::kHigh}) {
    SCOPED_TRACE(toString(friction));
    std::unique_ptr<sim::SimulatedDevice> device;
    sim::ExplorationResult result;
    WorkspaceExplorer::Options options;
    options.boundary_directions = 40;
    ASSERT_NO_FATAL_FAILURE(exploreFromTheCentre("sim:omni", friction, options, device, result));
    const ExploredWorkspace& workspace = result.workspace;
    ASSERT_LE(workspace.directions().size(),
              static_cast<std::size_t>(26 + options.boundary_directions));
    ASSERT_GE(workspace.directions().size(),
              static_cast<std::size_t>(26 + options.boundary_directions - 3));
    const ExploredWorkspace radial(
        workspace.center_m(),
        std::vector<Eigen::Vector3d>(workspace.directions().begin(),
                                     workspace.directions().begin() + 26),
        std::vector<double>(workspace.radii_m().begin(), workspace.radii_m().begin() + 26));
    EstimationParameters parameters;
    const WorkspaceExplorer planned(parameters, device->specifications(), options);
    double probed_gap_m = 0.0, skipped_gap_m = 0.0;
    int probed = 0, skipped = 0;
    for (int i = 26; i < planned.directionCount(); ++i) {
      const Eigen::Vector3d& u = planned.directions()[static_cast<std::size_t>(i)];
      const double true_reach_m = trueReach_m(*device, workspace.center_m(), u);
      const double gap_m = true_reach_m - radial.boundaryDistance_m(u);
      const auto found =
          std::find_if(workspace.directions().begin() + 26, workspace.directions().end(),
                       [&](const Eigen::Vector3d& d) { return d.dot(u) > 1.0 - 1e-12; });
      if (found == workspace.directions().end()) {
        skipped_gap_m += gap_m;
        ++skipped;
        continue;
      }
      probed_gap_m += gap_m;
      ++probed;
      // Each probed direction ends at the stop, as the radial ones do. At high friction a probe
      // may stick short of it, but never behind where it started (boundary_clearance_m inside
      // the radial triangle): that would be a stop inside the triangle.
      const double reach_m =
          workspace.radii_m()[static_cast<std::size_t>(found - workspace.directions().begin())];
      const double shortfall_m =
          friction == sim::FrictionLevel::kHigh ? options.boundary_clearance_m + 1e-3 : 3e-3;
      EXPECT_GT(reach_m - true_reach_m, -shortfall_m) << i;
      EXPECT_LT(reach_m - true_reach_m, 8e-3) << i;
    }
    ASSERT_GT(skipped, 30);
    probed_gap_m /= probed;
    skipped_gap_m /= skipped;
    RecordProperty(std::string("probed_gap_mm_") + toString(friction),
                   std::to_string(1e3 * probed_gap_m));
    RecordProperty(std::string("skipped_gap_mm_") + toString(friction),
                   std::to_string(1e3 * skipped_gap_m));
    EXPECT_GT(probed_gap_m, 1.2 * skipped_gap_m);
    EXPECT_EQ(result.saturation_count, 0u);
    EXPECT_LT(result.seconds_above_continuous_force, 0.05 * result.seconds);
  }
}

TEST(BoundaryProbeTest, BadBoundaryOptionsAreRefused) {
  EstimationParameters parameters;
  const DeviceSpecifications specifications =
      sim::makeSimulatedDevice("sim:omni", 1, sim::FrictionLevel::kTypical)->specifications();
  WorkspaceExplorer::Options options;
  options.boundary_directions = -1;
  EXPECT_THROW(WorkspaceExplorer(parameters, specifications, options), Error);
  options.boundary_directions = 50;
  options.boundary_clearance_m = 0.0;
  EXPECT_THROW(WorkspaceExplorer(parameters, specifications, options), Error);
  options.boundary_clearance_m = 0.01;
  options.boundary_directions = 20000;
  EXPECT_THROW(WorkspaceExplorer(parameters, specifications, options), Error);
  options.boundary_directions = 50;
  options.boundary_candidates = -1;
  EXPECT_THROW(WorkspaceExplorer(parameters, specifications, options), Error);
  options.boundary_candidates = 100;
  options.boundary_bulge_m = -1e-3;
  EXPECT_THROW(WorkspaceExplorer(parameters, specifications, options), Error);
  options.boundary_bulge_m = 1.5e-3;
  // The default probes the radial directions alone.
  EXPECT_EQ(WorkspaceExplorer(parameters, specifications).directionCount(), 26);
  // Any number of boundary probes are chosen among a 100-direction spread at least (less the
  // few that repeat a radial direction).
  options.boundary_directions = 40;
  const WorkspaceExplorer explorer(parameters, specifications, options);
  EXPECT_EQ(explorer.radialDirectionCount(), 26);
  EXPECT_GT(explorer.directionCount(), 100);
  EXPECT_EQ(explorer.directions().size(), static_cast<std::size_t>(explorer.directionCount()));
}

}  // namespace
}  // namespace autograv
