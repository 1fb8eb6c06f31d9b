#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/workspace_fit.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

/// Result of the manual initialization (paper Sec. III-A) done by the simulated hand.
struct InitializationResult {
  /// True when G_hat_0 was found; else `message` says why.
  bool ok = false;
  std::string message;                                  ///< Why not, when !ok.
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();  ///< G_hat_0 (eq. 7). Unit: [N]
  Eigen::Vector3d center_m = Eigen::Vector3d::Zero();   ///< X0. Unit: [m]
  Eigen::Vector3d settled_m = Eigen::Vector3d::Zero();  ///< X_inf. Unit: [m]
  double seconds = 0.0;                                 ///< Simulated. Unit: [s]
  /// The end-effector touched a mechanical end stop after the hand let go: X_inf is not where the
  /// k0 field alone put it, so eq. (7) does not hold (then ok is false and message says so).
  bool end_stop_hit = false;
};

/// The manual step as a person would do it: the simulated hand grabs the end-effector, carries it
/// to `center_m`, the k0 field fades in, the hand lets go, and eq. (7) gives G_hat_0 once the
/// end-effector settles. Fails (ok false, with a message) when the end-effector rested on an end
/// stop meanwhile. Runs the servo loop on simulated time, ticking as `timing` draws (null: exactly
/// every servo period) and recording the ticks into `stats` (null: nowhere). Not real-time safe.
InitializationResult initializeWithSimulatedHand(SimulatedDevice& device,
                                                 const EstimationParameters& parameters,
                                                 const Eigen::Vector3d& center_m,
                                                 double timeout_s = 30.0,
                                                 ServoTimingModel* timing = nullptr,
                                                 ServoLoopStats* stats = nullptr);

/// What the workspace exploration did on a simulated device.
struct ExplorationResult {
  ExploredWorkspace workspace;  ///< Empty when stopped.
  double seconds = 0.0;         ///< Servo time. Unit: [s]
  /// Longest time from the end-effector's last progress to a recognised stop. Unit: [s]
  double longest_recognition_s = 0.0;
  double seconds_above_continuous_force = 0.0;  ///< Unit: [s]
  double peak_force_n = 0.0;                    ///< Largest force sent. Unit: [N]
  std::uint64_t saturation_count = 0;           ///< setForce calls the device clamped.
  bool stopped = false;                         ///< stop_requested was honoured.
};

/// Runs WorkspaceExplorer on `device` from the end-effector at rest where `initialization` left
/// it, on simulated time ticked by `timing` (exact when null; `stats` records the loop when
/// given). Throws autograv::Error when the device stops answering. Not real-time safe.
ExplorationResult exploreWorkspace(SimulatedDevice& device, const EstimationParameters& parameters,
                                   const InitializationResult& initialization,
                                   const WorkspaceExplorer::Options& options = {},
                                   const std::atomic<bool>* stop_requested = nullptr,
                                   double timeout_s = 600.0, ServoTimingModel* timing = nullptr,
                                   ServoLoopStats* stats = nullptr);

/// The paper's Section V experiment on a simulated device.
struct PaperExperimentResult {
  /// The manual initialization before the experiment.
  InitializationResult initialization;
  VertexEstimate estimate;                                   ///< Outcome, iterations, history.
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();        ///< X_D. Unit: [m]
  Eigen::Vector3d gravity_true_n = Eigen::Vector3d::Zero();  ///< G(X_D). Unit: [N]
  double mass_true_kg = 0.0;       ///< |G(X_D)| / g, the "force sensor" of Fig. 9. Unit: [kg]
  double simulated_seconds = 0.0;  ///< Unit: [s]
};

/// Initializes at the paper's start point [-9.2, -68.3, 11.6] mm (the user's choice of X0), then
/// runs the inner loop at X_D = [0, -30, 0] mm (paper frame) from there.
/// Not real-time safe.
PaperExperimentResult runPaperExperiment(SimulatedDevice& device,
                                         const EstimationParameters& parameters);

