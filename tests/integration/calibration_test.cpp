// Whole-grid calibrations on the simulated devices, judged against their ground truth.
#include <algorithm>
#include <atomic>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/map/workspace_fit.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/sim/point_mass_device.h"
#include "autograv/sim/procedures.h"

namespace autograv {
namespace {

struct Outcome {
  sim::CalibrationRunResult run;
  sim::AccuracyReport accuracy;
  int converged = 0;
};

// Options for a run on `device`'s workspace centre; tests set what they vary.
sim::CalibrationRunOptions optionsFor(const sim::SimulatedDevice& device, double side_m,
                                      int resolution) {
  sim::CalibrationRunOptions options;
  options.grid_center_m = device.workspaceCenter_m();
  options.grid_size_m = Eigen::Vector3d::Constant(side_m);
  options.grid_resolution = Eigen::Vector3i::Constant(resolution);
  return options;
}

Outcome calibrate(const std::string& name, int resolution, double side_m, std::uint64_t seed,
                  const EstimationParameters& parameters = {},
                  sim::FrictionLevel friction = sim::FrictionLevel::kTypical) {
  auto device = sim::makeSimulatedDevice(name, seed, friction);
  EXPECT_TRUE(device->open());
  sim::CalibrationRunOptions options;
  options.grid_center_m = device->workspaceCenter_m();
  options.grid_size_m = Eigen::Vector3d::Constant(side_m);
  options.grid_resolution = Eigen::Vector3i::Constant(resolution);
  options.parameters = parameters;
  Outcome outcome;
  outcome.run = sim::runSimulatedCalibration(*device, options);
  const GravityMap map(WorkspaceGrid(options.grid_center_m, side_m, resolution),
                       outcome.run.vertices, MapMetadata{});
  outcome.accuracy = sim::measureAccuracy(map, *device, 1000, seed);
  outcome.converged = map.convergedCount();
  return outcome;
}

TEST(CalibrationTest, OmegaFiveCubedMeetsTheAccuracyTargets) {
  // The default grid of `autograv calibrate`, at typical friction.
  const Outcome outcome =
      calibrate("sim:omega", 5,
                defaultGridSide_m(sim::omegaParameters().specifications.workspace_radius_m), 1);
  EXPECT_EQ(outcome.run.status, AutoCalibrator::Status::kFinished);
  EXPECT_EQ(outcome.converged, 125);
  EXPECT_LE(outcome.accuracy.max_error_rel, 0.03);
  EXPECT_LE(outcome.accuracy.rms_residual_rel, 0.05);
  EXPECT_EQ(outcome.run.saturation_count, 0u);
  EXPECT_LT(outcome.run.peak_force_n, 12.0);
}

TEST(CalibrationTest, ParametersThatWouldSaturateAreRefusedBeforeTheDeviceMoves) {
  auto device = sim::makeSimulatedDevice("sim:omega", 1);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options;
  options.grid_center_m = device->workspaceCenter_m();
  options.grid_size_m = Eigen::Vector3d::Constant(0.05);
  options.grid_resolution = Eigen::Vector3i::Constant(2);  // one 50 mm cell
  options.parameters.beta_per_s2 = 2500.0;
  try {
    sim::runSimulatedCalibration(*device, options);
    FAIL() << "expected a refusal";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("saturation check failed"), std::string::npos) << message;
    EXPECT_NE(message.find("EstimationParameters::beta_per_s2"), std::string::npos) << message;
  }
}

TEST(CalibrationTest, ABetaTooLowForConvergenceIsRefused) {
  auto device = sim::makeSimulatedDevice("sim:omega", 1);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options;
  options.grid_center_m = device->workspaceCenter_m();
  options.parameters.beta_per_s2 = 50.0;
  options.parameters.alpha_per_s = 10.0;
  EXPECT_THROW(
      {
        try {
          sim::runSimulatedCalibration(*device, options);
        } catch (const Error& error) {
          EXPECT_NE(std::string(error.what()).find("raise beta to at least"), std::string::npos);
          throw;
        }
      },
      Error);
}

TEST(CalibrationTest, VerticesThatHitTheCapAreMarkedAndTheGridGoesOn) {
  EstimationParameters parameters;
  parameters.eps_g_n = 1e-7;  // unreachable through friction and quantization
  parameters.max_iterations = 6;
  const Outcome outcome = calibrate("sim:omega", 2, 0.04, 1, parameters);
  EXPECT_EQ(outcome.run.status, AutoCalibrator::Status::kFinished);
  EXPECT_EQ(outcome.converged, 0);
  for (const auto& vertex : outcome.run.vertices) {
    EXPECT_EQ(vertex.outcome, VertexOutcome::kIterationCap);
    EXPECT_EQ(vertex.iterations, 6);
    EXPECT_GT(vertex.gravity_n.norm(), 1.0);  // the last estimate is kept, not zeroed
  }
}

TEST(CalibrationTest, FailedVerticesAreVisitedAgainOnlyAsOftenAsAsked) {
  EstimationParameters parameters;
  parameters.eps_g_n = 1e-7;  // unreachable: every vertex hits the cap, every pass
  parameters.max_iterations = 6;
  auto device = sim::makeSimulatedDevice("sim:omega", 1);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options = optionsFor(*device, 0.04, 2);
  options.parameters = parameters;
  options.redo_passes = 2;
  const sim::CalibrationRunResult run = sim::runSimulatedCalibration(*device, options);
  EXPECT_EQ(run.status, AutoCalibrator::Status::kFinished);
  EXPECT_EQ(run.redo_passes, 2);
  EXPECT_EQ(run.redone_vertices, 16);  // 8 vertices, twice
  for (const auto& vertex : run.vertices) EXPECT_EQ(vertex.outcome, VertexOutcome::kIterationCap);

  options.redo_passes = 0;
  auto again = sim::makeSimulatedDevice("sim:omega", 1);
  ASSERT_TRUE(again->open());
  const sim::CalibrationRunResult once = sim::runSimulatedCalibration(*again, options);
  EXPECT_EQ(once.redo_passes, 0);
  EXPECT_LT(once.simulated_seconds, run.simulated_seconds);
}

TEST(CalibrationTest, OmniVerticesThatMissedTheirSteadyStateConvergeOnASecondVisit) {
  // Seed 2 at low friction: a vertex ends no_steady_state on the first pass (one-count encoder
  // dither against eps_S = 0.1 mm/s); one more visit settles it. The redo pass is what is
  // tested, not the estimator's accuracy through friction, hence the low friction.
  auto device = sim::makeSimulatedDevice("sim:omni", 2, sim::FrictionLevel::kLow);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options =
      optionsFor(*device, defaultGridSide_m(device->specifications().workspace_radius_m), 5);
  options.parameters.k0_n_per_m = defaultInitializationStiffness(device->specifications());
  const sim::CalibrationRunResult run = sim::runSimulatedCalibration(*device, options);
  EXPECT_EQ(run.status, AutoCalibrator::Status::kFinished);
  EXPECT_EQ(run.redo_passes, 1);
  EXPECT_GE(run.redone_vertices, 1);
  const auto converged = std::count_if(run.vertices.begin(), run.vertices.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  });
  EXPECT_EQ(converged, 125);
}

