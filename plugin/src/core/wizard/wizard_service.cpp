// CalibrationWizard, service half: the non-real-time side (device set-up, checks, the plan, the
// review, redo, save and the verify set-up). It runs on one thread; it hands objects to the servo
// half through the Impl's atomics and never touches what the servo half is stepping.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <system_error>

#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_summary.h"
#include "autograv/map/measurement_review.h"
#include "autograv/map/vertex_fill.h"
#include "core/wizard/wizard_impl.h"

namespace autograv {

using wizard::has;

namespace {

/// Fewest measurement points inside the explored workspace that make a map.
constexpr int kMinMeasurementPoints = 4;

/// Damping of the k0 field on a device that renders it stably. Unit: [N s/m]
constexpr double kFieldDamping_n_s_per_m = 5.0;

std::string millimetres(double metres) {
  std::ostringstream text;
  text.setf(std::ios::fixed);
  text.precision(1);
  text << metres * 1e3 << " mm";
  return text.str();
}

/// Messages of the plan check for the lightest |G| that the convergence check alone accepts:
/// when no |G| passes both checks, these name what to change. Empty when some |G| passes.
std::vector<std::string> refusalForAnyGravity(const EstimationParameters& parameters, double cell_m,
                                              double max_force_n) {
  constexpr int kSteps = 240;
  constexpr double kLightest_n = 0.01;
  double lightest_converging_n = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k <= kSteps; ++k) {
    const double gravity_n =
        kLightest_n * std::pow(max_force_n / kLightest_n, static_cast<double>(k) / kSteps);
    const Eigen::Vector3d gravity(0.0, 0.0, gravity_n);
    if (checkCalibrationPlan(parameters, cell_m, max_force_n, gravity).empty()) return {};
    if (std::isnan(lightest_converging_n) &&
        checkConvergence(parameters.beta_per_s2, gravity_n, parameters.lipschitz_prior_n_per_m)
            .ok) {
      lightest_converging_n = gravity_n;
    }
  }
  const double shown_n = std::isnan(lightest_converging_n) ? max_force_n : lightest_converging_n;
  return checkCalibrationPlan(parameters, cell_m, max_force_n, Eigen::Vector3d(0.0, 0.0, shown_n));
}

/// The review's per-vertex statistics of `vertices` on `grid` (`restored`: per vertex, converged
/// in the loaded checkpoint): what converged, failed, is pending or unreachable, and the
/// iteration and |G_hat| figures of the converged ones.
WizardReview reviewOf(const WorkspaceGrid& grid, const std::vector<VertexEstimate>& vertices,
                      const std::vector<char>& restored) {
  const MapSummary summary = summarizeVertices(vertices);
  WizardReview review;
  review.vertex_count = summary.vertices;
  review.converged = summary.converged;
  review.pending = summary.pending;
  review.unreachable = summary.unreachable;
  for (const int i : summary.failed) {
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
    review.failed.push_back(ReviewRow{i, grid.vertexPosition(i), vertex.outcome, vertex.iterations,
                                      vertex.seconds, vertex.gravity_n});
  }
  const ConvergedVertexStats& converged = summary.converged_only;
  review.iterations_min = converged.iterations.min;
  review.iterations_median = converged.iterations.median;
  review.iterations_max = converged.iterations.max;
  review.estimation_seconds = converged.seconds;
  review.gravity_min_n = converged.gravity_min_n;
  review.gravity_max_n = converged.gravity_max_n;
  for (int i = 0; i < review.vertex_count; ++i) {
    const bool converged_here =
        vertices[static_cast<std::size_t>(i)].outcome == VertexOutcome::kConverged;
    if (converged_here && restored[static_cast<std::size_t>(i)] != 0) ++review.restored;
  }
  return review;
}

}  // namespace

// --- Check -----------------------------------------------------------------------------------

