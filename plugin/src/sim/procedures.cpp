#include "autograv/sim/procedures.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <vector>

#include "autograv/device/servo_sample.h"
#include "autograv/error.h"
#include "autograv/estimation/initialization_estimator.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/map/map_summary.h"
#include "autograv/map/measurement_review.h"
#include "autograv/map/thermal_drift.h"
#include "autograv/map/vertex_fill.h"
#include "autograv/sim/paper_frame.h"
#include "core/estimation/vertex_estimator.h"

namespace autograv::sim {

namespace {

// How a person does the manual step: carry the stylus at 5 cm/s, hold it still for half a second,
// switch the field on, keep holding while it fades in, then let go.
constexpr double kHandSpeed_m_per_s = 0.05;
constexpr double kHandHold_s = 0.5;
constexpr double kFieldRamp_s = 0.3;

/// One servo tick on simulated time: read (with the servo time since the previous read),
/// control, command, then advance the device to the next tick the timing model draws.
template <typename Control>
void servoTick(SimulatedDevice& device, ServoTimingModel& timing, ServoLoopStats* stats,
               Control&& control) {
  const ServoSample sample = readServoSample(device, timing.lastInterval_s());
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  control(sample, force_n);
  device.setForce(force_n);
  device.advance(timing.nextInterval_s());
  if (stats != nullptr) stats->record(timing.lastInterval_s(), timing.lastLateness_s());
}

}  // namespace

InitializationResult initializeWithSimulatedHand(SimulatedDevice& device,
                                                 const EstimationParameters& parameters,
                                                 const Eigen::Vector3d& center_m, double timeout_s,
                                                 ServoTimingModel* timing, ServoLoopStats* stats) {
  ServoTimingModel exact(ServoTiming::kExact, 1, parameters.servo_period_s);
  ServoTimingModel& clock = timing != nullptr ? *timing : exact;
  const double start_s = device.time_s();
  const auto zero_force = [](const ServoSample&, Eigen::Vector3d& force_n) { force_n.setZero(); };
  InitializationResult result;
  SimulatedHand& hand = device.hand();
  if (!hand.holding()) hand.grab(device.truePosition_m());
  hand.moveTo(center_m, kHandSpeed_m_per_s);
  while (!hand.atGoal() && device.time_s() - start_s < timeout_s) {
    servoTick(device, clock, stats, zero_force);
  }
  for (double t = 0.0; t < kHandHold_s; t += clock.lastInterval_s()) {
    servoTick(device, clock, stats, zero_force);
  }

  InitializationEstimator estimator(parameters, device.specifications().max_linear_force_n,
                                    kFieldRamp_s);
  const ServoSample at_center = readServoSample(device);
  if (!at_center.valid) {
    result.message = "the device did not answer while the hand held it at the centre";
    return result;
  }
  estimator.start(at_center.position_m);
  device.clearEndStopHit();  // where the hand carried it does not matter; where it settles does
  const double field_on_s = device.time_s();
  InitializationEstimator::Status status = InitializationEstimator::Status::kRampingIn;
  while (status != InitializationEstimator::Status::kDone &&
         status != InitializationEstimator::Status::kDeviceFault &&
         device.time_s() - start_s < timeout_s) {
    if (hand.holding() && device.time_s() - field_on_s > kFieldRamp_s + 0.1) hand.release();
    servoTick(device, clock, stats, [&](const ServoSample& sample, Eigen::Vector3d& force_n) {
      status = estimator.step(sample, force_n);
    });
  }
  result.seconds = device.time_s() - start_s;
  result.center_m = estimator.center_m();
  if (status == InitializationEstimator::Status::kDeviceFault) {
    result.message = "the device stopped answering during the initialization";
    return result;
  }
  if (status != InitializationEstimator::Status::kDone) {
    std::ostringstream message;
    message << "the end-effector did not settle in the k0 field within " << timeout_s
            << " s (raise eps_S or k0)";
    result.message = message.str();
    return result;
  }
  result.gravity_n = estimator.gravityEstimate_n();
  result.settled_m = estimator.center_m() - result.gravity_n / parameters.k0_n_per_m;
  result.end_stop_hit = device.endStopHit();
  if (result.end_stop_hit) {
    const Eigen::Vector3d offset_mm = 1e3 * (result.center_m - device.workspaceCenter_m());
    std::ostringstream message;
    message << "the end-effector rested on an end stop after release (X0 is " << offset_mm.norm()
            << " mm from the workspace centre, radius "
            << device.specifications().workspace_radius_m * 1e3 << " mm, and sags by about "
            << 1e3 * result.gravity_n.norm() / parameters.k0_n_per_m
            << " mm in the k0 field): eq. (7) does not hold there; initialize further inside the "
               "workspace or raise k0";
    result.message = message.str();
    return result;
  }
  result.ok = true;
  return result;
}

PaperExperimentResult runPaperExperiment(SimulatedDevice& device,
                                         const EstimationParameters& parameters) {
  PaperExperimentResult result;
  const double start_s = device.time_s();
  // The user picks the (random) start point and initializes there: X0 = start (Sec. III-A, V).
  device.resetState(paperStartPoint_m());
  device.hand().grab(device.truePosition_m());
  result.initialization = initializeWithSimulatedHand(device, parameters, paperStartPoint_m());
  if (!result.initialization.ok) {
    throw Error("paper experiment: initialization failed: " + result.initialization.message);
  }
  result.target_m = paperTargetPoint_m();
  result.gravity_true_n = device.trueGravity(result.target_m);
  result.mass_true_kg = result.gravity_true_n.norm() / kStandardGravity;

  VertexEstimator estimator(parameters, device.specifications().max_linear_force_n);
  estimator.start(result.target_m, result.initialization.gravity_n);
  const double timeout_s = parameters.max_iterations * parameters.max_step_duration_s;
  const double loop_start_s = device.time_s();
  ServoTimingModel exact(ServoTiming::kExact, 1, parameters.servo_period_s);
  while (!estimator.finished() && device.time_s() - loop_start_s < timeout_s) {
    servoTick(device, exact, nullptr, [&](const ServoSample& sample, Eigen::Vector3d& force_n) {
      estimator.step(sample, force_n);
    });
  }
  result.estimate = estimator.estimate();
  result.simulated_seconds = device.time_s() - start_s;
  return result;
}

ExplorationResult exploreWorkspace(SimulatedDevice& device, const EstimationParameters& parameters,
                                   const InitializationResult& initialization,
                                   const WorkspaceExplorer::Options& options,
                                   const std::atomic<bool>* stop_requested, double timeout_s,
                                   ServoTimingModel* timing, ServoLoopStats* stats) {
  ServoTimingModel exact(ServoTiming::kExact, 1, parameters.servo_period_s);
  ServoTimingModel& clock = timing != nullptr ? *timing : exact;
  const DeviceSpecifications& specs = device.specifications();
  const double continuous_n = continuousForceRating_n(specs);
  WorkspaceExplorer explorer(parameters, specs, options);
  explorer.start(initialization.settled_m, initialization.gravity_n);
  ExplorationResult result;
  const double start_s = device.time_s();
  const std::uint64_t saturations_before = device.saturationCount();
  WorkspaceExplorer::Status state = WorkspaceExplorer::Status::kTransfer;
  while (state != WorkspaceExplorer::Status::kFinished &&
         state != WorkspaceExplorer::Status::kDeviceFault &&
         device.time_s() - start_s < timeout_s) {
    if (stop_requested != nullptr && stop_requested->load()) {
      result.stopped = true;
      break;
    }
    servoTick(device, clock, stats, [&](const ServoSample& sample, Eigen::Vector3d& force_n) {
      state = explorer.step(sample, force_n);
      const double norm_n = force_n.norm();
      result.peak_force_n = std::max(result.peak_force_n, norm_n);
      if (norm_n > continuous_n) {
        result.seconds_above_continuous_force +=
            sample.interval_s > 0.0 ? sample.interval_s : parameters.servo_period_s;
      }
    });
  }
  result.seconds = device.time_s() - start_s;
  result.longest_recognition_s = explorer.longestRecognition_s();
  result.saturation_count = device.saturationCount() - saturations_before;
  if (state == WorkspaceExplorer::Status::kDeviceFault) {
    throw Error("calibration: the device stopped answering while its workspace was explored");
  }
  if (result.stopped) return result;
  if (state != WorkspaceExplorer::Status::kFinished) {
    throw Error("calibration: the workspace exploration did not finish within " +
                std::to_string(timeout_s) + " s");
  }
  result.workspace = explorer.workspace();
  return result;
}

CalibrationRunResult runSimulatedCalibration(SimulatedDevice& device,
                                             const CalibrationRunOptions& options) {
  const EstimationParameters& parameters = options.parameters;
  const DeviceSpecifications& specs = device.specifications();
  const double max_force_n = specs.max_linear_force_n;
  const double continuous_n = continuousForceRating_n(specs);
  const double start_s = device.time_s();
  CalibrationRunResult result;
  result.grid = WorkspaceGrid(options.grid_center_m, options.grid_size_m, options.grid_resolution);
  const std::uint64_t saturations_before = device.saturationCount();
  ServoTimingModel timing(options.servo_timing, options.servo_timing_seed,
                          parameters.servo_period_s);
  ServoLoopStats stats;
  // What a real device would feel: the force sent each tick, held until the next, against its
  // ratings.
  const auto account = [&](const Eigen::Vector3d& force_n, const ServoSample& sample) {
    if (force_n.norm() > continuous_n) {
      result.seconds_above_continuous_force +=
          sample.interval_s > 0.0 ? sample.interval_s : parameters.servo_period_s;
    }
  };

  const Eigen::Vector3d x0_m =
      options.grid_from_workspace ? options.initialization_center_m : result.grid.center_m();
  result.initialization =
      initializeWithSimulatedHand(device, parameters, x0_m, 30.0, &timing, &stats);
  // With a workspace (explored now, or resumed) a stop under the initialization is recognised from
  // driver data (initializationClearanceProblem, below); the simulator's contact flag judges only
  // runs without one.
  const bool judged_from_workspace = options.explore;
  if (!result.initialization.ok && !(judged_from_workspace && result.initialization.end_stop_hit)) {
    throw Error("calibration: manual initialization failed: " + result.initialization.message);
  }
  // The plan depends on G_hat_0 and the parameters only: checked before the device moves by
  // itself, the exploration included.
  const auto problems = checkCalibrationPlan(
      parameters, AutoCalibrator::largestHoldStep_m(parameters, options.calibrator), max_force_n,
      result.initialization.gravity_n);
  if (!problems.empty()) {
    std::string message = "calibration refused before the device moves by itself:";
    for (const auto& problem : problems) message += "\n  - " + problem;
    throw Error(message);
  }

  if (options.explore && !options.workspace.empty()) {
    result.workspace = options.workspace;
  } else if (options.explore) {
    const ExplorationResult exploration =
        exploreWorkspace(device, parameters, result.initialization, options.explorer,
                         options.stop_requested, options.timeout_s, &timing, &stats);
    result.exploration_seconds = exploration.seconds;
    result.longest_stop_recognition_s = exploration.longest_recognition_s;
    result.seconds_above_continuous_force += exploration.seconds_above_continuous_force;
    if (exploration.stopped) {
      device.setForce(Eigen::Vector3d::Zero());
      result.stopped = true;
      result.status = AutoCalibrator::Status::kAborted;
      result.simulated_seconds = device.time_s() - start_s;
      return result;
    }
    result.workspace = exploration.workspace;
  }
  const std::string clearance =
      initializationClearanceProblem(result.workspace, result.initialization.settled_m);
  if (!clearance.empty()) {
    device.setForce(Eigen::Vector3d::Zero());
    throw Error("calibration refused: " + clearance);
  }
  if (options.grid_from_workspace && !result.workspace.empty()) {
    result.grid = gridAroundWorkspace(result.workspace, options.grid_resolution);
  }
  const WorkspaceGrid& grid = result.grid;
  result.plan = planMeasurements(grid, result.workspace);
  if (options.on_explored) options.on_explored(result.workspace, grid);
  AutoCalibrator::Options calibrator_options = options.calibrator;
  if (!(calibrator_options.continuous_force_n > 0.0)) {
    calibrator_options.continuous_force_n = continuous_n;
  }
  AutoCalibrator calibrator(grid, parameters, max_force_n, calibrator_options);
  if (!options.resume_from.empty()) calibrator.restore(options.resume_from);
  calibrator.setPlan(result.plan);
  const ServoSample first = readServoSample(device);
  calibrator.start(first.valid ? first.position_m : grid.center_m(),
                   result.initialization.gravity_n);

  double next_progress_s = device.time_s();
  AutoCalibrator::Status status = AutoCalibrator::Status::kMoving;
  bool reviewed = false;  // planReview ran
  std::vector<DriftReference> drift_references;
  std::vector<int> drift_vertices;  // theirs, measured after the others in the same pass
  while (device.time_s() - start_s < options.timeout_s) {
    if (options.stop_requested != nullptr && options.stop_requested->load()) {
      result.stopped = true;
      break;
    }
    servoTick(device, timing, &stats, [&](const ServoSample& sample, Eigen::Vector3d& force_n) {
      status = calibrator.step(sample, force_n);
      account(force_n, sample);
    });
    if (status == AutoCalibrator::Status::kVertexFinished) {
      if (options.on_vertex_finished) {
        options.on_vertex_finished(calibrator, calibrator.lastFinishedVertex());
      }
      if (options.on_progress) options.on_progress(calibrator);
    } else if (options.on_progress && device.time_s() >= next_progress_s) {
      options.on_progress(calibrator);
      next_progress_s = device.time_s() + options.progress_period_s;
    }
    if (status == AutoCalibrator::Status::kFinished &&
        (result.redo_passes < options.redo_passes || (options.review_measurements && !reviewed))) {
      std::vector<int> failed;
      const std::vector<VertexEstimate>& vertices = calibrator.vertices();
      if (result.redo_passes < options.redo_passes) {
        for (int i = 0; i < grid.vertexCount(); ++i) {
          // An unreachable vertex would hit the same stop again: it is filled, not redone.
          if (needsAnotherVisit(vertices[static_cast<std::size_t>(i)])) failed.push_back(i);
        }
      }
      if (options.review_measurements && !reviewed) {
        // The measurements judged against one another, once, after the plan (and in the same
        // pass as the failed vertices, as the wizard's Review does).
        reviewed = true;
        result.reviewed_measurements = planReview(grid, vertices, parameters.eps_g_n);
        for (const ReviewedMeasurement& entry : result.reviewed_measurements) {
          calibrator.remeasureAt(entry.first.vertex, entry.again_point_m);
          failed.push_back(entry.first.vertex);
        }
        // A few of the first points again, last, to see what the motors' warming did.
        drift_references = planThermalDriftCheck(grid, vertices, failed);
        for (const DriftReference& reference : drift_references) {
          calibrator.remeasureAt(reference.vertex, reference.point_m);
          drift_vertices.push_back(reference.vertex);
        }
      }
      if (!failed.empty() || !drift_vertices.empty()) {
        // Between ticks, as the wizard's redo: from where the end-effector is, with the last
        // vertex's estimate to start from.
        ++result.redo_passes;
        result.redone_vertices += static_cast<int>(failed.size() + drift_vertices.size());
        const int last = calibrator.lastFinishedVertex();
        const bool last_converged = last >= 0 && vertices[static_cast<std::size_t>(last)].outcome ==
                                                     VertexOutcome::kConverged;
        const Eigen::Vector3d estimate_n = last_converged
                                               ? vertices[static_cast<std::size_t>(last)].gravity_n
                                               : result.initialization.gravity_n;
        calibrator.visitOnly(failed, drift_vertices);
        drift_vertices.clear();
        const ServoSample here = readServoSample(device);
        calibrator.start(here.valid ? here.position_m : grid.center_m(), estimate_n);
        status = AutoCalibrator::Status::kMoving;
        continue;
      }
    }
    if (status == AutoCalibrator::Status::kFinished ||
        status == AutoCalibrator::Status::kDeviceFault) {
      break;
    }
  }
  if (options.on_progress) options.on_progress(calibrator);
  device.setForce(Eigen::Vector3d::Zero());
  result.status = status;
  // Solved from every measurement that stands (concludeReview leaves out the contradicted ones).
  result.vertices = calibrator.vertices();
  if (!result.stopped && status == AutoCalibrator::Status::kFinished) {
    concludeReview(grid, result.vertices, result.reviewed_measurements, parameters.eps_g_n);
    result.thermal_drift =
        concludeThermalDrift(grid, result.vertices, drift_references, parameters.eps_g_n);
  }
  fillUnreachableVertices(grid, result.vertices);
  result.simulated_seconds = device.time_s() - start_s;
  result.lipschitz_n_per_m = calibrator.lipschitzEstimate_n_per_m();
  result.peak_force_n = calibrator.peakForce_n();
  result.stop_retreats = calibrator.stopRetreats();
  result.saturation_count = device.saturationCount() - saturations_before;
  result.force_limit_ticks = result.saturation_count;
  result.servo_loop = stats.summary();
  return result;
}

AccuracyReport measureAccuracy(const GravityMap& map, const SimulatedDevice& device, int samples,
                               std::uint64_t seed) {
  AccuracyReport report;
  const WorkspaceGrid& grid = map.grid();
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = map.vertices()[static_cast<std::size_t>(i)];
    if (vertex.outcome != VertexOutcome::kConverged) continue;
    // The measurement, where it was made (a vertex beyond the stops is measured inside them).
    const Eigen::Vector3d truth = device.trueGravity(vertex.measuredAt_m(grid.vertexPosition(i)));
    const double error_n = (vertex.measuredGravity_n() - truth).norm();
    report.max_error_n = std::max(report.max_error_n, error_n);
    const double error = error_n / truth.norm();
    if (error > report.max_error_rel) {
      report.max_error_rel = error;
      report.worst_vertex = i;
    }
  }
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double sum_squared = 0.0;
  double sum_norm = 0.0;
  int reachable_samples = 0;
  for (int k = 0; k < samples; ++k) {
    const Eigen::Vector3d fraction(unit(random), unit(random), unit(random));
    const Eigen::Vector3d point = grid.minCorner_m() + grid.size_m().cwiseProduct(fraction);
    // A box fitted to the workspace pokes out of it; the map is judged where the hand can go.
    if (!device.isReachable(point)) continue;
    ++reachable_samples;
    const Eigen::Vector3d truth = device.trueGravity(point);
    sum_squared += (map.gravityAt(point) - truth).squaredNorm();
    sum_norm += truth.norm();
  }
  report.samples = reachable_samples;
  if (reachable_samples > 0) {
    report.mean_true_norm_n = sum_norm / reachable_samples;
    report.rms_residual_n = std::sqrt(sum_squared / reachable_samples);
    report.rms_residual_rel = report.rms_residual_n / report.mean_true_norm_n;
  }
  return report;
}

