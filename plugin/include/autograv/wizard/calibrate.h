#pragma once

// Calibrating a device in one call: calibrate() runs a CalibrationWizard to its end, with the
// servo loop on a thread of its own and the service on the calling thread.

#include <atomic>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "autograv/device/haptic_device.h"
#include "autograv/device/real_time_priority.h"
#include "autograv/map/gravity_map.h"
#include "autograv/wizard/calibration_wizard.h"
#include "autograv/wizard/wizard_types.h"

namespace autograv {

/// How calibrate() runs the wizard: its threads, what it tells the caller and what it answers by
/// itself. The defaults suit a real device in a program that shows progress and nothing else.
struct CalibrateOptions {
  /// Called on the calling thread, at most every progress_period_s and whenever the step or the
  /// prompt changes, with the wizard's status: one line of it (progressLine) makes a log.
  std::function<void(const WizardStatus& status)> on_progress;
  /// Wall time between two calls of on_progress within one step and prompt. Unit: [s]
  double progress_period_s = 1.0;
  /// Called on the calling thread after every service() (each frame_s), with the status and the
  /// wizard, to post the user's events (WizardEvent: confirm, pause, redo, abort) or to drive
  /// what the user does. Not needed on a device whose stylus button confirms Centre.
  std::function<void(const WizardStatus& status, CalibrationWizard& wizard)> on_status;
  /// Answer the prompts nobody else answers. Review: redo the vertices that did not converge
  /// once, then save. Check, when it stops (the device does not open, is not homed, a setting is
  /// refused, a checkpoint of an earlier run exists while WizardConfig::resume is false): give
  /// up, returning the status of Check, whose message says why and what to do. Save, when it
  /// fails: stop, keeping the checkpoint. False: on_status answers them all.
  bool answer_prompts = true;
  /// When it turns true (e.g. set by a signal handler), the run stops as WizardEvent::kAbort
  /// stops it: finished vertices are kept in the checkpoint. Null: never.
  const std::atomic<bool>* stop_requested = nullptr;
  /// How fast the servo thread ticks, in multiples of real time. 1, the default, for a real
  /// device: the thread ticks every servo period on the wall clock (WallClockTickSource), asks for
  /// real-time priority (real_time_priority), and a WizardConfig without a clock gets a
  /// SteadyServoClock. A device that runs in simulated time (its setForce advances its physics
  /// by one servo period, as a model or a test does) may tick faster: speed times real time, or
  /// as fast as the processor allows with 0; the wizard then counts exact servo periods unless
  /// WizardConfig::clock says otherwise.
  double speed = 1.0;
  /// At speed 1, ask for SCHED_FIFO priority for the servo thread (enterRealTimePriority); a
  /// refusal leaves it at normal priority (CalibrateResult::servo_priority says which).
  bool real_time_priority = true;
  /// Wall time between two service() calls on the calling thread. Unit: [s]
  double frame_s = 0.02;
};

/// What calibrate() ends with.
struct CalibrateResult {
  /// The wizard's last status: the step it ended in (kDone when the map was saved and
  /// verified; kCheck when it gave up there), the review, the release tests, the forces sent,
  /// and for a run that did not end in kDone what happened and what to do (message, fault).
  WizardStatus status;
  /// The saved map, null unless status.map_saved. Publish it to a GravityCompensatedDevice.
  std::shared_ptr<const GravityMap> map;
  /// What the servo thread got when it asked for real-time priority; empty when it did not ask
  /// (speed other than 1, or real_time_priority false).
  std::optional<RealTimePriority> servo_priority;
  /// True when the map was saved (and verified, when WizardConfig::verify_points asked for it).
  bool ok() const noexcept { return status.step == WizardStep::kDone && status.map_saved; }
};

/// Calibrates `device` with `config` from start to end: a CalibrationWizard whose servo half
/// ticks on a thread calibrate() starts (paced as CalibrateOptions::speed says), and whose
/// service half runs on the calling thread, which it blocks until the wizard finished (or gave
/// up in Check). The user's part is the wizard's Centre and Release steps: bring the
/// end-effector near WizardConfig::centre_m, press the stylus button (or post kConfirm from
/// on_status), let go. Once it returns, the servo thread has stopped, zero force was sent, and
/// the device is closed again if the wizard opened it. Throws autograv::Error for a
/// configuration or options it cannot use, before the device moves; never for the device or the
/// files, which the status reports. Not real-time safe.
CalibrateResult calibrate(std::shared_ptr<HapticDevice> device, WizardConfig config,
                          const CalibrateOptions& options = {});

/// calibrate() with the default WizardConfig: the map is saved to `map_path`.
/// Not real-time safe.
CalibrateResult calibrate(std::shared_ptr<HapticDevice> device, const std::string& map_path,
                          const CalibrateOptions& options = {});

/// One line for a log: "[5/8] Automatic calibration: Vertex 3 of 27, iteration 2, ..." (the
/// step, its title and the first line of its message), and the prompt after " > " when there is
/// one. Not real-time safe.
std::string progressLine(const WizardStatus& status);

}  // namespace autograv