void CalibrationWizard::Impl::runCheck(bool retry) {
  check_attempted_ = true;
  check_message_.clear();
  check_prompt_.clear();
  check_issue_ = CheckIssue::kNone;
  try {
    // opened_: the wizard opened the device, so it closes it too; one the caller opened stays
    // the caller's.
    if (!opened_ && !config_.advanced.device_already_open) {
      if (!device_->open()) {
        check_message_ =
            "The device did not open. Is it plugged in, switched on and not in use by another "
            "program?";
        check_prompt_ = "Press Enter to try again, q to quit.";
        check_issue_ = CheckIssue::kOpenFailed;
        return;
      }
      opened_ = true;
    }
    if (!config_.advanced.device_already_open && !device_->calibrate(force_calibrate_)) {
      force_calibrate_ = true;  // the retry runs the device's own homing
      check_message_ =
          "The device reports itself uncalibrated: its encoders are not homed, so every position "
          "it reports is offset and a map made now would be wrong.";
      check_prompt_ =
          "Put the end-effector in its rest (homing) position as the manufacturer describes, then "
          "press Enter: the wizard runs the device's calibration. q quits.";
      check_issue_ = CheckIssue::kUncalibrated;
      return;
    }
    const DeviceSpecifications& specifications = device_->specifications();
    validateSpecifications(specifications);
    max_force_n_ = specifications.max_linear_force_n;
    // The servo side is idle during Check: the figures it keeps of the forces sent are judged
    // against these.
    live_.force.limit_n = max_force_n_;
    live_.force.continuous_rating_n = continuousForceRating_n(specifications);

    const EstimationParameters& parameters = config_.advanced.parameters;
    // Without exploration a box fitted to the workspace has corners beyond it (found unreachable
    // and filled), but the middle of each face must lie inside the workspace sphere, or whole
    // faces are holes. An explored run measures only inside what the probe reached.
    const double half_extent_m = 0.5 * grid_.size_m().maxCoeff();
    if (!config_.advanced.explore && half_extent_m > specifications.workspace_radius_m) {
      std::ostringstream message;
      message << "The grid does not fit in the workspace: it reaches " << millimetres(half_extent_m)
              << " from the centre along an axis, the workspace radius is "
              << millimetres(specifications.workspace_radius_m)
              << ". Use a WizardConfig::advanced.box_size_m with no extent over "
              << std::floor(2.0 * specifications.workspace_radius_m * 1e3) * 1e-3 << " m ("
              << std::floor(2.0 * specifications.workspace_radius_m * 1e3) << " mm).";
      throw Error(message.str());
    }
    if (parameters.k0_n_per_m > specifications.max_linear_stiffness_n_per_m) {
      std::ostringstream message;
      message << "k0 = " << parameters.k0_n_per_m * 1e-3
              << " N/mm is stiffer than the device can render ("
              << specifications.max_linear_stiffness_n_per_m * 1e-3
              << " N/mm): lower EstimationParameters::k0_n_per_m to at most "
              << specifications.max_linear_stiffness_n_per_m << " N/m.";
      throw Error(message.str());
    }
    const std::vector<std::string> refusal = refusalForAnyGravity(
        parameters, AutoCalibrator::largestHoldStep_m(parameters, config_.advanced.calibrator),
        max_force_n_);
    if (!refusal.empty()) {
      std::string message =
          "These parameters cannot work on this device whatever its weight (paper Secs. IV and "
          "VI):";
      for (const auto& problem : refusal) message += "\n  - " + problem;
      throw Error(message);
    }
    // The constructors validate the remaining parameters with messages naming them.
    // The field's damping lets a device with little friction settle; it must stay well inside
    // what the device renders stably (an Omni-class arm quotes 3 N s/m).
    const double field_damping_n_s_per_m =
        std::min(kFieldDamping_n_s_per_m, 0.5 * specifications.max_linear_damping_n_s_per_m);
    initialization_ = std::make_unique<InitializationEstimator>(
        parameters, max_force_n_, config_.advanced.field_ramp_s, field_damping_n_s_per_m);
    if (config_.advanced.explore) {
      explorer_ = std::make_unique<WorkspaceExplorer>(parameters, specifications,
                                                      config_.advanced.explorer);
      probe_directions_ = explorer_->directions();
      explored_reach_m_.assign(probe_directions_.size(), 0.0);
      live_.direction_count = explorer_->directionCount();
    }
    grid_fixed_ = config_.advanced.box_size_m.has_value();

    const std::filesystem::path folder = std::filesystem::path(config_.map_path).parent_path();
    std::error_code error;
    if (!folder.empty() && !std::filesystem::is_directory(folder, error)) {
      throw Error("The folder of the map file, " + folder.string() +
                  ", does not exist: create it or choose another WizardConfig::map_path.");
    }

    if (config_.resume) {
      restoreCheckpoint(specifications.model_name);
    } else if (!retry && std::filesystem::exists(checkpoint_path_, error)) {
      check_message_ = "A checkpoint of an earlier, unfinished run exists: " + checkpoint_path_ +
                       ". Starting afresh replaces it at the first finished vertex.";
      check_prompt_ =
          "Quit with q and run again with WizardConfig::resume = true to continue it, or press "
          "Enter to start afresh.";
      check_issue_ = CheckIssue::kEarlierCheckpoint;
      return;
    }
    // The workspace of a resumed run is kept: it is not explored again.
    explore_now_ = config_.advanced.explore && workspace_.empty();
    if (!explore_now_) {
      useGrid(grid_, config_.resume ? &resumed_vertices_ : nullptr);
    } else {
      calibrator_.reset();  // built once the workspace is known
    }
    device_model_ = specifications.model_name;
    summarize();
    check_passed_ = true;
  } catch (const Error& error) {
    check_message_ = error.what();
    check_prompt_ = "Change what is named above and start again (q quits, Enter checks again).";
    check_issue_ = CheckIssue::kSettings;
  } catch (const std::exception& error) {
    check_message_ = std::string("Unexpected error: ") + error.what();
    check_prompt_ = "q quits, Enter checks again.";
    check_issue_ = CheckIssue::kSettings;
  }
}

