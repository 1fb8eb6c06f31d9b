#pragma once

// The values a calibration wizard run is set up with and shows: its steps, the events a front end
// posts, the configuration, and the status with its review and verify tables. The wizard itself is
// CalibrationWizard (calibration_wizard.h).

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/servo_clock.h"
#include "autograv/device/servo_loop_stats.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/initialization_estimator.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// The steps of the calibration wizard, in order, then the three ways it ends.
enum class WizardStep : std::uint8_t {
  kCheck,            ///< Device opens and is homed, specifications and parameters are sane.
  kCentre,           ///< The user brings the end-effector near the workspace centre.
  kRelease,          ///< The k0 field ramps in, the user lets go: G_hat_0 (paper eq. 7).
  kExplore,          ///< A soft probe finds the workspace from the device's own data.
  kAutoCalibration,  ///< The device visits the grid by itself (paper Sec. III-B).
  kReview,           ///< Results; the failed vertices can be redone.
  kSave,             ///< The map is written atomically.
  kVerify,           ///< Release tests at a few vertices with compensation on.
  kDone,             ///< Map saved (and verified); the device is held with compensation on.
  kAborted,          ///< The user stopped; finished vertices are in the checkpoint.
  kFault,            ///< Cannot go on (device fault, refused plan); see WizardStatus::message.
};

/// Stable lower-case name ("check", "centre", ..., "fault"). Real-time safe.
const char* toString(WizardStep step) noexcept;

/// What the front end tells the wizard. Events that mean nothing in the current step are ignored.
enum class WizardEvent : std::uint8_t {
  kConfirm,     ///< Centre: the end-effector is there. Check/Save: retry. Review: save as it is.
  kPause,       ///< AutoCalibration: hold the device where it is.
  kResume,      ///< AutoCalibration: go on after a pause.
  kAbort,       ///< Stop (checkpointing what is finished). In Verify: stop verifying.
  kRedoFailed,  ///< Review: visit again only the vertices that did not converge.
  kSkipRedo,    ///< Review: keep the result as it is and save it (same as kConfirm there).
};

/// Why Check stopped, so that a front end can answer for an unattended user.
enum class CheckIssue : std::uint8_t {
  kNone,               ///< Not stopped (or not checked yet).
  kOpenFailed,         ///< open() failed; Enter retries.
  kUncalibrated,       ///< calibrate() failed; Enter runs the device's homing.
  kEarlierCheckpoint,  ///< A checkpoint exists and WizardConfig::resume is false; Enter replaces
                       ///< it.
  kSettings,           ///< Specifications, grid or parameters refused; change them and restart.
};

/// Largest number of release tests in Verify.
inline constexpr int kMaxVerifyPoints = 8;

/// Settings of one wizard run. Set-up only. A value the run cannot use, and a setting it would
/// not use, are refused with a message naming the field: by CalibrationWizard's constructor
/// (autograv::Error), or by Check for what depends on the device or the checkpoint. No setting
/// is silently ignored. The first fields are what a run usually sets; `advanced` holds the rest.
struct WizardConfig {
  /// Where Save writes the map. Checkpoints go to map_path + ".partial", the convention of
  /// `autograv calibrate`, so either command resumes the other's run. Required.
  std::string map_path;
  /// Continue from the checkpoint map_path + ".partial": its finished vertices are kept bit for
  /// bit, and so are its grid and its explored workspace (the workspace is not explored again).
  bool resume = false;
  /// Where the user brings the end-effector in Centre, to let go of it there: near the middle of
  /// the workspace (CHAI3D devices report positions about the origin). The grid is fitted around
  /// the workspace explored from there. Unit: [m]
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
  /// Vertices along x, y, z of the grid: the box around the explored workspace (or
  /// advanced.box_size_m), each vertex measured where the end-effector can be.
  Eigen::Vector3i grid_resolution = Eigen::Vector3i::Constant(5);
  /// Release tests in Verify, with the saved map's compensation on (0 skips Verify; at most
  /// kMaxVerifyPoints).
  int verify_points = 3;
  /// The servo loop's time base, read once per servoTick(): every duration of the calibration is
  /// servo time from it, the wizard's compensation (GravityCompensatedDevice) is given the same
  /// reading, and the review says how regular the loop was. For a loop paced by the wall clock
  /// give a SteadyServoClock (calibrate() does); for a loop in simulated time its own clock.
  /// Null: a loop that ticks exactly every advanced.parameters.servo_period_s.
  std::shared_ptr<ServoClock> clock;

