// CalibrationWizard, servo half: everything servoTick() runs. Real-time safe throughout: the
// objects it steps were built by the Check step (service half, wizard_service.cpp); it only fills
// preallocated state and raises request flags that service() answers.
#include <algorithm>
#include <cmath>
#include <limits>

#include "autograv/device/servo_sample.h"
#include "autograv/estimation/impedance_hold.h"
#include "core/wizard/wizard_impl.h"

namespace autograv {

using wizard::has;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

WizardStep CalibrationWizard::Impl::servoTick() noexcept {
  const WizardStep phase = phase_.load(std::memory_order_acquire);
  if (phase == WizardStep::kCheck) return phase;  // service() owns the device during Check
  ++phase_ticks_;
  const double period_s = config_.advanced.parameters.servo_period_s;
  // Servo time since the previous tick, read once per tick (unknown without a clock: one period),
  // and handed to the compensation, which reads its clock in setForce below.
  double interval_s = 0.0;
  if (config_.clock) {
    const double now_s = config_.clock->now_s();
    if (clock_read_) interval_s = now_s - last_clock_s_;
    last_clock_s_ = now_s;
    clock_read_ = true;
    tick_clock_->set(now_s);
  } else {
    // Multiplied, not summed, as FixedPeriodServoClock does.
    tick_clock_->set(static_cast<double>(exact_ticks_++) * period_s);
  }
  const ServoSample sample = readServoSample(*device_, interval_s);
  const double periods = servoPeriodsOf(sample, period_s);
  servo_periods_ += periods;
  phase_periods_ += periods;
  loop_stats_.record(periods * period_s, std::max(0.0, (periods - 1.0) * period_s));
  if (++loop_summary_countdown_ >= wizard::kLoopSummaryTicks) {
    loop_summary_countdown_ = 0;
    live_.servo_loop = loop_stats_.summary();
  }
  bool pressed = false;
  if (!device_->getUserSwitch(0, pressed)) pressed = false;
  const std::uint32_t events = events_.exchange(0, std::memory_order_acq_rel);
  const std::uint32_t replies = replies_.exchange(0, std::memory_order_acq_rel);

  live_.time_s = servo_periods_ * period_s;
  live_.position_valid = sample.valid;
  if (sample.valid) {
    live_.position_m = sample.position_m;
    live_.speed_m_per_s = sample.velocity_m_per_s.norm();
  }

  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  switch (phase) {
    case WizardStep::kCentre:
      tickCentre(sample, pressed, events, force_n);
      break;
    case WizardStep::kRelease:
      tickRelease(sample, events, replies, force_n);
      break;
    case WizardStep::kExplore:
      tickExplore(sample, events, replies, force_n);
      break;
    case WizardStep::kAutoCalibration:
      tickCalibration(sample, events, force_n);
      break;
    case WizardStep::kReview:
      tickReview(sample, events, replies, force_n);
      break;
    case WizardStep::kSave:
      tickSave(sample, events, replies, force_n);
      break;
    case WizardStep::kVerify:
      tickVerify(sample, events, force_n);
      break;
    case WizardStep::kDone:
    case WizardStep::kAborted:
    case WizardStep::kFault:
      heldForce(sample, force_n);
      break;
    case WizardStep::kCheck:
      break;
  }
  last_switch_ = pressed;

  if (!force_n.allFinite()) force_n.setZero();
  if (device_->setForce(force_n)) {
    failed_writes_ = 0;
  } else if (++failed_writes_ > wizard::kMaxFailedWrites) {
    const WizardStep now = phase_.load(std::memory_order_relaxed);
    if (now != WizardStep::kFault && now != WizardStep::kAborted && now != WizardStep::kDone) {
      fail(wizard::kFaultWritesFailed, HoldMode::kNone);
    }
  }
  recordSentForce(periods * period_s);
  if (any_copy_pending_) flushMirror();
  publishLive();
  return phase_.load(std::memory_order_relaxed);
}

void CalibrationWizard::Impl::enter(WizardStep step) noexcept {
  phase_ticks_ = 0;
  phase_periods_ = 0.0;
  live_.servo_loop = loop_stats_.summary();  // what the loop did up to here, for the texts
  live_.step = step;
  phase_.store(step, std::memory_order_release);
}

void CalibrationWizard::Impl::recordSentForce(double interval_s) noexcept {
  // What reached the driver this tick: the wizard's force plus its compensation, clamped.
  const double sent_n = sent_force_->last_n().norm();
  WizardForces& force = live_.force;
  force.peak_n = std::max(force.peak_n, sent_n);
  if (sent_n > force.continuous_rating_n) force.above_continuous_s += interval_s;
  if (sent_n >= force.limit_n * wizard::kAtLimitFraction) ++force.at_limit_ticks;
}

bool CalibrationWizard::Impl::sampleLost(const ServoSample& sample) noexcept {
  if (sample.valid) {
    invalid_periods_ = 0.0;
    return false;
  }
  // A dropped frame now and then is ridden over; a device that stays silent is a fault.
  invalid_periods_ += servoPeriodsOf(sample, config_.advanced.parameters.servo_period_s);
  if (invalid_periods_ > maxInvalidPeriods(config_.advanced.parameters.servo_period_s)) {
    fail(wizard::kFaultDeviceStopped, HoldMode::kNone);
  }
  return true;
}

void CalibrationWizard::Impl::fail(int fault_code, HoldMode hold) noexcept {
  live_.fault_code = fault_code;
  hold_mode_ = hold;
  enter(WizardStep::kFault);
}

// --- Centre ----------------------------------------------------------------------------------

void CalibrationWizard::Impl::tickCentre(const ServoSample& sample, bool pressed,
                                         std::uint32_t events, Eigen::Vector3d& force_n) noexcept {
  force_n.setZero();                              // the user carries the end-effector
  if (phase_ticks_ == 1) last_switch_ = pressed;  // a button already down is not a confirmation
  if (has(events, WizardEvent::kAbort)) {
    hold_mode_ = HoldMode::kNone;
    enter(WizardStep::kAborted);
    return;
  }
  if (sampleLost(sample)) return;
  const bool within = (centre_m_ - sample.position_m).norm() <= config_.advanced.centre_tolerance_m;
  const bool confirm = has(events, WizardEvent::kConfirm) || (pressed && !last_switch_);
  if (!confirm) return;
  if (!within) {
    live_.confirm_rejected = true;
    live_.confirm_rejected_moving = false;
    return;
  }
  // X0 must be a point where the user holds still: confirming on the move would centre the field
  // on a point the hand is leaving, and the hand's pull would pass for gravity in eq. (7).
  if (sample.velocity_m_per_s.norm() > wizard::kCentreStillSpeed_m_per_s) {
    live_.confirm_rejected_moving = true;
    return;
  }
  live_.confirm_rejected = false;
  live_.confirm_rejected_moving = false;
  // X0 is where the user chose to stop (paper Sec. III-A), not the exact centre.
  initialization_->start(sample.position_m);
  live_.release_status = InitializationEstimator::Status::kRampingIn;
  live_.release_elapsed_s = 0.0;
  live_.sag_m = 0.0;
  live_.last_still_held_s = -1.0;
  live_.not_settling = false;
  live_.initial_gravity_valid = false;
  waiting_since_periods_ =
      servo_periods_ + static_cast<double>(std::lround(config_.advanced.field_ramp_s /
                                                       config_.advanced.parameters.servo_period_s));
  hold_mode_ = HoldMode::kField;
  enter(WizardStep::kRelease);
}

// --- Release ---------------------------------------------------------------------------------

void CalibrationWizard::Impl::tickRelease(const ServoSample& sample, std::uint32_t events,
                                          std::uint32_t replies,
                                          Eigen::Vector3d& force_n) noexcept {
  using Status = InitializationEstimator::Status;
  const double period_s = config_.advanced.parameters.servo_period_s;
  const Status status = initialization_->step(sample, force_n);
  live_.release_status = status;
  live_.sag_m = initialization_->sag_m();
  live_.release_elapsed_s = phase_periods_ * period_s;
  if (has(events, WizardEvent::kAbort)) {
    enter(WizardStep::kAborted);  // the field keeps holding until the front end closes
    return;
  }
  switch (status) {
    case Status::kRampingIn:
      break;
    case Status::kStillHeld:
      live_.last_still_held_s = live_.time_s;
      live_.not_settling = false;
      waiting_since_periods_ = servo_periods_;  // patience restarts: the user was told to let go
      break;
    case Status::kWaiting:
      if ((servo_periods_ - waiting_since_periods_) * period_s >
          config_.advanced.release_patience_s) {
        live_.not_settling = true;
      }
      break;
    case Status::kDone:
      live_.not_settling = false;
      if (!live_.initial_gravity_valid) {
        live_.initial_gravity_n = initialization_->gravityEstimate_n();
        live_.initial_gravity_valid = true;
        last_good_gravity_n_ = live_.initial_gravity_n;
        plan_gravity_n_ = live_.initial_gravity_n;
        awaiting_plan_ = true;
        live_.awaiting_service = true;
        requests_.fetch_or(wizard::kRequestPlanCheck, std::memory_order_acq_rel);
      }
      break;
    case Status::kDeviceFault:
      fail(wizard::kFaultDeviceStopped, HoldMode::kNone);
      return;
  }
  if (!awaiting_plan_) return;
  if ((replies & wizard::kReplyPlanAccepted) != 0) {
    awaiting_plan_ = false;
    live_.awaiting_service = false;
    if (!explore_now_) {  // the workspace is known (a resumed run) or not explored at all
      startCalibrator(sample);
      return;
    }
    // The probe starts where the end-effector settled in the field, with G_hat_0.
    explored_center_m_ = sample.valid ? sample.position_m : initialization_->center_m();
    explorer_->start(explored_center_m_, live_.initial_gravity_n);
    live_.directions_probed = 0;
    live_.explorer_state = explorer_->state();
    hold_mode_ = HoldMode::kExplorer;
    enter(WizardStep::kExplore);
  } else if ((replies & wizard::kReplyPlanRefused) != 0) {
    awaiting_plan_ = false;
    live_.awaiting_service = false;
    fail(wizard::kFaultPlanRefused, HoldMode::kField);  // the field keeps holding it
  }
}

// --- Explore ---------------------------------------------------------------------------------

void CalibrationWizard::Impl::tickExplore(const ServoSample& sample, std::uint32_t events,
                                          std::uint32_t replies,
                                          Eigen::Vector3d& force_n) noexcept {
  if (has(events, WizardEvent::kAbort)) explorer_->abort();
  const WorkspaceExplorer::Status status = explorer_->step(sample, force_n);
  const WorkspaceExplorer& explorer = *explorer_;
  live_.explorer_state = status;
  live_.exploration_elapsed_s = explorer.elapsed_s();
  live_.probe_target_m = explorer.target_m();
  // The explored volume as it grows: the box around the boundary points found so far.
  const int probed = std::min(explorer.probedCount(), static_cast<int>(probe_directions_.size()));
  for (int i = live_.directions_probed; i < probed; ++i) {
    const double reach_m = explorer.reach_m()[static_cast<std::size_t>(i)];
    if (!(reach_m > 0.0)) continue;  // a boundary direction the explorer skipped
    const Eigen::Vector3d point_m =
        explored_center_m_ + reach_m * probe_directions_[static_cast<std::size_t>(i)];
    if (i == 0) {
      live_.explored_low_m = live_.explored_high_m = point_m;
      live_.reach_min_m = live_.reach_max_m = reach_m;
    } else {
      live_.explored_low_m = live_.explored_low_m.cwiseMin(point_m);
      live_.explored_high_m = live_.explored_high_m.cwiseMax(point_m);
      live_.reach_min_m = std::min(live_.reach_min_m, reach_m);
      live_.reach_max_m = std::max(live_.reach_max_m, reach_m);
    }
  }
  live_.directions_probed = probed;
  switch (status) {
    case WorkspaceExplorer::Status::kDeviceFault:
      force_n.setZero();
      fail(wizard::kFaultDeviceStopped, HoldMode::kNone);
      return;
    case WorkspaceExplorer::Status::kAborted:
      hold_mode_ = HoldMode::kExplorer;  // it keeps holding the end-effector where it is
      enter(WizardStep::kAborted);
      return;
    case WorkspaceExplorer::Status::kFinished:
      if (!awaiting_workspace_) {
        // Handed to service() with the request (release/acquire on requests_): it plans the
        // grid while the explorer keeps holding the end-effector.
        std::copy(explorer.reach_m().begin(), explorer.reach_m().end(), explored_reach_m_.begin());
        awaiting_workspace_ = true;
        live_.awaiting_service = true;
        requests_.fetch_or(wizard::kRequestWorkspace, std::memory_order_acq_rel);
      }
      break;
    default:
      break;
  }
  if (!awaiting_workspace_) return;
  if ((replies & wizard::kReplyWorkspaceAccepted) != 0) {
    awaiting_workspace_ = false;
    live_.awaiting_service = false;
    startCalibrator(sample);
  } else if ((replies & wizard::kReplyWorkspaceRefused) != 0) {
    awaiting_workspace_ = false;
    live_.awaiting_service = false;
    fail(wizard::kFaultWorkspaceRefused, HoldMode::kExplorer);  // the probe keeps holding it
  }
}

void CalibrationWizard::Impl::startCalibrator(const ServoSample& sample) noexcept {
  calibrator_->start(sample.valid ? sample.position_m : initialization_->center_m(),
                     live_.initial_gravity_n);
  hold_mode_ = HoldMode::kCalibrator;
  enter(WizardStep::kAutoCalibration);
}

// --- AutoCalibration -------------------------------------------------------------------------

void CalibrationWizard::Impl::tickCalibration(const ServoSample& sample, std::uint32_t events,
                                              Eigen::Vector3d& force_n) noexcept {
  if (has(events, WizardEvent::kPause)) calibrator_->pause();
  if (has(events, WizardEvent::kResume)) calibrator_->resume();
  if (has(events, WizardEvent::kAbort)) calibrator_->abort();
  const AutoCalibrator::Status status = calibrator_->step(sample, force_n);
  const AutoCalibrator& calibrator = *calibrator_;

  live_.calibrator_state = calibrator.state();
  live_.vertex = calibrator.currentVertex();
  live_.visited = calibrator.visitedCount();
  live_.to_visit = calibrator.toVisitCount();
  live_.iteration = calibrator.iteration();
  live_.delta_m = calibrator.iteration() > 0 ? calibrator.lastPositionError_m() : kNaN;
  live_.calibration_elapsed_s = calibrator.elapsed_s();
  live_.eta_s = live_.visited > 0
                    ? calibrator.elapsed_s() / live_.visited * (live_.to_visit - live_.visited)
                    : kNaN;
  live_.peak_force_n = calibrator.peakForce_n();
  live_.lipschitz_n_per_m = calibrator.lipschitzEstimate_n_per_m();

  if (status == AutoCalibrator::Status::kVertexFinished ||
      status == AutoCalibrator::Status::kDeviceFault) {
    for (int vertex : {calibrator.lastFinishedVertex(), calibrator.currentVertex()}) {
      if (vertex < 0) continue;
      copy_pending_[static_cast<std::size_t>(vertex)] = 1;
      any_copy_pending_ = true;
      mirror_pending_.store(true, std::memory_order_release);
    }
    const int finished = calibrator.lastFinishedVertex();
    if (finished >= 0 && calibrator.vertices()[static_cast<std::size_t>(finished)].outcome ==
                             VertexOutcome::kConverged) {
      last_good_gravity_n_ = calibrator.vertices()[static_cast<std::size_t>(finished)].gravity_n;
    }
  }
  switch (calibrator.state()) {
    case AutoCalibrator::Status::kDeviceFault:
      fail(wizard::kFaultDeviceStopped, HoldMode::kNone);
      force_n.setZero();
      break;
    case AutoCalibrator::Status::kAborted:
      hold_mode_ = HoldMode::kCalibrator;  // it keeps holding the end-effector where it is
      enter(WizardStep::kAborted);
      break;
    case AutoCalibrator::Status::kFinished: {
      const int last = calibrator.lastFinishedVertex();
      // Where it was measured: a vertex beyond the stops is measured inside them.
      hold_m_ = last >= 0 ? calibrator.measurementPoint_m(last) : sample.position_m;
      hold_gravity_n_ = last_good_gravity_n_;
      hold_mode_ = HoldMode::kPd;
      enter(WizardStep::kReview);
      requests_.fetch_or(wizard::kRequestReview, std::memory_order_acq_rel);
      break;
    }
    default:
      break;
  }
  live_.paused = calibrator.state() == AutoCalibrator::Status::kPaused;
}

// --- Review and Save -------------------------------------------------------------------------

void CalibrationWizard::Impl::tickReview(const ServoSample& sample, std::uint32_t events,
                                         std::uint32_t replies, Eigen::Vector3d& force_n) noexcept {
  holdForce(sample, force_n);
  if (has(events, WizardEvent::kAbort)) {
    enter(WizardStep::kAborted);
    return;
  }
  if (awaiting_redo_) {
    if ((replies & wizard::kReplyRedoReady) != 0) {
      awaiting_redo_ = false;
      live_.awaiting_service = false;
      calibrator_->start(sample.valid ? sample.position_m : hold_m_, hold_gravity_n_);
      hold_mode_ = HoldMode::kCalibrator;
      enter(WizardStep::kAutoCalibration);
    } else if ((replies & wizard::kReplyNothingToRedo) != 0) {
      awaiting_redo_ = false;
      live_.awaiting_service = false;
    }
    return;
  }
  if (sampleLost(sample)) return;
  if (has(events, WizardEvent::kRedoFailed)) {
    awaiting_redo_ = true;
    live_.awaiting_service = true;
    requests_.fetch_or(wizard::kRequestRedo, std::memory_order_acq_rel);
    return;
  }
  if (has(events, WizardEvent::kConfirm) || has(events, WizardEvent::kSkipRedo)) {
    awaiting_save_ = true;
    live_.awaiting_service = true;
    enter(WizardStep::kSave);
    requests_.fetch_or(wizard::kRequestSave, std::memory_order_acq_rel);
  }
}

void CalibrationWizard::Impl::tickSave(const ServoSample& sample, std::uint32_t events,
                                       std::uint32_t replies, Eigen::Vector3d& force_n) noexcept {
  holdForce(sample, force_n);
  if ((replies & wizard::kReplySaved) != 0) {
    awaiting_save_ = false;
    live_.awaiting_service = false;
    verify_map_ = saved_map_.get();  // published with the reply (acquire above)
    const int count = std::min(static_cast<int>(verify_vertices_.size()), kMaxVerifyPoints);
    if (count == 0) {
      enter(WizardStep::kDone);
      return;
    }
    live_.verify_count = count;
    live_.verify_index = 0;
    live_.verify_cancelled = false;
    for (int i = 0; i < kMaxVerifyPoints; ++i) {
      live_.verify[static_cast<std::size_t>(i)] = VerifyResult{};
      if (i < count) {
        live_.verify[static_cast<std::size_t>(i)].vertex =
            verify_vertices_[static_cast<std::size_t>(i)];
      }
    }
    verify_stage_ = VerifyStage::kWaitMap;
    verify_periods_ = 0.0;
    enter(WizardStep::kVerify);
    return;
  }
  if ((replies & wizard::kReplySaveFailed) != 0) {
    awaiting_save_ = false;
    live_.awaiting_service = false;
  }
  if (sampleLost(sample) || awaiting_save_) return;
  if (has(events, WizardEvent::kAbort)) {
    enter(WizardStep::kAborted);
  } else if (has(events, WizardEvent::kConfirm)) {
    awaiting_save_ = true;
    live_.awaiting_service = true;
    requests_.fetch_or(wizard::kRequestSave, std::memory_order_acq_rel);
  }
}

// --- Verify ----------------------------------------------------------------------------------

void CalibrationWizard::Impl::beginVerifyMove(const Eigen::Vector3d& from_m) noexcept {
  // Where the vertex was measured, inside the explored workspace.
  const Eigen::Vector3d target_m = verify_targets_m_[static_cast<std::size_t>(live_.verify_index)];
  verify_move_.start(
      from_m, target_m,
      MinimumJerkMove::durationFor((target_m - from_m).norm(),
                                   config_.advanced.calibrator.max_move_acceleration_m_per_s2,
                                   config_.advanced.calibrator.min_move_duration_s));
  hold_gravity_n_ = verify_map_->gravityAt(target_m);
  verify_stage_ = VerifyStage::kMove;
  verify_periods_ = 0.0;
}

void CalibrationWizard::Impl::tickVerify(const ServoSample& sample, std::uint32_t events,
                                         Eigen::Vector3d& force_n) noexcept {
  const double period_s = config_.advanced.parameters.servo_period_s;
  verify_periods_ += servoPeriodsOf(sample, period_s);
  const double stage_s = verify_periods_ * period_s;
  if (sampleLost(sample)) {
    force_n.setZero();
    return;
  }
  if (has(events, WizardEvent::kAbort)) {
    live_.verify_cancelled = true;
    hold_m_ = sample.position_m;  // catch it where it is
    holdForce(sample, force_n);
    enter(WizardStep::kDone);
    return;
  }
  VerifyResult& result = live_.verify[static_cast<std::size_t>(live_.verify_index)];
  live_.verify_stage = static_cast<int>(verify_stage_);
  switch (verify_stage_) {
    case VerifyStage::kWaitMap:
      holdForce(sample, force_n);
      // Switch compensation on only once the decorator has taken the map, so that its fade and
      // the fade of our own feed-forward are the same ramp.
      if (device_->latestMapInUse()) {
        device_->setCompensationEnabled(true);
        beginVerifyMove(sample.position_m);
      }
      break;
    case VerifyStage::kMove: {
      Eigen::Vector3d desired_m, desired_velocity, desired_acceleration;
      verify_move_.sample(stage_s, desired_m, desired_velocity, desired_acceleration);
      // eq. (10) along the path; the decorator adds G_hat(X) as its ramp allows.
      force_n = hold_law_.trackForce_n(desired_m, desired_velocity, desired_acceleration, sample,
                                       hold_law_.apparentMass_kg(hold_gravity_n_),
                                       feedforward_n(sample.position_m));
      clampForce(force_n, max_force_n_);
      hold_m_ = desired_m;
      if (stage_s >= verify_move_.duration_s()) {
        verify_stage_ = VerifyStage::kSettle;
        verify_periods_ = 0.0;
      }
      break;
    }
    case VerifyStage::kSettle:
      holdForce(sample, force_n);
      if (stage_s >= config_.advanced.verify_settle_s && device_->compensationLevel() >= 1.0) {
        release_start_m_ = sample.position_m;
        verify_stage_ = VerifyStage::kRelease;
        verify_periods_ = 0.0;
      }
      break;
    case VerifyStage::kRelease: {
      force_n.setZero();  // only the compensation acts: the release test
      const double drift_m = (sample.position_m - release_start_m_).norm();
      result.drift_m = drift_m;
      result.duration_s = stage_s;
      if (drift_m <= config_.advanced.verify_drift_limit_m &&
          stage_s < config_.advanced.verify_release_s)
        break;
      result.residual_force_n =
          2.0 * hold_law_.apparentMass_kg(hold_gravity_n_) * drift_m / (stage_s * stage_s);
      result.finished = true;
      hold_m_ = sample.position_m;  // catch it where it drifted to
      hold_gravity_n_ = verify_map_->gravityAt(hold_m_);
      holdForce(sample, force_n);
      if (live_.verify_index + 1 < live_.verify_count) {
        ++live_.verify_index;
        beginVerifyMove(sample.position_m);
      } else {
        enter(WizardStep::kDone);
      }
      break;
    }
  }
}

// --- Holding ---------------------------------------------------------------------------------

Eigen::Vector3d CalibrationWizard::Impl::feedforward_n(
    const Eigen::Vector3d& position_m) const noexcept {
  // Once compensation is on, the decorator adds level * G_hat(X): supply only the rest.
  if (verify_map_ != nullptr) {
    return (1.0 - device_->compensationLevel()) * verify_map_->gravityAt(position_m);
  }
  return hold_gravity_n_;
}

void CalibrationWizard::Impl::holdForce(const ServoSample& sample,
                                        Eigen::Vector3d& force_n) noexcept {
  if (!sample.valid) {
    force_n.setZero();
    return;
  }
  force_n = hold_law_.holdForce_n(hold_m_, sample, hold_law_.apparentMass_kg(hold_gravity_n_),
                                  feedforward_n(sample.position_m));
  clampForce(force_n, max_force_n_);
}

void CalibrationWizard::Impl::heldForce(const ServoSample& sample,
                                        Eigen::Vector3d& force_n) noexcept {
  switch (hold_mode_) {
    case HoldMode::kNone:
      force_n.setZero();
      break;
    case HoldMode::kField:
      initialization_->step(sample, force_n);
      break;
    case HoldMode::kExplorer:
      explorer_->step(sample, force_n);
      break;
    case HoldMode::kCalibrator:
      calibrator_->step(sample, force_n);
      break;
    case HoldMode::kPd:
      holdForce(sample, force_n);
      break;
  }
}

// --- Exchange with the service side ----------------------------------------------------------

void CalibrationWizard::Impl::publishLive() noexcept {
  wizard::TryLock lock(live_busy_);
  if (!lock.tryLock()) return;  // status() is copying it: next tick
  live_shared_ = live_;
  lock.unlock();
}

}  // namespace autograv