void CalibrationWizard::Impl::useGrid(const WorkspaceGrid& grid,
                                      const std::vector<VertexEstimate>* restored) {
  AutoCalibrator::Options options = config_.advanced.calibrator;
  if (!(options.continuous_force_n > 0.0)) {
    options.continuous_force_n = continuousForceRating_n(device_->specifications());
  }
  auto calibrator =
      std::make_unique<AutoCalibrator>(grid, config_.advanced.parameters, max_force_n_, options);
  if (restored != nullptr) calibrator->restore(*restored);
  MeasurementPlan plan = planMeasurements(grid, workspace_);
  calibrator->setPlan(plan);
  const auto count = static_cast<std::size_t>(grid.vertexCount());
  // The mirror starts as the calibrator does: restored vertices, and those the plan skips marked
  // unreachable. Its histories have room for every iteration, so that the servo side's copies
  // into it allocate nothing.
  std::vector<VertexEstimate> mirror = calibrator->vertices();
  for (auto& vertex : mirror) {
    vertex.history.reserve(static_cast<std::size_t>(config_.advanced.parameters.max_iterations));
  }
  restored_.assign(count, 0);
  if (restored != nullptr) {
    for (std::size_t i = 0; i < count; ++i) {
      restored_[i] = (*restored)[i].outcome == VertexOutcome::kConverged ? 1 : 0;
    }
  }
  copy_pending_.assign(count, 0);
  {
    wizard::ScopedLock lock(mirror_busy_);
    mirror_ = std::move(mirror);
  }
  grid_ = grid;
  plan_ = std::move(plan);
  calibrator_ = std::move(calibrator);
}

void CalibrationWizard::Impl::summarize() {
  std::ostringstream summary;
  summary << device_model_ << ", max force " << max_force_n_ << " N; grid ";
  if (calibrator_) {
    summary << grid_.describe();
  } else {
    summary << config_.grid_resolution.x() << "x" << config_.grid_resolution.y() << "x"
            << config_.grid_resolution.z() << " vertices around the workspace explored first";
  }
  if (!workspace_.empty()) {
    summary << "; workspace "
            << (config_.resume && !explore_now_ ? "from the checkpoint" : "explored") << ": reach "
            << millimetres(workspace_.minRadius_m()) << " to "
            << millimetres(workspace_.maxRadius_m()) << ", measured " << plan_.at_vertex
            << " at vertices, " << plan_.off_vertex << " just inside the stops, " << plan_.skipped
            << " beyond reach";
  }
  if (config_.resume) {
    summary << "; resuming " << std::count(restored_.begin(), restored_.end(), 1)
            << " converged vertices from " << checkpoint_path_;
  }
  summary_ = summary.str();
}

