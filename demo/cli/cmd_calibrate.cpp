// autograv calibrate: the whole off-line autocalibration on a simulated device.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/friction_measurement.h"
#include "autograv/sim/procedures.h"
#include "autograv/wizard/calibration_wizard.h"
#include "calibrate_like.h"
#include "calibration_report.h"
#include "cli_support.h"
#include "commands.h"
#include "estimation_options.h"

namespace autograv::cli {

namespace {

std::atomic<bool> g_stop_requested{false};
extern "C" void requestStop(int) { g_stop_requested.store(true); }

struct CalibrateOptions {
  std::string device;
  GridOptions grid;
  std::string out_path;
  std::string report_path;
  bool resume = false;
  std::string like;  // a prior map: corrected, not calibrated whole
};

void runCalibrateCommand(const CalibrateOptions& options, const AdvancedOptions& advanced) {
  if (!options.like.empty()) {
    runCalibrateLike(options.device, options.like, options.out_path, options.report_path, advanced);
    return;
  }
  const SimulationKnobs& simulation = advanced.simulation();
  const CalibrationRunKnobs& knobs = advanced.run();
  auto device =
      openSimulatedDevice(options.device, simulation.seed, simulation.friction, simulation.unit);
  applySimulatedLoad(*device, simulation.load);
  const EstimationParameters parameters = estimationParameters(
      advanced.estimation(), EstimationMethod::kDither, device->specifications());
  const DeviceSpecifications& specs = device->specifications();
  // Default grid: the box around the workspace the device explores first; the simulated user
  // initializes near the workspace's centre, as a person would.
  sim::CalibrationRunOptions run;
  run.grid_from_workspace = gridFromWorkspace(options.grid);
  run.initialization_center_m = device->workspaceCenter_m();
  double workspace_coverage = 0.0;
  if (run.grid_from_workspace) {
    run.grid_resolution = gridResolution(options.grid);
  } else {
    const WorkspaceGrid box = resolveGrid(options.grid, *device, device.get(), workspace_coverage);
    run.grid_center_m = box.center_m();
    run.grid_size_m = box.size_m();
    run.grid_resolution = box.resolution();
  }
  run.parameters = parameters;
  run.calibrator.extrapolate_initial_estimate = !knobs.copy_initial_estimate;
  run.redo_passes = knobs.redo_failed;
  run.explorer.boundary_directions = knobs.boundary_probes;
  run.servo_timing = simulation.servo_timing;
  run.servo_timing_seed = simulation.servo_timing_seed.value_or(simulation.seed);

  MapMetadata metadata;
  metadata.device_model = specs.model_name;
  metadata.device_serial = specs.serial_number;
  metadata.parameters = parameters;  // created_utc stays empty: saveMap stamps each write
  metadata.field_model = knobs.field_model;
  const std::string checkpoint_path = options.out_path + ".partial";
  // Refuse now, not after minutes of calibration, when the files cannot be written.
  checkWritable(options.out_path, "map");
  checkWritable(checkpoint_path, "checkpoint");
  if (!options.report_path.empty()) checkWritable(options.report_path, "report");
  if (!options.resume && std::filesystem::exists(checkpoint_path)) {
    throw Error("checkpoint " + checkpoint_path +
                " holds the finished vertices of an interrupted run: add --resume to continue "
                "it, or delete it to start afresh");
  }
  if (options.resume) {
    // The checkpoint holds the grid and the explored workspace of the interrupted run: the
    // device is not explored again. The wizard's reader: either command resumes the other's run.
    const GravityMap partial = loadMap(checkpoint_path);
    const WorkspaceGrid& grid = partial.grid();
    run.grid_from_workspace = false;
    run.grid_center_m = grid.center_m();
    run.grid_size_m = grid.size_m();
    run.grid_resolution = grid.resolution();
    run.workspace = partial.metadata().workspace;
    run.resume_from = loadCheckpoint(checkpoint_path, grid, specs.model_name);
    const auto converged = std::count_if(
        run.resume_from.begin(), run.resume_from.end(),
        [](const VertexEstimate& vertex) { return vertex.outcome == VertexOutcome::kConverged; });
    std::fprintf(stderr, "resuming: %d of %d vertices already done (%s)\n",
                 static_cast<int>(converged), grid.vertexCount(), checkpoint_path.c_str());
  }

  std::printf("Calibrating %s: seed %llu, friction %s, unit %d with %s actuators\n",
              specs.model_name.c_str(), static_cast<unsigned long long>(simulation.seed),
              sim::toString(simulation.friction), simulation.unit.number,
              sim::toString(simulation.unit.actuators));
  if (run.workspace.empty()) {
    std::printf("Exploring the workspace: %d probe directions under a %.2f N cap...\n",
                run.explorer.directions,
                1.5 * std::min(WorkspaceExplorer::kContactForceFraction * specs.max_linear_force_n,
                               0.5 * continuousForceRating_n(specs)));
  }
  std::fflush(stdout);
  ProgressBar progress("vertex");
  run.on_explored = [&](const ExploredWorkspace& workspace, const WorkspaceGrid& grid) {
    metadata.workspace = workspace;
    metadata.lookup_refinement =
        lookupRefinementFor(grid, kDefaultLookupRefinement, knobs.field_model);
    std::printf("Explored: reach %.1f to %.1f mm from the centre; grid %s\n",
                workspace.minRadius_m() * 1e3, workspace.maxRadius_m() * 1e3,
                grid.describe().c_str());
    std::fflush(stdout);
  };
  run.on_progress = [&](const AutoCalibrator& calibrator) {
    char detail[128];
    const double delta_mm = calibrator.lastPositionError_m() * 1e3;
    if (calibrator.state() == AutoCalibrator::Status::kEstimating && std::isfinite(delta_mm)) {
      std::snprintf(detail, sizeof detail, "vertex #%d iter %d, delta %.3f mm, sim %.0f s",
                    calibrator.currentVertex(), calibrator.iteration(), delta_mm,
                    calibrator.elapsed_s());
    } else {
      std::snprintf(detail, sizeof detail, "%s, sim %.0f s", toString(calibrator.state()),
                    calibrator.elapsed_s());
    }
    progress.update(calibrator.visitedCount(), calibrator.toVisitCount(), detail);
  };
  const auto save_checkpoint = [&](const GravityMap& map) {
    writeFileAtomically(checkpoint_path, mapToJson(map), "checkpoint");  // temp file + rename
  };
  run.on_vertex_finished = [&](const AutoCalibrator& calibrator, int) {
    save_checkpoint(calibrator.makeMap(checkpointMetadata(metadata)));
  };
  g_stop_requested.store(false);
  run.stop_requested = &g_stop_requested;
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);