TEST(CalibrationTest, AStoppedRunResumesKeepingFinishedVerticesBitForBit) {
  auto device = sim::makeSimulatedDevice("sim:omega", 4);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options = optionsFor(*device, 0.04, 3);
  std::atomic<bool> stop{false};
  int finished = 0;
  options.stop_requested = &stop;
  options.on_vertex_finished = [&](const AutoCalibrator&, int) {
    if (++finished == 8) stop = true;
  };
  const sim::CalibrationRunResult first = sim::runSimulatedCalibration(*device, options);
  EXPECT_TRUE(first.stopped);

  auto fresh = sim::makeSimulatedDevice("sim:omega", 5);
  ASSERT_TRUE(fresh->open());
  options.stop_requested = nullptr;
  options.on_vertex_finished = nullptr;
  options.resume_from = first.vertices;
  const sim::CalibrationRunResult second = sim::runSimulatedCalibration(*fresh, options);
  EXPECT_EQ(second.status, AutoCalibrator::Status::kFinished);
  int kept = 0;
  for (std::size_t i = 0; i < first.vertices.size(); ++i) {
    if (first.vertices[i].outcome != VertexOutcome::kConverged) continue;
    ++kept;
    EXPECT_EQ(second.vertices[i].gravity_n, first.vertices[i].gravity_n);
  }
  EXPECT_EQ(kept, 8);
  for (const auto& vertex : second.vertices) EXPECT_EQ(vertex.outcome, VertexOutcome::kConverged);
}

TEST(CalibrationTest, ADeviceThatStopsAnsweringEndsTheRunAndKeepsTheFinishedVertices) {
  auto device = sim::makeSimulatedDevice("sim:omega", 6);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options = optionsFor(*device, 0.04, 3);
  int finished = 0;
  options.on_vertex_finished = [&](const AutoCalibrator&, int) {
    if (++finished == 5) device->injectFault(sim::DeviceFault::kStopsAnswering);
  };
  const sim::CalibrationRunResult result = sim::runSimulatedCalibration(*device, options);
  EXPECT_EQ(result.status, AutoCalibrator::Status::kDeviceFault);
  int converged = 0;
  for (const auto& vertex : result.vertices)
    converged += vertex.outcome == VertexOutcome::kConverged;
  EXPECT_EQ(converged, 5);
}

// A 5x5x5 box larger than the workspace sphere (edge 1.7 radii): its corners and edges lie
// beyond the end stops, none of its vertices within 4 % of the sphere (a vertex a millimetre
// into a rubber stop is held there, and the stop's push is indistinguishable from gravity). The
// calibration must find exactly the vertices it cannot reach from what the driver reports, and
// fill them.
class EndStopCalibrationTest : public ::testing::TestWithParam<std::string> {};