  /// The settings a run rarely changes. Each names the part of the method it tunes.
  struct Advanced {
    /// The estimation (paper Secs. II-III): gains, thresholds, the dither, the nominal servo
    /// period. The wizard checks them against the device at Check.
    EstimationParameters parameters;
    /// How the saved map reads the field between its measurements (MapMetadata::field_model): by
    /// default chosen from the measurements (FieldModel::kChoose); set one to force it.
    FieldModel field_model = kDefaultFieldModel;
    /// Lookup refinement written into the saved map (MapMetadata::lookup_refinement), lowered on
    /// a grid so fine that it would pass kMaxLookupVertices (lookupRefinementFor).
    int lookup_refinement = kDefaultLookupRefinement;
    /// Extents x, y, z of a box grid centred on centre_m, instead of the box around the explored
    /// workspace. It is still measured only inside the explored workspace (vertices beyond the
    /// stops are measured just inside them, or solved from the others). Empty: the grid is
    /// fitted to the explored workspace. Unit: [m]
    std::optional<Eigen::Vector3d> box_size_m;
    /// After the initialization, explore the workspace from the device's own data
    /// (WorkspaceExplorer: a soft probe that backs off from every stop) and measure only inside
    /// what it reached (planMeasurements), so that no move or hold targets a point beyond the
    /// stops. False needs box_size_m: every vertex of that box is visited where it is, which only
    /// a box well inside the workspace allows.
    bool explore = true;
    /// How the exploration probes (only with explore, and not when a resumed checkpoint holds
    /// its workspace).
    WorkspaceExplorer::Options explorer;
    /// An explored workspace is refused (Fault, before the grid run) when it is thinner than
    /// this along an axis: something held the end-effector (a hand, an object, a wall). Only
    /// with explore, as explorer. Unit: [m]
    double min_workspace_extent_m = 0.02;
    /// How the device travels between vertices and where each vertex starts.
    AutoCalibrator::Options calibrator;
    /// Centre is confirmed only this close to centre_m. Unit: [m]
    double centre_tolerance_m = 0.01;
    /// Fade-in time of the k0 field in Release. Unit: [s]
    double field_ramp_s = 0.3;
    /// After the field is on, how long the end-effector may take to settle before the wizard
    /// says that it does not (it keeps waiting). Unit: [s]
    double release_patience_s = 4.0;
    /// Hold at a verify vertex with compensation fully on before letting go (only with
    /// verify_points > 0). Unit: [s]
    double verify_settle_s = 0.8;
    /// Length of one release test (only with verify_points > 0). Unit: [s]
    double verify_release_s = 0.5;
    /// A release test stops early (and the device is caught) past this drift (only with
    /// verify_points > 0). Unit: [m]
    double verify_drift_limit_m = 0.01;
    /// The caller opened and homed the device and may still be driving it from its servo thread
    /// until the wizard's servo half takes over: the Check step then neither opens nor homes it
    /// again (that would touch the driver from the service thread while the servo thread uses
    /// it), it only reads the specifications.
    bool device_already_open = false;
    /// Serial number written into the map; empty takes the device's.
    std::string device_serial;
  };
  /// The rest of the settings; the defaults suit every device we know.
  Advanced advanced;
};

/// One release test of Verify.
struct VerifyResult {
  /// Grid index of the vertex tested.
  int vertex = -1;
  /// End-effector displacement while only the compensation acted. Unit: [m]
  double drift_m = 0.0;
  /// Duration of the test (shorter than WizardConfig::Advanced::verify_release_s when the drift
  /// limit was hit). Unit: [s]
  double duration_s = 0.0;
  /// Constant force that would cause that drift on the apparent mass |G_hat|/g from rest:
  /// 2 M d / t^2 (friction hides part of it). Unit: [N]
  double residual_force_n = 0.0;
  /// True once the test ended (drift limit or WizardConfig::Advanced::verify_release_s).
  bool finished = false;
};

/// One vertex of the review table.
struct ReviewRow {
  /// Grid index.
  int vertex = -1;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< Unit: [m]
  /// How the vertex ended.
  VertexOutcome outcome = VertexOutcome::kPending;
  /// Iterations it took.
  int iterations = 0;
  double seconds = 0.0;                                 ///< Unit: [s]
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();  ///< Unit: [N]
};

