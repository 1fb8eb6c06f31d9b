#pragma once

#include <memory>
#include <string>
#include <vector>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/haptic_device.h"
#include "autograv/device/servo_loop_stats.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/wizard/wizard_types.h"

namespace autograv {

/// The warning WizardStatus::servo_warning carries for a loop that did `loop` with nominal period
/// `period_s`: empty when the loop was regular enough for the estimator's windows (late ticks a
/// few milliseconds at most, stalls rare), else what was seen and what to do. Not real-time safe.
std::string servoLoopWarning(const ServoLoopStats::Summary& loop, double period_s);

/// The guided calibration (paper Sec. III-A then III-B) as a state machine with no UI code:
/// Check -> Centre -> Release -> Explore -> AutoCalibration -> Review -> Save -> Verify -> Done.
/// Explore finds the workspace from the device's own data; the grid is then fitted to it and
/// measured inside it. A resumed run takes the grid and the workspace from its checkpoint and
/// does not explore again. calibrate() (calibrate.h) runs the whole of it in one call.
///
/// Two sides, so that the servo loop never blocks, allocates or touches a file:
///  - servoTick(), on the servo thread once per period: reads the device, steps the current
///    step, writes the force. It only fills preallocated state and raises request flags.
///  - service(), on one non-real-time thread (typically the UI thread, every frame): the device's
///    open/calibrate, the checks, checkpoint and map files, the review table, publishing the map
///    to the compensation. status() is read on that same thread.
/// post() may be called from any thread. All I/O with the device goes through a
/// GravityCompensatedDevice owned by the wizard (compensation off until Verify); it reads the
/// servo time the wizard read from WizardConfig::clock on the same tick: one clock, read once.
///
/// Checkpoints: after each finished vertex the servo side copies it into a mirror (a try-lock it
/// never waits on) and service() writes the mirror to map_path + ".partial" with saveMap (atomic).
///
/// The state of both sides lives in a private Impl that the constructor allocates whole, so that
/// nothing on the servo path allocates.
class CalibrationWizard {
 public:
  /// Checks the configuration (grid, paths, and that every setting given is one this run uses);
  /// the device is opened by the Check step, not here. Throws autograv::Error naming the field.
  /// Not real-time safe.
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
  WizardStep step() const noexcept;
  /// True in Done, Aborted or Fault once every checkpoint has been written: the front end may
  /// stop ticking and exit. Same thread as service(). Not real-time safe.
  bool finished() const;

  /// Vertices as the checkpoint mirror holds them (restored, finished, pending). Same thread as
  /// service(). Not real-time safe.
  std::vector<VertexEstimate> vertices() const;
  /// The saved map, null before Save succeeded. Same thread as service(). Not real-time safe.
  std::shared_ptr<const GravityMap> savedMap() const;

  /// The configuration of this run. Real-time safe.
  const WizardConfig& config() const noexcept;
  /// The grid of this run: when it is fitted to the explored workspace, known once Explore has
  /// ended (or Check has read the checkpoint of a resumed run); before, a box of the same
  /// resolution about WizardConfig::centre_m that only sizes the buffers. Same thread as
  /// service(). Not real-time safe.
  const WorkspaceGrid& grid() const noexcept;
  /// The explored workspace (empty until known). Same thread as service(). Not real-time safe.
  const ExploredWorkspace& workspace() const noexcept;
  /// The device as the wizard drives it (compensation decorator around the one passed in), e.g.
  /// for its fault counters. Real-time safe.
  GravityCompensatedDevice& device() noexcept;
  /// map_path + ".partial". Real-time safe.
  const std::string& checkpointPath() const noexcept;

 private:
  struct Impl;  // the state of both sides (plugin/src/core/wizard/wizard_impl.h)
  std::unique_ptr<Impl> impl_;
};

/// Loads the checkpoint `path` of a run on `grid` with a device of model `device_model` and
/// returns its vertices (pending ones included). Throws autograv::Error naming the file when it
/// is missing, invalid, or made for another device or grid. Not real-time safe.
std::vector<VertexEstimate> loadCheckpoint(const std::string& path, const WorkspaceGrid& grid,
                                           const std::string& device_model);

}  // namespace autograv