  const auto wall_start = std::chrono::steady_clock::now();
  const sim::CalibrationRunResult result = sim::runSimulatedCalibration(*device, run);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  progress.finish();
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);

  const WorkspaceGrid& grid = result.grid;
  workspace_coverage = sim::deviceWorkspaceCoverage(*device, grid);
  metadata.lookup_refinement =
      lookupRefinementFor(grid, kDefaultLookupRefinement, knobs.field_model);
  metadata.reviewed_measurements = result.reviewed_measurements;
  metadata.thermal_drift = result.thermal_drift;
  const GravityMap map(grid, result.vertices, metadata);
  if (result.stopped || result.status == AutoCalibrator::Status::kDeviceFault) {
    save_checkpoint(map);
    throw Error(std::string(result.stopped ? "interrupted" : "the device stopped answering") +
                ": " + std::to_string(map.convergedCount()) + " of " +
                std::to_string(grid.vertexCount()) + " vertices are saved in " + checkpoint_path +
                "; run the same command with --resume to continue");
  }
  try {
    saveMap(map, options.out_path);
  } catch (const Error& error) {
    // The last checkpoint, written after the last vertex, holds the whole result.
    throw Error(std::string(error.what()) + ". Every finished vertex is kept in " +
                checkpoint_path + ": make room and run the same command with --resume");
  }
  std::error_code ignored;
  std::filesystem::remove(checkpoint_path, ignored);

  CalibrationOutcome outcome{options.out_path,        simulation.seed, simulation.friction,
                             simulation.servo_timing, specs,           parameters};
  outcome.servo_timing_seed = run.servo_timing_seed;
  outcome.unit = simulation.unit;
  outcome.actuator_gains = sim::actuatorGains(specs.model_name, simulation.unit);
  outcome.wall_s = wall_s;
  if (const sim::MotorThermalModel* motors = device->motorThermal()) {
    outcome.motors_at_end =
        Eigen::Vector3d(motors->winding_c().maxCoeff(), motors->housing_c().maxCoeff(),
                        motors->gainFactor().minCoeff());
  }
  outcome.workspace_coverage = workspace_coverage;
  outcome.accuracy = sim::measureAccuracy(map, *device, 1000, simulation.seed);
  // The device's friction, measured on a fresh copy (same seed and level) so that the
  // calibration run above is what it was.
  auto bench =
      openSimulatedDevice(options.device, simulation.seed, simulation.friction, simulation.unit);
  outcome.device_friction = sim::measureFriction(*bench);
  // The field where the hand can be, judged against the simulation's truth (scoring only), and
  // where its error beats the breakaway force: where a released stylus would drift.
  outcome.field = sim::measureFieldError(map, *device, sim::kFieldErrorSamples, simulation.seed,
                                         5e-3, outcome.device_friction.breakaway_force_n);
  outcome.agreement = judgeAgreement(map);
  printCalibrationOutcome(outcome, result, map);
  writeJsonReport(options.report_path, calibrationReportJson(outcome, result, map));
}

void addCalibrateCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<CalibrateOptions>();
  CLI::App* command = app.add_subcommand(
      "calibrate",
      "Run the whole off-line autocalibration on a simulated device and save the map (a real "
      "device is calibrated with `autograv wizard`)");
  addDeviceOption(*command, options->device)->check(simulatedOnly("calibrate"));
  command->add_option("--out", options->out_path, "Map file to write (JSON)")->required();
  addGridOptions(*command, options->grid);
  addReportOption(*command, options->report_path);
  command->add_flag("--resume", options->resume,
                    "Continue an interrupted run from <out>.partial, keeping its vertices");
  addLikeOption(*command, options->like);
  advanced->accept(*command, {knob::kSimulatedDevice, knob::kSimulatedLoad, knob::kServoTiming,
                              knob::kServoTimingSeed, knob::kEstimation, knob::kCalibrationRun,
                              knob::kFieldModel});
  command->callback([options, advanced] { runCalibrateCommand(*options, *advanced); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(30, addCalibrateCommand);

}  // namespace autograv::cli
