#pragma once

// CalibrationWizard::Impl: the state of the wizard's two sides and the constants they share.
// One class in named units:
//   calibration_wizard.cpp   the public class, the configuration check, the Impl's construction
//   wizard_servo.cpp         the servo half: everything servoTick() runs (real-time safe)
//   wizard_service.cpp       the service half: Check, the plan, the review, redo, save, verify
//   set-up wizard_checkpoint.cpp    the vertex mirror both sides share and the checkpoint file
//   wizard_status.cpp        status(): the numbers and texts a front end shows

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/forwarding_device.h"
#include "autograv/device/servo_clock.h"
#include "autograv/device/servo_loop_stats.h"
#include "autograv/device/servo_sample.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/impedance_hold.h"
#include "autograv/estimation/initialization_estimator.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/wizard/calibration_wizard.h"
#include "core/estimation/minimum_jerk_move.h"

namespace autograv::wizard {

/// True when two sets of exploration options are the same (calibration_wizard.cpp).
bool sameExplorerOptions(const WorkspaceExplorer::Options& a,
                         const WorkspaceExplorer::Options& b) noexcept;

/// Bit of a WizardEvent in the pending-event word.
constexpr std::uint32_t eventBit(int event) noexcept { return 1u << event; }

/// True when the pending-event word `events` holds `event`.
constexpr bool has(std::uint32_t events, WizardEvent event) noexcept {
  return (events & eventBit(static_cast<int>(event))) != 0;
}

// Requests from the servo side to service().
constexpr std::uint32_t kRequestPlanCheck = 1u << 0;
constexpr std::uint32_t kRequestReview = 1u << 1;
constexpr std::uint32_t kRequestRedo = 1u << 2;
constexpr std::uint32_t kRequestSave = 1u << 3;
constexpr std::uint32_t kRequestWorkspace = 1u << 4;  // the exploration finished: plan the grid

// Replies from service() to the servo side.
constexpr std::uint32_t kReplyPlanAccepted = 1u << 0;
constexpr std::uint32_t kReplyPlanRefused = 1u << 1;
constexpr std::uint32_t kReplyRedoReady = 1u << 2;
constexpr std::uint32_t kReplyNothingToRedo = 1u << 3;
constexpr std::uint32_t kReplySaved = 1u << 4;
constexpr std::uint32_t kReplySaveFailed = 1u << 5;
constexpr std::uint32_t kReplyWorkspaceAccepted = 1u << 6;  // the calibrator is ready
constexpr std::uint32_t kReplyWorkspaceRefused = 1u << 7;

// Why the servo side entered Fault (WizardStatus::fault is written from it by status()).
constexpr int kFaultNone = 0;
constexpr int kFaultDeviceStopped = 1;
constexpr int kFaultPlanRefused = 2;
constexpr int kFaultWritesFailed = 3;
constexpr int kFaultWorkspaceRefused = 4;

/// The servo side refreshes the loop summary it publishes every this many ticks (and on every
/// step change): reading the histograms is cheap, but not per tick.
constexpr int kLoopSummaryTicks = 4096;
/// Centre is confirmed only with the end-effector about still (a hand holding it shakes a
/// little; carrying it moves it at several cm/s). Unit: [m/s]
constexpr double kCentreStillSpeed_m_per_s = 0.02;
/// Consecutive refused setForce calls tolerated before a fault.
constexpr int kMaxFailedWrites = 50;
/// The "still held" notice stays up this long after the estimator last reported it. Unit: [s]
constexpr double kStillHeldNotice_s = 1.5;

/// The servo time of the current tick, as the wizard's servo side read it, for the wizard's
/// compensation: one clock, read once per tick (a clock that advances on every reading, as
/// FixedPeriodServoClock does, read twice would run at twice its rate). Servo thread only.
class TickClock final : public ServoClock {
 public:
  /// The reading of this tick. Real-time safe. Unit: [s]
  void set(double now_s) noexcept { now_s_ = now_s; }
  double now_s() noexcept override { return now_s_; }

