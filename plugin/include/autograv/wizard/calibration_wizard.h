#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/haptic_device.h"
#include "autograv/device/servo_clock.h"
#include "autograv/device/servo_loop_stats.h"
#include "autograv/device/servo_sample.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/initialization_estimator.h"
#include "autograv/estimation/minimum_jerk_move.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/workspace_grid.h"

namespace autograv {

namespace wizard {
struct Live;  // the servo side's live numbers (plugin/src/core/wizard_internal.h)
}  // namespace wizard

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

/// Settings of one wizard run. Set-up only.
struct WizardConfig {
  /// Where the user brings the end-effector for the initialization (Centre), and the centre of
  /// the box grid when the grid is not fitted to the explored workspace. Unit: [m]
  Eigen::Vector3d grid_center_m = Eigen::Vector3d::Zero();
  /// Box extents x, y, z of the grid when it is not fitted to the explored workspace
  /// (grid_from_workspace false, or explore false). Unit: [m]
  Eigen::Vector3d grid_size_m = Eigen::Vector3d::Constant(0.06);
  Eigen::Vector3i grid_resolution = Eigen::Vector3i::Constant(5);  ///< Vertices along x, y, z.
  /// After the initialization, explore the workspace from the device's own data
  /// (WorkspaceExplorer: a soft probe that backs off from every stop) and measure only inside
  /// what it reached (planMeasurements): no move and no hold targets a point beyond the stops.
  /// False: every vertex of the box is visited where it is, as before exploration existed.
  bool explore = true;
  /// With explore: the grid is the box around the explored workspace (gridAroundWorkspace with
  /// grid_resolution), as `autograv calibrate` makes it by default. False: the box
  /// grid_center_m, grid_size_m, measured inside the explored workspace.
  bool grid_from_workspace = true;
  /// How the exploration probes.
  WorkspaceExplorer::Options explorer;
  /// An explored workspace is refused (Fault, before the grid run) when it is thinner than this
  /// along an axis: something held the end-effector (a hand, an object, a wall). Unit: [m]
  double min_workspace_extent_m = 0.02;
  /// Lookup refinement written into the saved map (MapMetadata::lookup_refinement).
  int lookup_refinement = kDefaultLookupRefinement;
  /// The estimation (paper Secs. II-III); the wizard checks them against the device at Check.
  EstimationParameters parameters;
  /// How the device travels between vertices.
  AutoCalibrator::Options calibrator;
  /// Where Save writes the map. Checkpoints go to map_path + ".partial", the convention of
  /// `autograv calibrate`, so either command resumes the other's run.
  std::string map_path;
  /// Continue from the checkpoint: its finished vertices are kept bit for bit.
  bool resume = false;
  /// The caller opened and homed the device and may still be driving it from its servo thread
  /// until the wizard's servo half takes over: the Check step then neither opens nor homes it
  /// again (that would touch the driver from the service thread while the servo thread uses
  /// it), it only reads the specifications.
  bool device_already_open = false;
  /// Centre is confirmed only this close to grid_center_m. Unit: [m]
  double centre_tolerance_m = 0.01;
  /// Fade-in time of the k0 field. Unit: [s]
  double field_ramp_s = 0.3;
  /// After the field is on, how long the end-effector may take to settle before the wizard says
  /// that it does not (it keeps waiting). Unit: [s]
  double release_patience_s = 4.0;
  /// Vertices of the release test in Verify (0 skips Verify; at most kMaxVerifyPoints).
  int verify_points = 3;
  /// Hold at a verify vertex with compensation fully on before letting go. Unit: [s]
  double verify_settle_s = 0.8;
  /// Length of one release test. Unit: [s]
  double verify_release_s = 0.5;
  /// A release test stops early (and the device is caught) past this drift. Unit: [m]
  double verify_drift_limit_m = 0.01;
  /// Fade of the compensation when Verify switches it on. Unit: [s]
  double compensation_ramp_s = 0.5;
  /// Serial number written into the map; empty takes the device's.
  std::string device_serial;
  /// The servo loop's time base, read once per servoTick() by the wizard and by its compensation:
  /// every duration of the calibration is servo time from it, and the review says how regular
  /// the loop was. For a wall-clock loop give a SteadyServoClock; for a simulated loop the clock
  /// that loop keeps. Null: a loop that ticks exactly every parameters.servo_period_s.
  std::shared_ptr<ServoClock> clock;
};

/// Largest number of release tests in Verify.
inline constexpr int kMaxVerifyPoints = 8;

/// One release test of Verify.
struct VerifyResult {
  /// Grid index of the vertex tested.
  int vertex = -1;
  /// End-effector displacement while only the compensation acted. Unit: [m]
  double drift_m = 0.0;
  /// Duration of the test (shorter than verify_release_s when the drift limit was hit). Unit: [s]
  double duration_s = 0.0;
  /// Constant force that would cause that drift on the apparent mass |G_hat|/g from rest:
  /// 2 M d / t^2 (friction hides part of it). Unit: [N]
  double residual_force_n = 0.0;
  /// True once the test ended (drift limit or verify_release_s).
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
  double sag_m = 0.0;              ///< Unit: [m]
  bool still_held = false;         ///< The estimator saw the hand carry the weight recently.
  bool not_settling = false;       ///< Field on for release_patience_s and still no steady state.
  double release_elapsed_s = 0.0;  ///< Unit: [s]
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

