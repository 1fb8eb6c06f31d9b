#pragma once

// Constants shared by the servo side (calibration_wizard.cpp), the service side
// (wizard_service.cpp) and the texts (wizard_status.cpp) of CalibrationWizard.

#include <array>
#include <atomic>
#include <cstdint>
#include <thread>

#include <Eigen/Core>

#include "autograv/device/servo_sample.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/initialization_estimator.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/wizard/calibration_wizard.h"

namespace autograv::wizard {

/// Bit of a WizardEvent in the pending-event word.
constexpr std::uint32_t eventBit(int event) noexcept { return 1u << event; }

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