void CalibrationWizard::Impl::acceptWorkspace() {
  workspace_message_.clear();
  try {
    ExploredWorkspace workspace =
        exploredWorkspaceOf(explored_center_m_, probe_directions_, explored_reach_m_);
    // Its box, found as gridAroundWorkspace finds it.
    const Eigen::Vector3d extent_m =
        gridAroundWorkspace(workspace, Eigen::Vector3i::Constant(2)).size_m();
    Eigen::Index thinnest = 0;
    if (extent_m.minCoeff(&thinnest) < config_.advanced.min_workspace_extent_m) {
      static const char* const kAxes[3] = {"x (toward you)", "y (left-right)", "z (up-down)"};
      std::ostringstream message;
      message << "The explored workspace is too small to calibrate: the probe reached only "
              << millimetres(extent_m[thinnest]) << " along " << kAxes[thinnest] << " (box "
              << millimetres(extent_m.x()) << " x " << millimetres(extent_m.y()) << " x "
              << millimetres(extent_m.z()) << "; reach " << millimetres(workspace.minRadius_m())
              << " to " << millimetres(workspace.maxRadius_m()) << " from the centre), at least "
              << millimetres(config_.advanced.min_workspace_extent_m)
              << " is needed along every axis. Something held the end-effector: let go of it, "
                 "clear the space around the device (nothing may touch the arm), and start "
                 "again.";
      throw Error(message.str());
    }
    // Where the initialization settled, from driver data: resting on a stop spoils G_hat_0.
    const std::string clearance = initializationClearanceProblem(workspace, explored_center_m_);
    if (!clearance.empty()) {
      throw Error("The initialization is not to be trusted: " + clearance + ".");
    }
    workspace_ = std::move(workspace);
    const WorkspaceGrid grid =
        grid_fixed_ ? grid_ : gridAroundWorkspace(workspace_, config_.grid_resolution);
    useGrid(grid, resumed_vertices_.empty() ? nullptr : &resumed_vertices_);
    const int measured = plan_.at_vertex + plan_.off_vertex;
    if (measured < kMinMeasurementPoints) {
      std::ostringstream message;
      message << "The grid " << grid.describe() << " has only " << measured
              << " measurement points inside the explored workspace: it lies mostly beyond "
                 "the stops. Fit the grid to the workspace instead "
                 "(leave WizardConfig::advanced.box_size_m empty).";
      calibrator_.reset();
      throw Error(message.str());
    }
    summarize();
    // A checkpoint now keeps the workspace and the grid, so that a run stopped before its first
    // vertex resumes without exploring again.
    {
      wizard::ScopedLock lock(mirror_busy_);
      ++mirror_version_;
    }
    replies_.fetch_or(wizard::kReplyWorkspaceAccepted, std::memory_order_acq_rel);
  } catch (const Error& error) {
    workspace_message_ = error.what();
    replies_.fetch_or(wizard::kReplyWorkspaceRefused, std::memory_order_acq_rel);
  }
}

// --- The service loop ------------------------------------------------------------------------