 private:
  double now_s_ = 0.0;
};

/// Below the wizard's compensation, right above the driver: remembers the force that reached it
/// on the latest tick (WizardStatus::force). Forwards everything else. Servo thread only.
class SentForce final : public ForwardingDevice {
 public:
  /// Throws autograv::Error for a null device. Not real-time safe.
  explicit SentForce(std::shared_ptr<HapticDevice> driver)
      : ForwardingDevice(std::move(driver), "CalibrationWizard") {}
  /// Forwards, remembering the force. Real-time safe when the driver's setForce is. Unit: [N]
  bool setForce(const Eigen::Vector3d& force_n) override {
    last_n_ = force_n;
    return ForwardingDevice::setForce(force_n);
  }
  /// The force of the latest setForce. Unit: [N]
  const Eigen::Vector3d& last_n() const noexcept { return last_n_; }

 private:
  Eigen::Vector3d last_n_ = Eigen::Vector3d::Zero();
};

/// A force within this fraction of the device's limit counts as at the limit (the clamps scale
/// to the limit up to rounding).
constexpr double kAtLimitFraction = 1.0 - 1e-9;

/// Live numbers the servo side of CalibrationWizard publishes each tick (plain data: copied
/// under the try-lock, never allocated in the servo loop).
struct Live {
  WizardStep step = WizardStep::kCheck;
  double time_s = 0.0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double speed_m_per_s = 0.0;
  bool position_valid = false;
  bool confirm_rejected = false;         // too far from the centre
  bool confirm_rejected_moving = false;  // within reach but moving
  InitializationEstimator::Status release_status = InitializationEstimator::Status::kRampingIn;
  double sag_m = 0.0;
  double release_elapsed_s = 0.0;
  double last_still_held_s = -1.0;
  bool not_settling = false;
  Eigen::Vector3d initial_gravity_n = Eigen::Vector3d::Zero();
  bool initial_gravity_valid = false;
  bool awaiting_service = false;
  WorkspaceExplorer::Status explorer_state = WorkspaceExplorer::Status::kIdle;
  int directions_probed = 0;
  int direction_count = 0;
  double reach_min_m = 0.0;
  double reach_max_m = 0.0;
  Eigen::Vector3d explored_low_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d explored_high_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d probe_target_m = Eigen::Vector3d::Zero();
  double exploration_elapsed_s = 0.0;
  AutoCalibrator::Status calibrator_state = AutoCalibrator::Status::kIdle;
  bool paused = false;
  int vertex = -1;
  int visited = 0;
  int to_visit = 0;
  int iteration = 0;
  double delta_m = 0.0;
  double eta_s = 0.0;
  double calibration_elapsed_s = 0.0;
  double peak_force_n = 0.0;
  double lipschitz_n_per_m = 0.0;
  ServoLoopStats::Summary servo_loop;
  WizardForces force;  // the rating and the limit are set by Check
  std::array<VerifyResult, kMaxVerifyPoints> verify{};
  int verify_count = 0;
  int verify_index = 0;
  int verify_stage = 0;
  bool verify_cancelled = false;
  int fault_code = 0;
};

/// A lock the servo side only ever tries (it skips the work and retries on a later tick when the
/// lock is taken); the service side may wait for it, yielding. Real-time safe: tryLock, unlock.
class TryLock {
 public:
  explicit TryLock(std::atomic_flag& flag) noexcept : flag_(flag) {}
  bool tryLock() noexcept { return !flag_.test_and_set(std::memory_order_acquire); }
  void lock() noexcept {
    while (flag_.test_and_set(std::memory_order_acquire)) std::this_thread::yield();
  }
  void unlock() noexcept { flag_.clear(std::memory_order_release); }