namespace {
// The reachable set of a simulated device lies in its workspace sphere (end stops beyond it);
// the bound is a little larger so that a device whose reach differs is not cut.
constexpr double kReachBoundFactor = 1.05;

ReachabilityTest reachabilityOf(const SimulatedDevice& device) {
  return [&device](const Eigen::Vector3d& position_m) { return device.isReachable(position_m); };
}
}  // namespace

namespace {
// The q-quantile of `values` (sorted in place), by the nearest rank; 0 when empty.
double quantile(std::vector<double>& values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::min(values.size() - 1, rank == 0 ? 0 : rank - 1)];
}

bool nearBoundary(const SimulatedDevice& device, const Eigen::Vector3d& point_m, double shell_m) {
  for (int x = -1; x <= 1; ++x) {
    for (int y = -1; y <= 1; ++y) {
      for (int z = -1; z <= 1; ++z) {
        if (x == 0 && y == 0 && z == 0) continue;
        const Eigen::Vector3d direction = Eigen::Vector3d(x, y, z).normalized();
        if (!device.isReachable(point_m + shell_m * direction)) return true;
      }
    }
  }
  return false;
}
}  // namespace

FieldErrorReport measureFieldError(const GravityMap& map, const SimulatedDevice& device,
                                   int samples, std::uint64_t seed, double shell_m,
                                   double breakaway_n) {
  if (samples < 1 || !(shell_m >= 0.0) || !(breakaway_n >= 0.0)) {
    throw Error(
        "measureFieldError: samples must be at least 1, shell_m and breakaway_n non-negative");
  }
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const double bound_m = kReachBoundFactor * device.specifications().workspace_radius_m;
  // The Falcon's cube has its corners beyond the inscribed radius: draw from the cube's corners.
  const double half_box_m = std::sqrt(3.0) * bound_m;
  FieldErrorReport report;
  report.breakaway_n = breakaway_n;
  long above_breakaway = 0;
  std::vector<double> errors, shell_errors;
  errors.reserve(static_cast<std::size_t>(samples));
  constexpr int kMaxDrawsPerSample = 1000;
  for (long draws = 0; report.samples < samples; ++draws) {
    if (draws > static_cast<long>(kMaxDrawsPerSample) * samples) {
      throw Error("measureFieldError: " + device.specifications().model_name +
                  " reaches almost none of its workspace box");
    }
    const Eigen::Vector3d point =
        device.workspaceCenter_m() +
        half_box_m * Eigen::Vector3d(unit(random), unit(random), unit(random));
    if (!device.isReachable(point)) continue;
    ++report.samples;
    const Eigen::Vector3d truth = device.trueGravity(point);
    const double error_n = (map.gravityAt(point) - truth).norm();
    const double error = error_n / truth.norm();
    errors.push_back(error);
    report.max_n = std::max(report.max_n, error_n);
    if (breakaway_n > 0.0 && error_n > breakaway_n) ++above_breakaway;
    if (error > report.max_rel) {
      report.max_rel = error;
      report.worst_point_m = point;
    }
    if (nearBoundary(device, point, shell_m)) shell_errors.push_back(error);
  }
  report.above_breakaway_fraction =
      static_cast<double>(above_breakaway) / static_cast<double>(report.samples);
  report.p50_rel = quantile(errors, 0.5);
  report.p90_rel = quantile(errors, 0.9);
  report.p99_rel = quantile(errors, 0.99);
  report.shell_samples = static_cast<int>(shell_errors.size());
  report.shell_p50_rel = quantile(shell_errors, 0.5);
  report.shell_p90_rel = quantile(shell_errors, 0.9);
  report.shell_p99_rel = quantile(shell_errors, 0.99);
  report.shell_max_rel = shell_errors.empty() ? 0.0 : shell_errors.back();
  return report;
}

WorkspaceFit fitGridToDevice(const SimulatedDevice& device, double target_coverage) {
  return fitWorkspaceBox(reachabilityOf(device), device.workspaceCenter_m(),
                         kReachBoundFactor * device.specifications().workspace_radius_m,
                         target_coverage);
}

double deviceWorkspaceCoverage(const SimulatedDevice& device, const WorkspaceGrid& grid) {
  return workspaceCoverage(grid, reachabilityOf(device), device.workspaceCenter_m(),
                           kReachBoundFactor * device.specifications().workspace_radius_m);
}

}  // namespace autograv::sim