void CalibrationWizard::Impl::service() {
  if (step() == WizardStep::kCheck) {
    const std::uint32_t events = events_.exchange(0, std::memory_order_acq_rel);
    if (has(events, WizardEvent::kAbort)) {
      phase_.store(WizardStep::kAborted, std::memory_order_release);
      return;
    }
    const bool retry = has(events, WizardEvent::kConfirm);
    if (!check_attempted_ || retry) runCheck(retry);
    if (check_passed_) {
      // The servo side is idle during Check: its state may be set here, published by the store.
      events_.store(0, std::memory_order_relaxed);
      live_.step = WizardStep::kCentre;
      phase_.store(WizardStep::kCentre, std::memory_order_release);
    }
    return;
  }

  const std::uint32_t requests = requests_.exchange(0, std::memory_order_acq_rel);
  if ((requests & wizard::kRequestPlanCheck) != 0) {
    // The moves are minimum-jerk paths: the gap they leave, not a whole cell, is what the PD
    // must close (AutoCalibrator::largestHoldStep_m).
    const std::vector<std::string> problems = checkCalibrationPlan(
        config_.advanced.parameters,
        AutoCalibrator::largestHoldStep_m(config_.advanced.parameters, config_.advanced.calibrator),
        max_force_n_, plan_gravity_n_);
    plan_message_.clear();
    for (const auto& problem : problems) plan_message_ += "\n  - " + problem;
    replies_.fetch_or(problems.empty() ? wizard::kReplyPlanAccepted : wizard::kReplyPlanRefused,
                      std::memory_order_acq_rel);
  }
  if ((requests & wizard::kRequestWorkspace) != 0) acceptWorkspace();
  writeCheckpoint();
  // Review, redo and save read the mirror: wait until the servo side has flushed it.
  std::uint32_t deferred = 0;
  const bool mirror_ready = !mirror_pending_.load(std::memory_order_acquire);
  if ((requests & wizard::kRequestReview) != 0) {
    if (mirror_ready)
      buildReview();
    else
      deferred |= wizard::kRequestReview;
  }
  if ((requests & wizard::kRequestRedo) != 0) {
    if (mirror_ready)
      prepareRedo();
    else
      deferred |= wizard::kRequestRedo;
  }
  if ((requests & wizard::kRequestSave) != 0) {
    if (mirror_ready)
      saveAndPrepareVerify();
    else
      deferred |= wizard::kRequestSave;
  }
  if (deferred != 0) requests_.fetch_or(deferred, std::memory_order_acq_rel);
  device_->reclaimRetiredMaps();
}

void CalibrationWizard::Impl::buildReview() {
  const std::vector<VertexEstimate> vertices = mirrorCopy(nullptr);
  WizardReview review = reviewOf(grid_, vertices, restored_);
  if (!review_planned_) {
    // Once, after the pass over the plan: the measurements the others contradict.
    review_planned_ = true;
    reviewed_ = planReview(grid_, vertices, config_.advanced.parameters.eps_g_n);
    std::vector<int> measured_anyway;
    for (const ReviewedMeasurement& entry : reviewed_)
      measured_anyway.push_back(entry.first.vertex);
    for (const ReviewRow& row : review.failed) measured_anyway.push_back(row.vertex);
    drift_references_ = planThermalDriftCheck(grid_, vertices, measured_anyway);
  }
  review.measure_again = reviewed_;
  review.drift_points = static_cast<int>(drift_references_.size());
  review.measured_again = remeasure_sent_;
  {
    wizard::ScopedLock lock(live_busy_);
    review.lipschitz_n_per_m = live_shared_.lipschitz_n_per_m;
    review.peak_force_n = live_shared_.peak_force_n;
  }
  review_ = std::move(review);
  review_valid_ = true;
}

void CalibrationWizard::Impl::prepareRedo() {
  // An unreachable vertex would hit the same stop again (needsAnotherVisit).
  std::vector<int> redo = summarizeVertices(mirrorCopy(nullptr)).to_visit_again;
  std::vector<int> last;  // the drift points, measured after the others
  if (!remeasure_sent_) {
    for (const ReviewedMeasurement& entry : reviewed_) {
      calibrator_->remeasureAt(entry.first.vertex, entry.again_point_m);
      redo.push_back(entry.first.vertex);
    }
    for (const DriftReference& reference : drift_references_) {
      calibrator_->remeasureAt(reference.vertex, reference.point_m);
      last.push_back(reference.vertex);
    }
    remeasure_sent_ = true;
  }
  if (redo.empty() && last.empty()) {
    redo_message_ = "Nothing to redo: every reachable vertex converged.";
    replies_.fetch_or(wizard::kReplyNothingToRedo, std::memory_order_acq_rel);
    return;
  }
  // The servo side holds the device with its own PD during Review: the calibrator is ours now.
  calibrator_->visitOnly(redo, last);
  redo_message_.clear();
  replies_.fetch_or(wizard::kReplyRedoReady, std::memory_order_acq_rel);
}