/// Settings of runSimulatedCalibration.
struct CalibrationRunOptions {
  /// Explore the workspace from the device's own data before the grid run (WorkspaceExplorer),
  /// and measure only inside what it reached (planMeasurements). False: every vertex is visited
  /// where it is, as before the exploration existed.
  bool explore = true;
  /// With explore: fit the grid's box to the explored workspace (gridAroundWorkspace, with
  /// grid_resolution) instead of grid_center_m and grid_size_m.
  bool grid_from_workspace = false;
  /// Where the simulated hand initializes (X0) when grid_from_workspace; else the grid's centre.
  /// Unit: [m]
  Eigen::Vector3d initialization_center_m = Eigen::Vector3d::Zero();
  WorkspaceExplorer::Options explorer;  ///< How the exploration probes.
  /// A workspace explored before (a resumed run's checkpoint): used instead of exploring again.
  ExploredWorkspace workspace;
  /// Centre of the grid's box. Unit: [m]
  Eigen::Vector3d grid_center_m = Eigen::Vector3d::Zero();
  /// Extent of the grid's box along x, y, z. Unit: [m]
  Eigen::Vector3d grid_size_m = Eigen::Vector3d::Constant(0.06);
  /// Vertices along x, y, z.
  Eigen::Vector3i grid_resolution = Eigen::Vector3i::Constant(4);
  /// The estimation (paper Secs. II-III).
  EstimationParameters parameters;
  /// How the device travels between vertices.
  AutoCalibrator::Options calibrator;
  /// Finished vertices of an earlier, interrupted run (empty: start afresh).
  std::vector<VertexEstimate> resume_from;
  /// Called every `progress_period_s` of simulated time, and when a vertex finishes.
  std::function<void(const AutoCalibrator&)> on_progress;
  /// Simulated time between two on_progress calls. Unit: [s]
  double progress_period_s = 0.5;
  /// Called once the workspace is explored and the grid known, before the grid run.
  std::function<void(const ExploredWorkspace&, const WorkspaceGrid&)> on_explored;
  /// Called after each finished vertex (checkpoint it here: it runs between servo ticks).
  std::function<void(const AutoCalibrator&, int vertex)> on_vertex_finished;
  /// Set to true from another thread or a signal handler to stop after the current tick.
  const std::atomic<bool>* stop_requested = nullptr;
  /// Gives up when the whole run exceeds this much simulated time. Unit: [s]
  double timeout_s = 3600.0;
  /// How the servo ticks arrive (README, "Servo timing"), drawn from servo_timing_seed; the
  /// nominal period is parameters.servo_period_s.
  ServoTiming servo_timing = ServoTiming::kExact;
  std::uint64_t servo_timing_seed = 1;  ///< Seed of the timing model's draws.
  /// After the grid, visit again the vertices that did not converge, up to this many times (what
  /// the wizard's Review offers a user): a vertex that missed its steady state once, because of
  /// an encoder's one-count dither, usually settles on a second visit.
  int redo_passes = 1;
  /// After the grid, judge the measurements against one another (planReview): those that stand
  /// out are measured again, further from the stops, in the first redo pass (as the wizard's
  /// Review does), and those that stand out again are left out of the fit (concludeReview).
  bool review_measurements = true;
};

/// What runSimulatedCalibration measured.
struct CalibrationRunResult {
  /// How the outer loop ended.
  AutoCalibrator::Status status = AutoCalibrator::Status::kIdle;
  /// The manual initialization (G_hat_0).
  InitializationResult initialization;
  /// The grid calibrated (the options' box, or the one fitted to the explored workspace).
  WorkspaceGrid grid{Eigen::Vector3d::Zero(), 0.06, 2};
  ExploredWorkspace workspace;       ///< Empty without explore.
  MeasurementPlan plan;              ///< Where each vertex was measured.
  double exploration_seconds = 0.0;  ///< Servo time of the exploration. Unit: [s]
  /// Longest time from the end-effector's last progress to a recognised stop. Unit: [s]
  double longest_stop_recognition_s = 0.0;
  /// Servo ticks whose force reached the device's limit (clamped by the device), and the servo
  /// time spent above its continuous rating, exploration and grid run together. Unit: [s]
  std::uint64_t force_limit_ticks = 0;
  double seconds_above_continuous_force = 0.0;  ///< Unit: [s]
  /// Every vertex; the unreachable ones filled from the converged ones (AutoCalibrator::makeMap).
  std::vector<VertexEstimate> vertices;
  double simulated_seconds = 0.0;      ///< Initialization included. Unit: [s]
  double lipschitz_n_per_m = 0.0;      ///< Paper's c, measured. Unit: [N/m]
  double peak_force_n = 0.0;           ///< Largest force commanded. Unit: [N]
  std::uint64_t saturation_count = 0;  ///< setForce calls the device clamped.
  bool stopped = false;                ///< stop_requested was honoured.
  int redo_passes = 0;                 ///< Passes over failed vertices actually run.
  int redone_vertices = 0;             ///< Vertex visits made by those passes.
  /// The measurements that stood out, measured again, and what the review made of each.
  std::vector<ReviewedMeasurement> reviewed_measurements;
  /// What the review's points measured again saw of the motors warming (concludeThermalDrift),
  /// already taken out of `vertices`.
  ThermalDrift thermal_drift;
  int stop_retreats = 0;  ///< Points moved back from a stop (AutoCalibrator::stopRetreats).
  ServoLoopStats::Summary servo_loop;  ///< What the servo loop did, initialization included.
};

