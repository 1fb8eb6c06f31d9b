#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/end_stop_watch.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/wizard/calibration_wizard.h"
#include "hand_script.h"
#include "lock_free.h"
#include "servo_timing.h"

namespace autograv::demo {

/// What the servo loop is doing.
enum class ServoMode : std::uint8_t {
  kApplication,  ///< The application's loop: its force (none: free space) through the decorator.
  kCalibrating,  ///< The calibration wizard drives the device (paper Sec. III, guided).
  kHandover,     ///< The new map is published: a hold fades out as compensation ramps in.
};
const char* toString(ServoMode mode) noexcept;

/// The state the servo thread publishes after every tick. Plain data.
struct ServoSnapshot {
  std::int64_t ticks = 0;
  double time_s = 0.0;  ///< Servo time: ticks x period. Unit: [s]
  bool sample_valid = false;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();        ///< Measured. Unit: [m]
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();  ///< Estimated. Unit: [m/s]
  Eigen::Vector3d force_sent_n = Eigen::Vector3d::Zero();      ///< Actuator force, saturated. [N]
  bool hand_holding = false;
  Eigen::Vector3d hand_target_m = Eigen::Vector3d::Zero();  ///< Unit: [m]
  bool compensation_enabled = false;
  double compensation_level = 0.0;  ///< Ramp, 0..1.
  bool map_in_use = false;
  std::uint64_t clamps = 0;              ///< Decorator: forces scaled to the device limit.
  std::uint64_t device_saturations = 0;  ///< Driver: setForce calls it clamped.
  std::uint64_t faults = 0;              ///< Decorator: ticks that ended in a fault.
  ServoFault last_fault = ServoFault::kNone;
  bool released = false;         ///< The hand let go and has not grabbed again.
  double drift_m = 0.0;          ///< Distance from the release point. Unit: [m]
  double since_release_s = 0.0;  ///< Unit: [s]
  ServoMode mode = ServoMode::kApplication;
  WizardStep wizard_step = WizardStep::kCheck;  ///< Meaningful while mode is kCalibrating.
  bool realtime = false;  ///< Paced on the wall clock (timing below is meaningful).
  ServoTiming::Report timing;
};

struct SessionOptions {
  /// A device name (autograv::makeDevice) with a simulation behind it: sim:omega, sim:omni, or
  /// a simulated CHAI3D device.
  std::string device = "sim:omega";
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;  ///< Of the simulated device.
  double servo_period_s = 1.0e-3;                              ///< Unit: [s]
  CompensationOptions compensation;
  EstimationParameters estimation;
  /// Vertices per axis of a calibration's grid, fitted to the workspace it explores first (as
  /// `autograv calibrate` does).
  int calibration_resolution = 5;
  /// Where a calibration saves its map; finished vertices are checkpointed to this path +
  /// ".partial" as they come, and a calibration started while that file exists resumes it.
  std::string calibration_map_path = "autograv-map.json";
  /// Release tests the calibration runs on the new map before handing over (0 skips them).
  int calibration_verify_points = 3;
  /// Raise the servo thread to SCHED_FIFO when the system allows it.
  bool realtime_priority = true;
};

/// The servo time of the demo's loop: the simulated time it has advanced its simulation by, one
/// period per tick on simulated time and the time that really passed when the servo thread paces
/// it on the wall clock. Read by the decorator and the wizard, advanced by the session, all on the
/// servo thread. Real-time safe.
class LoopClock final : public ServoClock {
 public:
  double now_s() noexcept override { return time_s_; }
  /// Unit: [s]
  void advance(double dt_s) noexcept { time_s_ += dt_s; }

 private:
  double time_s_ = 0.0;
};

/// A simulated device behind the GravityCompensatedDevice decorator, driven by one servo loop:
/// either on its own thread paced at 1 kHz on absolute wall-clock deadlines (startRealTime), or
/// stepped tick by tick by the caller on simulated time (runTicks, for deterministic headless
/// runs). The UI thread talks to it through lock-free channels only.
class DemoSession {
  enum class UiCalibration { kNone, kInitializing, kRunning, kPublished };