std::vector<int> CalibrationWizard::Impl::chooseVerifyVertices(
    const std::vector<VertexEstimate>& vertices) const {
  std::vector<int> converged;
  for (int i = 0; i < grid_.vertexCount(); ++i) {
    if (vertices[static_cast<std::size_t>(i)].outcome == VertexOutcome::kConverged) {
      converged.push_back(i);
    }
  }
  std::vector<int> chosen;
  if (converged.empty() || config_.verify_points == 0) return chosen;
  // Where each was measured: a vertex beyond the stops is tested where it was measured.
  const auto point = [&](int vertex) {
    const VertexEstimate& estimate = vertices[static_cast<std::size_t>(vertex)];
    return estimate.measuredAt_m(grid_.vertexPosition(vertex));
  };
  // The vertex nearest the centre, then each time the one farthest from those chosen: a few
  // tests that still span the grid.
  const auto nearest = std::min_element(converged.begin(), converged.end(), [&](int a, int b) {
    return (point(a) - grid_.center_m()).norm() < (point(b) - grid_.center_m()).norm();
  });
  chosen.push_back(*nearest);
  const auto wanted =
      std::min<std::size_t>(static_cast<std::size_t>(config_.verify_points), converged.size());
  while (chosen.size() < wanted) {
    int best = -1;
    double best_distance = -1.0;
    for (int candidate : converged) {
      double distance = std::numeric_limits<double>::infinity();
      for (int taken : chosen) {
        distance = std::min(distance, (point(candidate) - point(taken)).norm());
      }
      if (distance > best_distance) {
        best_distance = distance;
        best = candidate;
      }
    }
    chosen.push_back(best);
  }
  return chosen;
}

void CalibrationWizard::Impl::saveAndPrepareVerify() {
  std::vector<VertexEstimate> vertices = mirrorCopy(nullptr);
  std::shared_ptr<const GravityMap> map;
  try {
    // Judged again: what still stands out is left out of the fit (measured again or not).
    std::vector<ReviewedMeasurement> reviewed = reviewed_;
    concludeReview(grid_, vertices, reviewed, config_.advanced.parameters.eps_g_n);
    // The drift points read what they read first when the redo was not run: nothing to see.
    const ThermalDrift drift = concludeThermalDrift(
        grid_, vertices, remeasure_sent_ ? drift_references_ : std::vector<DriftReference>{},
        config_.advanced.parameters.eps_g_n);
    fillUnreachableVertices(grid_, vertices);
    MapMetadata map_metadata = metadata();
    map_metadata.reviewed_measurements = std::move(reviewed);
    map_metadata.thermal_drift = drift;
    map = std::make_shared<const GravityMap>(grid_, vertices, std::move(map_metadata));
    saveMap(*map, config_.map_path);
  } catch (const Error& error) {
    save_error_ = error.what();
    replies_.fetch_or(wizard::kReplySaveFailed, std::memory_order_acq_rel);
    return;
  }
  save_error_.clear();
  map_saved_ = true;
  std::error_code ignored;
  std::filesystem::remove(checkpoint_path_, ignored);  // the map supersedes it
  verify_vertices_ = chooseVerifyVertices(vertices);
  verify_targets_m_.clear();
  for (int vertex : verify_vertices_) {
    const VertexEstimate& estimate = vertices[static_cast<std::size_t>(vertex)];
    verify_targets_m_.push_back(estimate.measuredAt_m(grid_.vertexPosition(vertex)));
  }
  if (!verify_vertices_.empty()) {
    try {
      device_->publishMap(map);
    } catch (const Error& error) {
      verify_vertices_.clear();
      save_error_ = std::string("verification skipped: ") + error.what();
    }
  }
  saved_map_ = std::move(map);
  replies_.fetch_or(wizard::kReplySaved, std::memory_order_acq_rel);
}

}  // namespace autograv