/// Whole off-line autocalibration on a simulated device: feasibility checks (refused with a
/// message before the device moves by itself), manual initialization by the simulated hand, then
/// the outer loop over every vertex. Throws autograv::Error when a check fails or the
/// initialization cannot finish. Not real-time safe.
CalibrationRunResult runSimulatedCalibration(SimulatedDevice& device,
                                             const CalibrationRunOptions& options);

/// The default calibration box of `device`: fitted to its reachable workspace (isReachable) so
/// that at least `target_coverage` of it lies inside, with the coverage measured on other
/// samples. Deterministic. Not real-time safe.
WorkspaceFit fitGridToDevice(const SimulatedDevice& device, double target_coverage = 0.9);

/// Fraction of `device`'s reachable workspace inside `grid` (Monte Carlo, seeded).
/// Not real-time safe.
double deviceWorkspaceCoverage(const SimulatedDevice& device, const WorkspaceGrid& grid);

/// Accuracy of a map against the device's ground truth.
struct AccuracyReport {
  /// Worst measured point |G_hat - G| / |G| (a converged vertex, or its point inside the
  /// workspace when it was measured off the vertex).
  double max_error_rel = 0.0;
  /// Grid index of the worst measured vertex (-1 when none).
  int worst_vertex = -1;
  double max_error_n = 0.0;  ///< Worst converged vertex |G_hat - G| (maybe another one). Unit: [N]
  double rms_residual_n = 0.0;    ///< RMS of |G_hat(X) - G(X)| at random points. Unit: [N]
  double rms_residual_rel = 0.0;  ///< rms_residual_n / mean |G|.
  double mean_true_norm_n = 0.0;  ///< Unit: [N]
  int samples = 0;                ///< Random points that were reachable (the RMS is over these).
};

/// Compares `map` with `device.trueGravity` at every converged vertex and at those of `samples`
/// seeded random points inside the grid that the device can reach (isReachable).
/// Not real-time safe.
AccuracyReport measureAccuracy(const GravityMap& map, const SimulatedDevice& device,
                               int samples = 1000, std::uint64_t seed = 1);

/// The error of a map's field where the hand can be: |G_hat(X) - G(X)| / |G(X)| at points drawn
/// uniformly from the device's reachable workspace (isReachable, so ground truth: for scoring
/// only), inside the grid's box or not. The shell is the part within `shell_m` of the workspace's
/// boundary, where hands rest against the stops.
struct FieldErrorReport {
  int samples = 0;       ///< Points drawn (all reachable).
  double p50_rel = 0.0;  ///< Median of the relative error.
  double p90_rel = 0.0;  ///< 90th percentile.
  double p99_rel = 0.0;  ///< 99th percentile.
  double max_rel = 0.0;  ///< Largest.
  double max_n = 0.0;    ///< Largest |G_hat(X) - G(X)|. Unit: [N]
  /// Where max_rel was found. Unit: [m]
  Eigen::Vector3d worst_point_m = Eigen::Vector3d::Zero();
  int shell_samples = 0;       ///< Of those, the points within shell_m of the boundary.
  double shell_p50_rel = 0.0;  ///< The same over the shell's points.
  double shell_p90_rel = 0.0;  ///< 90th percentile in the shell.
  double shell_p99_rel = 0.0;  ///< 99th percentile in the shell.
  double shell_max_rel = 0.0;  ///< Largest in the shell.
  /// The force a released stylus must feel to move: measureFieldError's `breakaway_n` (0 when not
  /// given). Unit: [N]
  double breakaway_n = 0.0;
  /// Share of the points (of the reachable workspace's volume) whose error |G_hat - G| exceeds
  /// breakaway_n: where a released stylus drifts instead of staying put (0 when none was given).
  double above_breakaway_fraction = 0.0;
};

/// Points the tools draw for FieldErrorReport. The tail figures rest on few of them (the 99th
/// percentile on the worst 1 %, the maximum on one): with 4000, one sim:omni map's p99 read
/// 2.82-3.87 % over eight draws of the points and its shell p99 6.5-9.0 %; with 200000, 3.25-3.36
/// and 7.0-7.6 % (README, "How many points the field figures need"). About 0.5 s per run.
constexpr int kFieldErrorSamples = 200000;

/// Draws `samples` reachable points uniformly (seeded) and measures the map's error there; a point
/// is in the shell when a point `shell_m` away from it in one of 26 directions is unreachable.
/// With `breakaway_n` > 0 (the device's breakaway force, sim::measureFriction), also the share of
/// points whose error in newtons exceeds it. Deterministic. Not real-time safe. Units: [m], [N]
FieldErrorReport measureFieldError(const GravityMap& map, const SimulatedDevice& device,
                                   int samples = kFieldErrorSamples, std::uint64_t seed = 1,
                                   double shell_m = 5e-3, double breakaway_n = 0.0);

}  // namespace autograv::sim
