// CalibrationWizard, the status: the texts and numbers a front end shows, built on the service
// thread from the servo half's latest live numbers.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "core/wizard/wizard_impl.h"

namespace autograv {

namespace {

std::string format(const char* pattern, double value) {
  char text[64];
  std::snprintf(text, sizeof text, pattern, value);
  return text;
}

std::string mm(double metres) { return format("%.1f mm", metres * 1e3); }

/// "12 mm right, 20 mm down": the move that brings the end-effector to the centre, in CHAI3D's
/// frame (x toward the operator, y right, z up); components under half a millimetre are left out.
std::string directionWords(const Eigen::Vector3d& to_centre_m) {
  static const char* const kWords[3][2] = {
      {"away from you", "toward you"}, {"left", "right"}, {"down", "up"}};
  std::string words;
  for (int axis = 0; axis < 3; ++axis) {
    const double component_m = to_centre_m[axis];
    if (std::abs(component_m) < 0.5e-3) continue;
    if (!words.empty()) words += ", ";
    words += format("%.0f mm ", std::abs(component_m) * 1e3) + kWords[axis][component_m > 0.0];
  }
  return words.empty() ? "right there" : words;
}

std::string vector_n(const Eigen::Vector3d& force_n) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.3f, %.3f, %.3f) N", force_n.x(), force_n.y(), force_n.z());
  return text;
}

std::string seconds(double value) {
  if (!std::isfinite(value) || value < 0.0) return "?";
  if (value < 60.0) return format("%.0f s", value);
  const int whole = static_cast<int>(value);
  char text[32];
  std::snprintf(text, sizeof text, "%dm %02ds", whole / 60, whole % 60);
  return text;
}

/// 1-based number among the steps of a normal run, in WizardStep's order (Verify and Done share
/// the last); 0 for the two that end a run early.
int stepNumber(WizardStep step) {
  if (step == WizardStep::kAborted || step == WizardStep::kFault) return 0;
  return std::min(static_cast<int>(step) + 1, WizardStatus::kStepCount);
}

}  // namespace

std::string servoLoopWarning(const ServoLoopStats::Summary& loop, double period_s) {
  if (loop.ticks < 1000 || !(loop.duration_s > 0.0)) return {};  // too early to judge
  // The estimator's windows span one dither period (50 ms at 20 Hz) in servo time: ticks a few
  // milliseconds late average out, a gap of more than a fifth of a window spoils the window
  // (SteadyStateDetector::kMaxGapOfWindow), which costs time, and a loop that keeps stalling or
  // runs far below its nominal rate no longer holds the end-effector as the figures assume.
  const double stalls_per_minute =
      60.0 * static_cast<double>(loop.gaps_over_10ms) / loop.duration_s;
  const bool slow = loop.rate_hz < 0.5 / period_s;
  const bool late = loop.interval_p99_ms > 5.0;
  const bool stalling = stalls_per_minute > 6.0 || loop.longest_gap_ms > 100.0;
  if (!slow && !late && !stalling) return {};
  std::ostringstream text;
  text << "The servo loop ran irregularly: " << format("%.0f Hz", loop.rate_hz) << " (nominal "
       << format("%.0f Hz", 1.0 / period_s) << "), 99 % of ticks within "
       << format("%.1f ms", loop.interval_p99_ms) << " of the previous one, longest gap "
       << format("%.0f ms", loop.longest_gap_ms) << ", " << loop.gaps_over_10ms
       << " stalls over 10 ms. The figures shown assume a loop that keeps its time: give the "
          "servo thread real-time priority (run as a user allowed SCHED_FIFO, e.g. chrt -f 80), "
          "close programs that load the machine, and calibrate again.";
  return text.str();
}