TEST_P(EndStopCalibrationTest, VerticesBeyondTheEndStopsAreUnreachableAndFilled) {
  auto device = sim::makeSimulatedDevice(GetParam(), 3);
  ASSERT_TRUE(device->open());
  const double radius_m = device->specifications().workspace_radius_m;
  sim::CalibrationRunOptions options = optionsFor(*device, 1.7 * radius_m, 5);
  // The tools' method: the paper's wanders in the friction dead band, which the stall rule
  // would take for a vertex that cannot be held.
  options.parameters = EstimationParameters::frictionRobust();
  options.parameters.k0_n_per_m = defaultInitializationStiffness(device->specifications());
  const sim::CalibrationRunResult run = sim::runSimulatedCalibration(*device, options);
  EXPECT_EQ(run.status, AutoCalibrator::Status::kFinished);
  const WorkspaceGrid grid(options.grid_center_m, options.grid_size_m, options.grid_resolution);
  const GravityMap map(grid, run.vertices, MapMetadata{});
  EXPECT_TRUE(map.isComplete());
  EXPECT_GT(map.unreachableCount(), 20);
  EXPECT_EQ(map.filledCount(), map.unreachableCount());
  EXPECT_EQ(map.convergedCount() + map.unreachableCount(), grid.vertexCount());
  const double centre_gravity_n =
      map.vertices()[static_cast<std::size_t>(grid.vertexIndex(2, 2, 2))].gravity_n.norm();
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(i)];
    const Eigen::Vector3d x = grid.vertexPosition(i);
    // Ground truth only to judge: the estimator never saw it.
    EXPECT_EQ(v.outcome == VertexOutcome::kUnreachable, !device->isReachable(x)) << "vertex " << i;
    if (v.outcome == VertexOutcome::kUnreachable) {
      EXPECT_EQ(v.provenance, VertexProvenance::kFilled);
      // Filled by extrapolation from the measured cross: the size of the field, not the garbage
      // an estimate grows to against a stop.
      EXPECT_LT(v.gravity_n.norm(), 3.0 * centre_gravity_n) << "vertex " << i;
    }
  }
  // Where the hand can go, the map is close to the truth.
  EXPECT_LT(sim::measureAccuracy(map, *device, 500, 3).rms_residual_rel, 0.08);
}

// Not sim:falcon: its arm stops lie well beyond a box of 1.7 workspace radii (the limits of the
// parallelograms' ball joints, which bound a real Falcon to its 4-inch cube, are not modelled).
INSTANTIATE_TEST_SUITE_P(DevicesWithStopsInReach, EndStopCalibrationTest,
                         ::testing::Values("sim:omega", "sim:omni"));

// The default grid of `autograv calibrate`: a 5x5x5 box fitted to the reachable workspace.
class FittedBoxCalibrationTest : public ::testing::TestWithParam<std::string> {};

TEST_P(FittedBoxCalibrationTest, EveryVertexConvergesOrIsUnreachableAndFilled) {
  auto device = sim::makeSimulatedDevice(GetParam(), 1);
  ASSERT_TRUE(device->open());
  const WorkspaceFit fit = sim::fitGridToDevice(*device);
  EXPECT_GE(fit.workspace_coverage, 0.9);
  sim::CalibrationRunOptions options;
  options.grid_center_m = fit.center_m;
  options.grid_size_m = fit.size_m;
  options.grid_resolution = Eigen::Vector3i::Constant(5);
  options.parameters = EstimationParameters::frictionRobust();  // what `calibrate` uses
  options.parameters.k0_n_per_m = defaultInitializationStiffness(device->specifications());
  const sim::CalibrationRunResult run = sim::runSimulatedCalibration(*device, options);
  const WorkspaceGrid grid(options.grid_center_m, options.grid_size_m, options.grid_resolution);
  const GravityMap map(grid, run.vertices, MapMetadata{});
  EXPECT_TRUE(map.isComplete());
  EXPECT_GT(map.unreachableCount(), 0);
  // sim:falcon's fitted box reaches the corners of its 4-inch cube, where an arm's torque limit
  // can give out before its stop: a few vertices the kinematics call reachable are found
  // unreachable there (and filled), so the exact match is asked of the other devices only.
  if (GetParam() != "sim:falcon") {
    for (int i = 0; i < grid.vertexCount(); ++i) {
      EXPECT_EQ(map.vertices()[static_cast<std::size_t>(i)].outcome == VertexOutcome::kUnreachable,
                !device->isReachable(grid.vertexPosition(i)))
          << "vertex " << i;
    }
  }
  const sim::AccuracyReport accuracy = sim::measureAccuracy(map, *device, 1000, 1);
  EXPECT_LT(accuracy.max_error_rel, 0.03);
  EXPECT_LT(accuracy.rms_residual_rel, 0.04);
}

INSTANTIATE_TEST_SUITE_P(EverySimulatedDevice, FittedBoxCalibrationTest,
                         ::testing::ValuesIn(sim::simulatedDeviceNames()));

}  // namespace
}  // namespace autograv