  /// What the servo loop did so far (rate, lateness beyond the nominal period, longest gap).
  ServoLoopStats::Summary servo_loop;
  /// Not empty when the loop was too irregular for the figures shown: what happened and what to
  /// do (servoLoopWarning).
  std::string servo_warning;
};

/// The warning WizardStatus::servo_warning carries for a loop that did `loop` with nominal period
/// `period_s`: empty when the loop was regular enough for the estimator's windows (late ticks a
/// few milliseconds at most, stalls rare), else what was seen and what to do. Not real-time safe.
std::string servoLoopWarning(const ServoLoopStats::Summary& loop, double period_s);

/// The guided calibration (paper Sec. III-A then III-B) as a state machine with no UI code:
/// Check -> Centre -> Release -> Explore -> AutoCalibration -> Review -> Save -> Verify -> Done.
/// Explore (WizardConfig::explore) finds the workspace from the device's own data; the grid is
/// then fitted to it and measured inside it. A resumed run takes the grid and the workspace
/// from its checkpoint and does not explore again.
///
/// Two sides, so that the servo loop never blocks, allocates or touches a file:
///  - servoTick(), on the servo thread once per period: reads the device, steps the current
///    step, writes the force. It only fills preallocated state and raises request flags.
///  - service(), on one non-real-time thread (typically the UI thread, every frame): the device's
///    open/calibrate, the checks, checkpoint and map files, the review table, publishing the map
///    to the compensation. status() is read on that same thread.
/// post() may be called from any thread. All I/O with the device goes through a
/// GravityCompensatedDevice owned by the wizard (compensation off until Verify).
///
/// Checkpoints: after each finished vertex the servo side copies it into a mirror (a try-lock it
/// never waits on) and service() writes the mirror to map_path + ".partial" with saveMap (atomic).
class CalibrationWizard {
 public:
  /// Checks the configuration (grid, paths); the device is opened by the Check step, not here.
  /// Throws autograv::Error. Not real-time safe.
  CalibrationWizard(std::shared_ptr<HapticDevice> device, WizardConfig config);
  /// Sends zero force and closes the device if the wizard opened it. The servo loop must have
  /// stopped. Not real-time safe.
  ~CalibrationWizard();
  CalibrationWizard(const CalibrationWizard&) = delete;
  CalibrationWizard& operator=(const CalibrationWizard&) = delete;

  /// Queues an event for the next tick (or the next service() in Check). Any thread.
  /// Real-time safe.
  void post(WizardEvent event) noexcept;

  /// One servo tick: read, step, write. Returns the step after the tick. Does nothing during
  /// Check (the device may not be open yet). Real-time safe: no allocation, lock, throw or I/O.
  WizardStep servoTick() noexcept;

  /// The non-real-time half: runs Check, answers the servo side's requests (plan check, review,
  /// redo, save, verify set-up) and writes checkpoints. Call it often (each UI frame). Never
  /// throws for device or file problems: they become the step's message. Not real-time safe.
  void service();

  /// Snapshot for the front end, with the texts. Same thread as service(). Not real-time safe.
  WizardStatus status() const;

  /// Current step. Any thread. Real-time safe.
  WizardStep step() const noexcept { return phase_.load(std::memory_order_acquire); }
  /// True in Done, Aborted or Fault once every checkpoint has been written: the front end may
  /// stop ticking and exit. Same thread as service(). Not real-time safe.
  bool finished() const;