 private:
  std::atomic_flag& flag_;
};

/// Holds a TryLock taken with lock() for a scope. Not real-time safe (it may wait).
class ScopedLock {
 public:
  explicit ScopedLock(std::atomic_flag& flag) noexcept : lock_(flag) { lock_.lock(); }
  ~ScopedLock() { lock_.unlock(); }
  ScopedLock(const ScopedLock&) = delete;
  ScopedLock& operator=(const ScopedLock&) = delete;

 private:
  TryLock lock_;
};

}  // namespace autograv::wizard

namespace autograv {

/// Everything CalibrationWizard keeps, allocated whole by its constructor. Each member says which
/// side owns it; the two sides exchange state only through the atomics and the try-locked mirror
/// and live numbers.
struct CalibrationWizard::Impl {
  // Sub-states the servo side keeps between ticks.
  enum class HoldMode : std::uint8_t { kNone, kField, kExplorer, kCalibrator, kPd };
  enum class VerifyStage : std::uint8_t { kWaitMap, kMove, kSettle, kRelease };

  /// Checks the configuration and sizes every buffer the servo side fills. Throws
  /// autograv::Error. Not real-time safe.
  Impl(std::shared_ptr<HapticDevice> device, WizardConfig config);
  /// Closes the device if the wizard opened it. Not real-time safe.
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  WizardStep step() const noexcept { return phase_.load(std::memory_order_acquire); }

  // Servo side (servo thread only; wizard_servo.cpp). Real-time safe.
  WizardStep servoTick() noexcept;
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
  void recordSentForce(double interval_s) noexcept;
  void flushMirror() noexcept;  // wizard_checkpoint.cpp
  void publishLive() noexcept;

  // Service side (non-real-time thread only; wizard_service.cpp).
  void service();
  void runCheck(bool retry);
  void acceptWorkspace();
  void useGrid(const WorkspaceGrid& grid, const std::vector<VertexEstimate>* restored);
  void summarize();
  void buildReview();
  void prepareRedo();
  void saveAndPrepareVerify();
  std::vector<int> chooseVerifyVertices(const std::vector<VertexEstimate>& vertices) const;
  // The checkpoint (wizard_checkpoint.cpp).
  void restoreCheckpoint(const std::string& device_model);
  void writeCheckpoint();
  bool finished() const;
  MapMetadata metadata() const;
  std::vector<VertexEstimate> mirrorCopy(std::uint64_t* version) const;
  // The front end's snapshot (wizard_status.cpp).
  WizardStatus status() const;

  WizardConfig config_;
  WorkspaceGrid grid_;
  std::string checkpoint_path_;
  std::shared_ptr<GravityCompensatedDevice> device_;  // over sent_force_, over the driver
  std::shared_ptr<wizard::SentForce> sent_force_;
  std::shared_ptr<wizard::TickClock> tick_clock_;  // the compensation's clock
  // The paper's hold (eq. 10) with the estimator's floor on |G|: the wizard's own holds and moves.
  ImpedanceHold hold_law_;

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
  wizard::Live live_shared_;  // guarded by live_busy_
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
  wizard::Live live_;
  double servo_periods_ = 0.0;  // servo time since the first tick, in nominal periods
  long phase_ticks_ = 0;
  double phase_periods_ = 0.0;  // servo time in the current step
  double invalid_periods_ = 0.0;
  double last_clock_s_ = 0.0;
  bool clock_read_ = false;
  long long exact_ticks_ = 0;  // without a clock: ticks so far, the compensation's time
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
  // The measurements the others contradicted (planReview, at the first review), where each is
  // measured again, and whether the redo has taken them to the calibrator.
  std::vector<ReviewedMeasurement> reviewed_;
  // The first points, measured again with the contradicted ones to see the motors' warming
  // (planThermalDriftCheck); kept in memory only: a resumed run looks for no drift.
  std::vector<DriftReference> drift_references_;
  bool review_planned_ = false;
  bool remeasure_sent_ = false;
};

}  // namespace autograv