/// What Review shows: the whole grid in numbers, and the vertices to redo.
struct WizardReview {
  /// Vertices of the grid.
  int vertex_count = 0;
  /// Vertices that converged (restored ones included).
  int converged = 0;
  /// Fewest iterations of a converged vertex.
  int iterations_min = 0;
  /// Median iterations of the converged vertices.
  double iterations_median = 0.0;
  /// Most iterations of a converged vertex.
  int iterations_max = 0;
  /// Servo time spent estimating, moves excluded. Unit: [s]
  double estimation_seconds = 0.0;
  /// Smallest and largest |G_hat| over converged vertices. Unit: [N]
  double gravity_min_n = 0.0;
  /// Largest |G_hat| over the converged vertices. Unit: [N]
  double gravity_max_n = 0.0;
  /// Paper's Lipschitz constant c measured on the converged neighbours. Unit: [N/m]
  double lipschitz_n_per_m = 0.0;
  /// Largest force commanded by the calibration. Unit: [N]
  double peak_force_n = 0.0;
  /// Vertices that hit the iteration cap, never settled or faulted (not kPending, not
  /// kUnreachable).
  std::vector<ReviewRow> failed;
  /// Vertices never visited (a run aborted before them).
  int pending = 0;
  /// Vertices the device could not be held at (end stop, saturation, singular pose): not redone;
  /// the saved map fills them from their converged neighbours.
  int unreachable = 0;
  /// Converged vertices that came from the checkpoint of an earlier run.
  int restored = 0;
  /// Converged measurements that the others contradict (planReview): the redo measures each
  /// again, further from the stops (again_point_m); one that still stands out is left out of the
  /// saved map (concludeReview), its value solved from the others.
  std::vector<ReviewedMeasurement> measure_again;
  /// True once the redo took measure_again (and the drift points) to the device.
  bool measured_again = false;
  /// The first points the redo measures again to see what the motors' warming did during the
  /// calibration (planThermalDriftCheck), which the saved map then corrects (thermal_drift).
  int drift_points = 0;
};

/// True when a redo has something to do: vertices that failed or were never visited, or
/// contradicted measurements or drift points not yet measured again. Real-time safe.
inline bool offersRedo(const WizardReview& review) noexcept {
  return !review.failed.empty() || review.pending > 0 ||
         ((!review.measure_again.empty() || review.drift_points > 0) && !review.measured_again);
}

/// What the device was made to deliver so far: figures from the forces the wizard sent to the
/// device's driver (its own commands plus its compensation, after the force limit), so a real
/// device reports them as a simulated one does. The driver may still saturate a motor of its
/// own; a simulator knows that part too (sim::SimulatedDevice::saturationCount).
struct WizardForces {
  /// The device's continuous force rating the figures are judged against
  /// (continuousForceRating_n of its specifications), known once Check passed. Unit: [N]
  double continuous_rating_n = 0.0;
  /// The device's force limit (DeviceSpecifications::max_linear_force_n). Unit: [N]
  double limit_n = 0.0;
  /// Largest force sent. Unit: [N]
  double peak_n = 0.0;
  /// Servo time during which the force sent was above continuous_rating_n. Unit: [s]
  double above_continuous_s = 0.0;
  /// Servo ticks whose force was at limit_n (the wizard or its compensation clamped it there).
  std::uint64_t at_limit_ticks = 0;
};

/// Everything a front end shows, rebuilt by CalibrationWizard::status().
struct WizardStatus {
  /// The current step.
  WizardStep step = WizardStep::kCheck;
  /// 1-based number of the step among the eight of a normal run (0 for Aborted and Fault); a run
  /// that does not explore skips number 4.
  int step_number = 1;
  /// Steps of a normal run (Check to Done).
  static constexpr int kStepCount = 8;
  std::string title;    ///< e.g. "Centre the end-effector".
  std::string message;  ///< What is happening, with the live numbers; may span lines.
  std::string prompt;   ///< What the user should do now; empty when nothing.
  /// One line on the run (device, grid, resume), known once Check passed.
  std::string summary;
  /// True while the wizard waits for the user (a key, the stylus button, letting go).
  bool waiting_for_user = false;
  /// Check: why it stopped.
  CheckIssue check_issue = CheckIssue::kNone;

  /// Latest end-effector position and speed. Units: [m], [m/s]
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  /// Speed of the end-effector. Unit: [m/s]
  double speed_m_per_s = 0.0;
  /// False when the latest reading failed.
  bool position_valid = false;
  /// Servo time since the wizard started ticking. Unit: [s]
  double time_s = 0.0;

  // Centre.
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();     ///< Unit: [m]
  Eigen::Vector3d to_centre_m = Eigen::Vector3d::Zero();  ///< centre - position. Unit: [m]
  double centre_distance_m = 0.0;                         ///< Unit: [m]
  double centre_tolerance_m = 0.0;                        ///< Unit: [m]
  /// True when the end-effector is within centre_tolerance_m of the centre.
  bool within_tolerance = false;