 public:
  /// Makes, opens and homes the device, puts the end-effector at rest at the workspace centre in
  /// the simulated hand's grip, wraps it in the decorator. Throws autograv::Error. Not real-time
  /// safe.
  explicit DemoSession(const SessionOptions& options);
  /// Stops the servo thread if it runs. Not real-time safe.
  ~DemoSession();
  DemoSession(const DemoSession&) = delete;
  DemoSession& operator=(const DemoSession&) = delete;

  /// The device as the application sees it (the decorator) and the simulation behind it.
  GravityCompensatedDevice& device() noexcept { return *decorator_; }
  sim::SimulatedDevice& simulation() noexcept { return *simulation_; }
  const sim::SimulatedDevice& simulation() const noexcept { return *simulation_; }
  const SessionOptions& options() const noexcept { return options_; }

  // --- Map (UI thread) -------------------------------------------------------------------------
  /// Publishes `map` to the decorator. Throws autograv::Error when it was made for another
  /// device model. Not real-time safe.
  void publishMap(std::shared_ptr<const GravityMap> map);
  std::shared_ptr<const GravityMap> map() const { return decorator_->publishedMap(); }

  // --- Hand and compensation (UI thread; executed by the servo thread) -----------------------
  /// Grabs the end-effector where it is. Not real-time safe (may be called from the UI only).
  void grab();
  /// Moves the hand's target at once (mouse drag). Unit: [m]
  void setHandTarget(const Eigen::Vector3d& target_m);
  void release();
  /// Ramps compensation in or out. Any thread.
  void setCompensationEnabled(bool enabled) noexcept;
  /// A script whose events fire on servo time; must outlive the session. Call before running.
  void setScript(const HandScript* script);

  // --- Calibration (UI thread) -----------------------------------------------------------------
  // The calibration wizard (autograv::CalibrationWizard) takes the device over: Check, Centre
  // (the user brings the end-effector to the centre and confirms), Release (the user lets go),
  // the grid run, Review (the user confirms), Save, Verify. Its servo half runs in tick(), its
  // service half in updateCalibration().

  /// Starts a calibration: the user initializes at the centre of calibrationGrid(), the wizard
  /// explores the workspace and calibrates a grid fitted to it (a checkpoint's grid and workspace
  /// when it resumes one). Returns a message for the user.
  /// Throws autograv::Error for an unusable configuration. Not real-time safe.
  std::string startCalibration();
  /// Tells the running calibration what the user did (confirm, pause, redo...). Ignored when
  /// none runs. Any thread.
  void postCalibrationEvent(WizardEvent event) noexcept;
  /// Stops the calibration: finished vertices stay in the checkpoint, the application loop takes
  /// over once it is written (in updateCalibration). Not real-time safe.
  void abortCalibration();
  /// Moves a calibration along from the UI side: the wizard's service half (checks, checkpoint
  /// and map files), then, once it is done, publishes the saved map and hands the device back to
  /// the application. Returns a message when something happened (empty otherwise). Call once per
  /// frame. Not real-time safe.
  std::string updateCalibration();
  /// True from startCalibration until the application loop has the device back. UI thread.
  bool calibrationRunning() const noexcept { return wizard_ui_ != nullptr; }
  /// The wizard's status as of the last updateCalibration, or null when no calibration runs.
  /// UI thread.
  const WizardStatus* calibrationStatus() const noexcept {
    return wizard_ui_ != nullptr ? &wizard_status_ : nullptr;
  }
  /// The status of the running calibration, or how the last one ended. UI thread.
  const WizardStatus& lastCalibrationStatus() const noexcept { return wizard_status_; }
  /// True when the end-effector rested on an end stop while the initialization of the running
  /// (or last) calibration settled: its G_hat_0 (eq. 7) is wrong. The simulator's contact flag,
  /// for scoring only: the user hears of it from the wizard, which judges the settled point from
  /// driver data once the workspace is explored (initializationClearanceProblem). Any thread.
  bool initializationEndStopHit() const noexcept { return initialization_end_stop_hit_.load(); }