  /// Vertices as the checkpoint mirror holds them (restored, finished, pending). Same thread as
  /// service(). Not real-time safe.
  std::vector<VertexEstimate> vertices() const;
  /// The saved map, null before Save succeeded. Same thread as service(). Not real-time safe.
  std::shared_ptr<const GravityMap> savedMap() const { return saved_map_; }

  /// The configuration of this run. Real-time safe.
  const WizardConfig& config() const noexcept { return config_; }
  /// The grid of this run: when it is fitted to the explored workspace, known once Explore has
  /// ended (or Check has read the checkpoint of a resumed run); the configured box before. Same
  /// thread as service(). Not real-time safe.
  const WorkspaceGrid& grid() const noexcept { return grid_; }
  /// The explored workspace (empty until known). Same thread as service(). Not real-time safe.
  const ExploredWorkspace& workspace() const noexcept { return workspace_; }
  /// The device as the wizard drives it (compensation decorator around the one passed in), e.g.
  /// for its fault counters. Real-time safe.
  GravityCompensatedDevice& device() noexcept { return *device_; }
  /// map_path + ".partial". Real-time safe.
  const std::string& checkpointPath() const noexcept { return checkpoint_path_; }

 private:
  // Sub-states the servo side keeps between ticks.
  enum class HoldMode : std::uint8_t { kNone, kField, kExplorer, kCalibrator, kPd };
  enum class VerifyStage : std::uint8_t { kWaitMap, kMove, kSettle, kRelease };