  // Release.
  /// Where the manual initialization (eq. 7) stands.
  InitializationEstimator::Status release_status = InitializationEstimator::Status::kRampingIn;
  double sag_m = 0.0;       ///< Unit: [m]
  bool still_held = false;  ///< The estimator saw the hand carry the weight recently.
  /// Field on for WizardConfig::Advanced::release_patience_s and still no steady state.
  bool not_settling = false;
  double release_elapsed_s = 0.0;                               ///< Unit: [s]
  Eigen::Vector3d initial_gravity_n = Eigen::Vector3d::Zero();  ///< G_hat_0. Unit: [N]
  /// True once G_hat_0 is known.
  bool initial_gravity_valid = false;

  // Explore.
  /// What the exploration does now.
  WorkspaceExplorer::Status explorer_state = WorkspaceExplorer::Status::kIdle;
  int directions_probed = 0;  ///< Probe directions finished so far.
  int direction_count = 0;    ///< Probe directions in all.
  /// Shortest and longest reach found so far from the initialization's centre. Unit: [m]
  double reach_min_m = 0.0;
  double reach_max_m = 0.0;  ///< Unit: [m]
  /// Box around the boundary points found so far: the explored volume as it grows. Unit: [m]
  Eigen::Vector3d explored_low_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d explored_high_m = Eigen::Vector3d::Zero();  ///< Unit: [m]
  /// Where the probe target is now. Unit: [m]
  Eigen::Vector3d probe_target_m = Eigen::Vector3d::Zero();
  double exploration_elapsed_s = 0.0;  ///< Servo time of the exploration so far. Unit: [s]
  /// The explored workspace once known (explored now or restored from the checkpoint); empty
  /// before, and in a run that does not explore.
  ExploredWorkspace workspace;
  /// Where the grid's vertices are measured (once the workspace is known): at the vertex, just
  /// inside the stops, or not at all (beyond reach, solved from the others).
  int measured_at_vertex = 0;
  int measured_off_vertex = 0;  ///< Pulled inside the explored workspace.
  int beyond_reach = 0;         ///< Not measured; solved from the measured ones.

  // AutoCalibration.
  /// What the auto-calibration does now.
  AutoCalibrator::Status calibrator_state = AutoCalibrator::Status::kIdle;
  /// True while the user paused the auto-calibration.
  bool paused = false;
  int vertex = -1;            ///< Grid index being approached or estimated.
  int vertex_ordinal = 0;     ///< i of "vertex i of N" (1-based).
  int vertices_to_visit = 0;  ///< N.
  int vertex_count = 0;       ///< Whole grid.
  int converged = 0;          ///< Converged vertices so far (restored ones included).
  int iteration = 0;          ///< j at the current vertex.
  double delta_m = 0.0;       ///< Latest ||Delta_j||, NaN before the first update. Unit: [m]
  double eta_s = 0.0;         ///< Remaining servo time, NaN while unknown. Unit: [s]
  double calibration_elapsed_s = 0.0;  ///< Unit: [s]

  // Review (filled from the first Review on).
  /// Results of the calibration, valid when review_valid.
  WizardReview review;
  /// True once `review` is filled.
  bool review_valid = false;

  // Files.
  /// Where the map is saved (WizardConfig::map_path).
  std::string map_path;
  /// Where finished vertices are checkpointed (map_path + ".partial").
  std::string checkpoint_path;
  int checkpointed_converged = 0;  ///< Converged vertices in the last checkpoint written.
  /// True once a checkpoint was written.
  bool checkpoint_written = false;
  /// True once the map was saved.
  bool map_saved = false;
  std::string save_error;  ///< Why the last save failed (Save retries on kConfirm).

  // Verify.
  std::vector<VerifyResult> verify;  ///< One per test, finished ones first.
  int verify_index = 0;              ///< Test in progress (0-based).
  double max_drift_m = 0.0;          ///< Over finished tests. Unit: [m]
  /// True when the user stopped Verify before its end.
  bool verify_cancelled = false;

  /// Aborted / Fault: what happened and what to do.
  std::string fault;

  /// What the device was made to deliver so far, from the forces sent to it (any device).
  WizardForces force;

  /// What the servo loop did so far (rate, lateness beyond the nominal period, longest gap).
  ServoLoopStats::Summary servo_loop;
  /// Not empty when the loop was too irregular for the figures shown: what happened and what to
  /// do (servoLoopWarning).
  std::string servo_warning;
};

}  // namespace autograv