  // --- Running ----------------------------------------------------------------------------------
  /// One servo tick: commands, script, read, control, write, physics, snapshot. Servo thread
  /// (or the caller of runTicks). Real-time safe.
  void tick() noexcept;
  /// Runs `count` ticks on simulated time on the calling thread. Not while the thread runs.
  void runTicks(std::int64_t count) noexcept;
  /// Starts the servo thread (1 kHz on absolute deadlines). Not real-time safe.
  void startRealTime();
  /// Stops and joins it. Not real-time safe.
  void stopRealTime();
  bool running() const noexcept { return thread_.joinable(); }
  /// True when the servo thread got SCHED_FIFO.
  bool realtimePriority() const noexcept { return realtime_priority_.load(); }
  /// True when the process's memory is locked resident for the servo thread (mlockall).
  bool memoryLocked() const noexcept { return memory_locked_.load(); }

  /// The published map's grid, else the default grid (the cube of 80 % of the cube inscribed in
  /// the workspace sphere): where a calibration asks the user to initialize. Not real-time safe.
  WorkspaceGrid calibrationGrid() const;

  /// Latest published state. UI thread only (or the caller of runTicks). Real-time safe.
  const ServoSnapshot& snapshot() noexcept { return snapshots_.read(); }

 private:
  struct Command {
    enum class Kind : std::uint8_t {
      kGrab,
      kSetTarget,
      kRelease,
      kStartCalibration,
      kEndCalibration,
    };
    Kind kind = Kind::kGrab;
    Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
    CalibrationWizard* wizard = nullptr;  // kStartCalibration
    const GravityMap* map = nullptr;      // kEndCalibration: hand over under this map, or none
  };

  void sendCommand(const Command& command);
  void handleCommand(const Command& command) noexcept;
  void handleScriptEvent(const HandEvent& event) noexcept;
  void grabNow() noexcept;
  void releaseNow() noexcept;
  Eigen::Vector3d holdForce(const ServoSample& sample) const noexcept;
  void publishSnapshot(const ServoSample& sample) noexcept;
  void servoThreadMain();
  void catchUpWithTheWallClock() noexcept;
  void advanceSimulation(double dt_s) noexcept;

  /// A tick of the servo thread advances the simulation by the time since the previous one, at
  /// most this much: a longer stall is not simulated. Unit: [s]
  static constexpr double kMaxCatchUp_s = 0.1;

  SessionOptions options_;
  std::shared_ptr<HapticDevice> device_;              // what the decorator and the wizard drive
  std::shared_ptr<sim::SimulatedDevice> simulation_;  // its physics and the simulated hand
  std::shared_ptr<GravityCompensatedDevice> decorator_;

  // Servo-thread state.
  std::int64_t ticks_ = 0;
  ServoMode mode_ = ServoMode::kApplication;
  HandScriptPlayer script_player_;
  bool released_ = false;
  Eigen::Vector3d release_position_m_ = Eigen::Vector3d::Zero();
  std::int64_t release_tick_ = 0;
  Eigen::Vector3d last_position_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hold_position_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hold_gravity_n_ = Eigen::Vector3d::Zero();
  ServoTiming timing_;
  bool timing_valid_ = false;
  std::shared_ptr<LoopClock> clock_;  // the decorator's and the wizard's servo time
  // Paced on the wall clock (the servo thread): the simulation follows the time that passed.
  bool paced_ = false;
  std::chrono::steady_clock::time_point paced_last_tick_;

  // Calibration wizards: made on the UI thread, handed to the servo thread by a command, kept
  // until the session ends so that a late tick never sees one freed.
  std::vector<std::unique_ptr<CalibrationWizard>> wizards_;
  CalibrationWizard* wizard_ = nullptr;     // servo thread's
  CalibrationWizard* wizard_ui_ = nullptr;  // UI thread's: the one running, null when none
  WizardStatus wizard_status_;
  WizardStep last_wizard_step_ = WizardStep::kCheck;
  bool compensation_before_calibration_ = true;
  // Watched on the servo thread, which advances the simulation; the UI reads the atomic.
  sim::InitializationEndStopWatch end_stop_watch_;
  std::atomic<bool> initialization_end_stop_hit_{false};

  SpscQueue<Command, 256> commands_;
  TripleBuffer<ServoSnapshot> snapshots_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> realtime_priority_{false};
  std::atomic<bool> memory_locked_{false};
};

}  // namespace autograv::demo