  // Servo side (servo thread only).
  void tickCentre(const ServoSample& sample, bool pressed, std::uint32_t events,
                  Eigen::Vector3d& force_n) noexcept;
  void tickRelease(const ServoSample& sample, std::uint32_t events, std::uint32_t replies,
                   Eigen::Vector3d& force_n) noexcept;
  void tickExplore(const ServoSample& sample, std::uint32_t events, std::uint32_t replies,
                   Eigen::Vector3d& force_n) noexcept;
  void startCalibrator(const ServoSample& sample) noexcept;
  void tickCalibration(const ServoSample& sample, std::uint32_t events,
                       Eigen::Vector3d& force_n) noexcept;
  void tickReview(const ServoSample& sample, std::uint32_t events, std::uint32_t replies,
                  Eigen::Vector3d& force_n) noexcept;
  void tickSave(const ServoSample& sample, std::uint32_t events, std::uint32_t replies,
                Eigen::Vector3d& force_n) noexcept;
  void tickVerify(const ServoSample& sample, std::uint32_t events,
                  Eigen::Vector3d& force_n) noexcept;
  void holdForce(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;
  void heldForce(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;
  Eigen::Vector3d feedforward_n(const Eigen::Vector3d& position_m) const noexcept;
  void beginVerifyMove(const Eigen::Vector3d& from_m) noexcept;
  void enter(WizardStep step) noexcept;
  void fail(int fault_code, HoldMode hold) noexcept;
  bool sampleLost(const ServoSample& sample) noexcept;
  void flushMirror() noexcept;
  void publishLive() noexcept;

  // Service side (non-real-time thread only).
  void runCheck(bool retry);
  void restoreCheckpoint(const std::string& device_model);
  void acceptWorkspace();
  void useGrid(const WorkspaceGrid& grid, const std::vector<VertexEstimate>* restored);
  void summarize();
  void writeCheckpoint();
  void buildReview();
  void prepareRedo();
  void saveAndPrepareVerify();
  std::vector<int> chooseVerifyVertices(const std::vector<VertexEstimate>& vertices) const;
  MapMetadata metadata() const;
  std::vector<VertexEstimate> mirrorCopy(std::uint64_t* version) const;

  WizardConfig config_;
  WorkspaceGrid grid_;
  std::string checkpoint_path_;
  std::shared_ptr<GravityCompensatedDevice> device_;

  // Built by Check on the service side, then used by the servo side.
  std::unique_ptr<InitializationEstimator> initialization_;
  std::unique_ptr<WorkspaceExplorer> explorer_;  // null when the run does not explore
  // Built by Check, or by service() once the exploration is accepted (the servo side holds the
  // device with the explorer meanwhile and touches neither).
  std::unique_ptr<AutoCalibrator> calibrator_;
  double max_force_n_ = 0.0;

  // Shared between the two sides.
  std::atomic<WizardStep> phase_{WizardStep::kCheck};
  std::atomic<std::uint32_t> events_{0};
  std::atomic<std::uint32_t> requests_{0};  // servo -> service
  std::atomic<std::uint32_t> replies_{0};   // service -> servo
  mutable std::atomic_flag mirror_busy_ = ATOMIC_FLAG_INIT;
  std::vector<VertexEstimate> mirror_;  // guarded by mirror_busy_
  std::uint64_t mirror_version_ = 0;    // guarded by mirror_busy_
  std::atomic<bool> mirror_pending_{false};
  mutable std::atomic_flag live_busy_ = ATOMIC_FLAG_INIT;
  std::unique_ptr<wizard::Live> live_shared_;  // guarded by live_busy_
  // Written by service before the reply that hands them over, read by the servo side after it.
  std::vector<int> verify_vertices_;
  std::vector<Eigen::Vector3d> verify_targets_m_;  // where each verify vertex was measured
  std::shared_ptr<const GravityMap> saved_map_;
  Eigen::Vector3d plan_gravity_n_ = Eigen::Vector3d::Zero();  // G_hat_0 for the plan check

  // Written by Check, read by the servo side: where Centre asks for the end-effector, the probe
  // directions (the explorer's), and the reach the servo side copies out once it finished.
  Eigen::Vector3d centre_m_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> probe_directions_;
  std::vector<double> explored_reach_m_;
  Eigen::Vector3d explored_center_m_ = Eigen::Vector3d::Zero();
  bool explore_now_ = false;  // Release goes on to Explore (else straight to the grid run)

  // Servo side only.
  std::unique_ptr<wizard::Live> live_;
  double servo_periods_ = 0.0;  // servo time since the first tick, in nominal periods
  long phase_ticks_ = 0;
  double phase_periods_ = 0.0;  // servo time in the current step
  double invalid_periods_ = 0.0;
  double last_clock_s_ = 0.0;
  bool clock_read_ = false;
  ServoLoopStats loop_stats_;
  int loop_summary_countdown_ = 0;
  int failed_writes_ = 0;
  bool last_switch_ = false;
  bool awaiting_plan_ = false;
  bool awaiting_workspace_ = false;
  bool awaiting_redo_ = false;
  bool awaiting_save_ = false;
  double waiting_since_periods_ = 0.0;
  HoldMode hold_mode_ = HoldMode::kNone;
  Eigen::Vector3d hold_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hold_gravity_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_good_gravity_n_ = Eigen::Vector3d::Zero();
  std::vector<char> copy_pending_;  // per vertex: to copy into the mirror
  bool any_copy_pending_ = false;
  const GravityMap* verify_map_ = nullptr;
  VerifyStage verify_stage_ = VerifyStage::kMove;
  MinimumJerkMove verify_move_;
  double verify_periods_ = 0.0;
  Eigen::Vector3d release_start_m_ = Eigen::Vector3d::Zero();

  // Service side only.
  bool opened_ = false;
  bool check_passed_ = false;
  bool check_attempted_ = false;
  bool force_calibrate_ = false;
  std::string check_message_;
  std::string check_prompt_;
  CheckIssue check_issue_ = CheckIssue::kNone;
  std::string summary_;
  std::string plan_message_;
  std::string workspace_message_;  // why the explored workspace was refused
  ExploredWorkspace workspace_;
  MeasurementPlan plan_;
  bool grid_fixed_ = false;  // the grid is the box (or the checkpoint's), not fitted
  std::vector<VertexEstimate> resumed_vertices_;  // of the checkpoint, when resuming
  std::string device_model_;
  std::uint64_t checkpoint_version_ = 0;
  bool checkpoint_written_ = false;
  int checkpointed_converged_ = 0;
  std::string checkpoint_error_;
  WizardReview review_;
  bool review_valid_ = false;
  std::vector<char> restored_;  // per vertex: converged in the loaded checkpoint
  std::string save_error_;
  bool map_saved_ = false;
  std::string redo_message_;
};

/// Loads the checkpoint `path` of a run on `grid` with a device of model `device_model` and
/// returns its vertices (pending ones included). Throws autograv::Error naming the file when it
/// is missing, invalid, or made for another device or grid. Not real-time safe.
std::vector<VertexEstimate> loadCheckpoint(const std::string& path, const WorkspaceGrid& grid,
                                           const std::string& device_model);

}  // namespace autograv