WizardStatus CalibrationWizard::Impl::status() const {
  wizard::Live live;
  {
    wizard::ScopedLock lock(live_busy_);
    live = live_shared_;
  }
  WizardStatus s;
  s.step = step();
  s.step_number = stepNumber(s.step);
  s.summary = summary_;
  s.position_m = live.position_m;
  s.speed_m_per_s = live.speed_m_per_s;
  s.position_valid = live.position_valid;
  s.time_s = live.time_s;
  s.servo_loop = live.servo_loop;
  s.force = live.force;
  s.servo_warning = servoLoopWarning(live.servo_loop, config_.advanced.parameters.servo_period_s);
  s.centre_m = centre_m_;
  s.to_centre_m = centre_m_ - live.position_m;
  s.centre_distance_m = s.to_centre_m.norm();
  s.centre_tolerance_m = config_.advanced.centre_tolerance_m;
  s.within_tolerance =
      live.position_valid && s.centre_distance_m <= config_.advanced.centre_tolerance_m;
  s.release_status = live.release_status;
  s.sag_m = live.sag_m;
  s.still_held = live.last_still_held_s >= 0.0 &&
                 live.time_s - live.last_still_held_s < wizard::kStillHeldNotice_s;
  s.not_settling = live.not_settling;
  s.release_elapsed_s = live.release_elapsed_s;
  s.initial_gravity_n = live.initial_gravity_n;
  s.initial_gravity_valid = live.initial_gravity_valid;
  s.explorer_state = live.explorer_state;
  s.directions_probed = live.directions_probed;
  s.direction_count = live.direction_count;
  s.reach_min_m = live.reach_min_m;
  s.reach_max_m = live.reach_max_m;
  s.explored_low_m = live.explored_low_m;
  s.explored_high_m = live.explored_high_m;
  s.probe_target_m = live.probe_target_m;
  s.exploration_elapsed_s = live.exploration_elapsed_s;
  s.workspace = workspace_;
  s.measured_at_vertex = plan_.at_vertex;
  s.measured_off_vertex = plan_.off_vertex;
  s.beyond_reach = plan_.skipped;
  s.calibrator_state = live.calibrator_state;
  s.paused = live.paused && s.step == WizardStep::kAutoCalibration;
  s.vertex = live.vertex;
  s.vertices_to_visit = live.to_visit;
  s.vertex_ordinal = std::min(live.visited + 1, std::max(live.to_visit, 1));
  s.vertex_count = grid_.vertexCount();
  s.iteration = live.iteration;
  s.delta_m = live.delta_m;
  s.eta_s = live.eta_s;
  s.calibration_elapsed_s = live.calibration_elapsed_s;
  s.review = review_;
  s.review_valid = review_valid_;
  s.map_path = config_.map_path;
  s.checkpoint_path = checkpoint_path_;
  s.checkpoint_written = checkpoint_written_;
  s.checkpointed_converged = checkpointed_converged_;
  s.map_saved = map_saved_;
  s.save_error = save_error_;
  for (int i = 0; i < live.verify_count; ++i) {
    const VerifyResult& result = live.verify[static_cast<std::size_t>(i)];
    s.verify.push_back(result);
    if (result.finished) s.max_drift_m = std::max(s.max_drift_m, result.drift_m);
  }
  s.verify_index = live.verify_index;
  s.verify_cancelled = live.verify_cancelled;
  {
    wizard::ScopedLock lock(mirror_busy_);
    for (const auto& vertex : mirror_) {
      if (vertex.outcome == VertexOutcome::kConverged) ++s.converged;
    }
  }

  const EstimationParameters& parameters = config_.advanced.parameters;
  std::ostringstream message;
  switch (s.step) {
    case WizardStep::kCheck:
      s.title = "Check the device and the settings";
      if (!check_attempted_) {
        message << "Opening the device and checking the settings...";
      } else {
        message << check_message_;
        s.prompt = check_prompt_;
        s.check_issue = check_issue_;
        s.waiting_for_user = true;
      }
      break;

    case WizardStep::kCentre:
      s.title = "Bring the end-effector to the centre";
      s.waiting_for_user = true;
      // The live numbers first: a small screen cuts messages from their end.
      if (!live.position_valid) {
        message << "Waiting for the device's position...\n";
      } else {
        message << "Distance to the centre: " << mm(s.centre_distance_m) << " (move "
                << directionWords(s.to_centre_m) << ").\n";
        if (live.confirm_rejected && !s.within_tolerance) {
          message << "Not close enough yet: confirm within "
                  << mm(config_.advanced.centre_tolerance_m) << " of the centre.\n";
        } else if (live.confirm_rejected_moving) {
          message << "Not taken: it was moving. Hold it still, then confirm again.\n";
        }
      }
      message << "Hold the end-effector and bring it near the centre of the workspace.";
      s.prompt = s.within_tolerance ? "Hold it still there and press Enter (or the stylus button)."
                                    : "Move it closer to the centre (within " +
                                          mm(config_.advanced.centre_tolerance_m) + ").";
      break;

    case WizardStep::kRelease:
      s.title = "Let go in the spring field";
      if (live.initial_gravity_valid) {
        message << "Settled. Initial estimate (eq. 7): G_hat_0 = "
                << vector_n(live.initial_gravity_n) << ", apparent mass "
                << format("%.0f g", live.initial_gravity_n.norm() / kStandardGravity * 1e3)
                << ".\nChecking the calibration plan (convergence and saturation)...";
      } else if (live.release_status == InitializationEstimator::Status::kRampingIn) {
        message << "The spring field (k0 = " << format("%.2f", parameters.k0_n_per_m * 1e-3)
                << " N/mm) is coming on around the point where you stopped.";
        s.prompt = "Keep holding for a moment.";
        s.waiting_for_user = true;
      } else if (s.still_held) {
        message << "The end-effector is still being held: it stays where the field centre is "
                   "(sag "
                << mm(live.sag_m) << "), so the field carries none of its weight.";
        s.prompt = "Let go of it completely.";
        s.waiting_for_user = true;
      } else if (live.not_settling) {
        message << "It has not settled yet: speed " << format("%.2f mm/s", live.speed_m_per_s * 1e3)
                << ", sag " << mm(live.sag_m) << ". It must stay under "
                << format("%.2f mm/s", parameters.eps_s_m_per_s * 1e3) << " for " << parameters.n_s
                << " samples in a row. If the end-effector is not moving, this device's velocity "
                   "noise is above eps_S: start again with a larger "
                   "EstimationParameters::eps_s_m_per_s.";
        s.prompt = "Let go of it, and keep the device and the table still.";
        s.waiting_for_user = true;
      } else {
        message << "Field on. Sag " << mm(live.sag_m) << ", speed "
                << format("%.2f mm/s", live.speed_m_per_s * 1e3) << ".";
        s.prompt = "Let go of the end-effector now.";
        s.waiting_for_user = true;
      }
      break;

    case WizardStep::kExplore: {
      s.title = "Explore the workspace";
      message << "Direction " << std::min(s.directions_probed + 1, std::max(s.direction_count, 1))
              << " of " << s.direction_count << ": " << toString(live.explorer_state);
      if (s.directions_probed > 0) {
        const Eigen::Vector3d extent_m = s.explored_high_m - s.explored_low_m;
        message << ".\nExplored so far: reach " << mm(s.reach_min_m) << " to " << mm(s.reach_max_m)
                << " from the centre, a box of " << format("%.0f", extent_m.x() * 1e3) << " x "
                << format("%.0f", extent_m.y() * 1e3) << " x "
                << format("%.0f mm", extent_m.z() * 1e3);
      }
      const double eta_s = s.directions_probed > 0 ? s.exploration_elapsed_s / s.directions_probed *
                                                         (s.direction_count - s.directions_probed)
                                                   : std::numeric_limits<double>::quiet_NaN();
      message << ".\nElapsed " << seconds(s.exploration_elapsed_s) << ", ETA " << seconds(eta_s)
              << ".";
      s.eta_s = eta_s;
      if (live.awaiting_service) message << "\nPlanning the measurements inside it...";
      message << "\nA soft probe pushes the end-effector outward and backs off from every stop: "
                 "the grid is then measured only where it can go.";
      s.prompt = "The device moves by itself: keep clear. q stops.";
      break;
    }

    case WizardStep::kAutoCalibration: {
      s.title = "Automatic calibration";
      message << "Vertex " << s.vertex_ordinal << " of " << s.vertices_to_visit;
      if (s.vertex >= 0) message << " (grid #" << s.vertex << ")";
      if (live.calibrator_state == AutoCalibrator::Status::kMoving) {
        message << ": moving there";
      } else {
        message << ", iteration " << s.iteration;
        if (std::isfinite(s.delta_m))
          message << ", |Delta_j| = " << format("%.3f mm", s.delta_m * 1e3);
      }
      message << "\nConverged " << s.converged << " of " << s.vertex_count << ", elapsed "
              << seconds(s.calibration_elapsed_s) << ", ETA " << seconds(s.eta_s) << ".";
      if (s.checkpoint_written) {
        message << "\nCheckpoint: " << s.checkpointed_converged << " vertices in "
                << checkpoint_path_ << ".";
      }
      if (!checkpoint_error_.empty()) message << "\nCheckpoint failed: " << checkpoint_error_;
      if (s.paused) {
        message << "\nPaused: the device holds its position.";
        s.prompt = "Press p to resume; q stops (finished vertices are kept).";
        s.waiting_for_user = true;
      } else {
        s.prompt = "The device moves by itself: keep clear. p pauses, q stops (progress is kept).";
      }
      break;
    }

    case WizardStep::kReview: {
      s.title = "Review the result";
      const WizardReview& r = review_;
      if (!review_valid_) {
        message << "Gathering the results...";
        break;
      }
      message << "Converged: " << r.converged << " of " << r.vertex_count << " vertices";
      if (r.restored > 0) message << " (" << r.restored << " from the checkpoint)";
      if (r.unreachable > 0) {
        message << "; " << r.unreachable
                << " out of the device's reach, solved from the measured ones";
      }
      if (!workspace_.empty()) {
        message << ".\nInside the explored workspace: " << plan_.at_vertex
                << " measured at their vertex, " << plan_.off_vertex << " just inside the stops; "
                << plan_.skipped << " beyond reach";
      }
      message << ".\nIterations per vertex: median " << format("%.1f", r.iterations_median)
              << ", min " << r.iterations_min << ", max " << r.iterations_max << ".\n"
              << "|G_hat| from " << format("%.3f", r.gravity_min_n) << " to "
              << format("%.3f N", r.gravity_max_n)
              << "; Lipschitz c = " << format("%.1f N/m", r.lipschitz_n_per_m) << "; peak force "
              << format("%.2f N", r.peak_force_n) << ".";
      for (const ReviewRow& row : r.failed) {
        message << "\n  vertex #" << row.vertex << " at ("
                << format("%.0f", row.position_m.x() * 1e3) << ", "
                << format("%.0f", row.position_m.y() * 1e3) << ", "
                << format("%.0f", row.position_m.z() * 1e3) << ") mm: " << toString(row.outcome)
                << " after " << row.iterations << " iterations";
      }
      if (!r.measure_again.empty()) {
        message << "\n"
                << r.measure_again.size()
                << (r.measured_again ? " measured again because the others contradicted them"
                                     : " to measure again: the others contradict them")
                << " (one that still stands out is left out of the map):";
        for (const ReviewedMeasurement& entry : r.measure_again) {
          message << "\n  vertex #" << entry.first.vertex << " at ("
                  << format("%.1f", entry.first.point_m.x() * 1e3) << ", "
                  << format("%.1f", entry.first.point_m.y() * 1e3) << ", "
                  << format("%.1f", entry.first.point_m.z() * 1e3)
                  << ") mm: " << format("%.2f", 100.0 * entry.first.residual_rel)
                  << " % off the others (" << format("%.2f", 100.0 * entry.first.local_rel)
                  << " % around it)";
        }
      }
      if (!redo_message_.empty()) message << "\n" << redo_message_;
      if (!s.servo_warning.empty()) message << "\nWarning: " << s.servo_warning;
      s.waiting_for_user = true;
      if (live.awaiting_service) {
        message << "\nPreparing the redo...";
        s.waiting_for_user = false;
      } else if (!offersRedo(r)) {
        s.prompt = "Press Enter to save the map.";
      } else {
        // What the redo does, in the order it says it.
        std::vector<std::string> parts;
        const std::size_t to_redo = r.failed.size() + static_cast<std::size_t>(r.pending);
        if (to_redo > 0) {
          parts.push_back("redo the " + std::to_string(to_redo) +
                          " vertices that did not converge");
        }
        if (!r.measured_again && !r.measure_again.empty()) {
          parts.push_back("measure the " + std::to_string(r.measure_again.size()) +
                          " contradicted ones again");
        }
        if (!r.measured_again && r.drift_points > 0) {
          parts.push_back("measure " + std::to_string(r.drift_points) +
                          " of the first points again to see how much the motors warmed");
        }
        std::string what;
        for (std::size_t i = 0; i < parts.size(); ++i) {
          what += (i == 0 ? "" : (i + 1 == parts.size() ? " and " : ", ")) + parts[i];
        }
        s.prompt = "Press r to " + what + ", or Enter to save the map as it is.";
      }
      break;
    }

    case WizardStep::kSave:
      s.title = "Save the map";
      if (!save_error_.empty() && !live.awaiting_service) {
        message << "Could not save the map: " << save_error_;
        s.prompt = "Press Enter to try again; q stops (the checkpoint is kept).";
        s.waiting_for_user = true;
      } else {
        message << "Writing " << config_.map_path << "...";
      }
      break;

    case WizardStep::kVerify: {
      s.title = "Verify: release tests with compensation on";
      const int count = static_cast<int>(s.verify.size());
      message << "Test " << std::min(s.verify_index + 1, count) << " of " << count;
      if (s.verify_index < count) {
        message << " at vertex #" << s.verify[static_cast<std::size_t>(s.verify_index)].vertex;
      }
      static const char* const kStages[] = {": switching compensation on", ": moving there",
                                            ": holding", ": let go, measuring the drift"};
      message << kStages[std::min(std::max(live.verify_stage, 0), 3)] << ".";
      for (const VerifyResult& result : s.verify) {
        if (!result.finished) continue;
        message << "\n  vertex #" << result.vertex << ": drift " << mm(result.drift_m) << " in "
                << format("%.2f s", result.duration_s) << " (residual about "
                << format("%.1f mN", result.residual_force_n * 1e3) << ")";
      }
      s.prompt =
          "Keep clear: the device lets go of itself briefly at each vertex. q skips the "
          "rest.";
      break;
    }

    case WizardStep::kDone: {
      s.title = "Done";
      message << "Map saved to " << config_.map_path << ": " << s.converged << " of "
              << s.vertex_count << " vertices converged.";
      if (!s.servo_warning.empty()) message << "\nWarning: " << s.servo_warning;
      int tested = 0;
      for (const VerifyResult& result : s.verify) tested += result.finished ? 1 : 0;
      if (tested > 0) {
        message << "\nRelease test with compensation on: largest drift " << mm(s.max_drift_m)
                << " over " << tested << " vertices in "
                << format("%.2f s", config_.advanced.verify_release_s) << ".";
        for (const VerifyResult& result : s.verify) {
          if (!result.finished) continue;
          message << "\n  vertex #" << result.vertex << ": drift " << mm(result.drift_m)
                  << " (residual about " << format("%.1f mN", result.residual_force_n * 1e3) << ")";
        }
      }
      if (s.verify_cancelled) message << "\nVerification stopped before the end.";
      if (!save_error_.empty()) message << "\n" << save_error_;
      break;
    }

    case WizardStep::kAborted:
      s.title = "Stopped";
      if (checkpoint_written_) {
        message << "Stopped by you. " << checkpointed_converged_
                << " converged vertices are saved in " << checkpoint_path_
                << ".\nRun again with WizardConfig::resume = true to continue.";
      } else if (config_.resume && check_passed_) {
        message << "Stopped by you. The checkpoint " << checkpoint_path_
                << " is unchanged; run again with WizardConfig::resume = true to continue.";
      } else {
        message << "Stopped by you before any vertex was finished; nothing was saved.";
      }
      s.fault = message.str();
      break;

    case WizardStep::kFault:
      s.title = "Cannot continue";
      switch (live.fault_code) {
        case wizard::kFaultDeviceStopped:
          message << "The device stopped answering (no valid position for "
                  << format("%.0f ms", kMaxInvalidReadings_s * 1e3) << " of servo time).";
          break;
        case wizard::kFaultWritesFailed:
          message << "The device refused the forces sent to it (" << wizard::kMaxFailedWrites
                  << " failed writes in a row; decorator fault: " << toString(device_->lastFault())
                  << ").";
          break;
        case wizard::kFaultWorkspaceRefused:
          message << workspace_message_
                  << "\nThe probe still holds the end-effector: take it, then start again.";
          break;
        case wizard::kFaultPlanRefused:
          message << "The calibration was refused before the device moves by itself, with "
                     "G_hat_0 = "
                  << vector_n(live.initial_gravity_n) << ":" << plan_message_
                  << "\nThe spring field still holds the end-effector: take it, then start again "
                     "with the parameter named above changed.";
          break;
        default:
          message << "Unknown fault.";
          break;
      }
      if (map_saved_) {
        message << "\nThe map had been saved to " << config_.map_path << " before that.";
      } else if (live.fault_code != wizard::kFaultPlanRefused &&
                 live.fault_code != wizard::kFaultWorkspaceRefused) {
        if (checkpoint_written_) {
          message << "\n"
                  << checkpointed_converged_ << " converged vertices are saved in "
                  << checkpoint_path_
                  << ". Check the cable and the power, then run again with WizardConfig::resume = "
                     "true.";
        } else {
          message << "\nCheck the cable and the power, then start again.";
        }
      }
      s.fault = message.str();
      break;
  }
  s.message = message.str();
  return s;
}

}  // namespace autograv
