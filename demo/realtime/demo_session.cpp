#include "demo_session.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "autograv/device/real_time_priority.h"
#include "autograv/device/servo_sample.h"
#include "autograv/devices/device_registry.h"
#include "autograv/error.h"
#include "autograv/estimation/impedance_hold.h"
#include "autograv/estimation/pd_design.h"

namespace autograv::demo {

namespace {
/// Floor on |G_hat| for the apparent mass of the handover hold (constraint 6), whose feedforward
/// is the new map's value where the wizard left the end-effector. The demo's own floor, twice
/// VertexEstimator::kMinGravityN: only the gains of a near-weightless end-effector depend on
/// it. Unit: [N]
constexpr double kHandoverMinGravityN = 0.02;
}  // namespace

const char* toString(ServoMode mode) noexcept {
  switch (mode) {
    case ServoMode::kApplication:
      return "application";
    case ServoMode::kCalibrating:
      return "calibrating";
    case ServoMode::kHandover:
      return "handover";
  }
  return "unknown";
}

DemoSession::DemoSession(const SessionOptions& options)
    : options_(options),
      timing_(static_cast<std::int64_t>(std::llround(options.servo_period_s * 1e9))) {
  if (!(options.servo_period_s > 0.0 && options.servo_period_s <= 0.01)) {
    throw Error("servo period must be in (0, 10] ms");
  }
  // Any device name (sim:omni, chai3d:0, ...); the mouse is a simulated hand, so the demo needs
  // the simulation behind the device, while every force and position goes through the device
  // itself (a simulated CHAI3D device is driven through Chai3dDeviceAdapter).
  const DeviceHandle handle = makeDevice(options.device, options.seed, options.friction);
  if (!handle.simulation) {
    throw Error(
        "autograv-demo: the mouse plays a simulated hand, so the demo runs on a simulated "
        "device (sim:..., or a simulated CHAI3D device); on " +
        options.device +
        " calibrate with `autograv wizard`, and use the CHAI3D bridge in your application");
  }
  device_ = handle.device;
  simulation_ = handle.simulation;
  if (!device_->open()) throw Error(options.device + ": open() failed");
  if (!device_->calibrate()) throw Error(options.device + ": homing (calibrate) failed");
  simulation_->resetState(simulation_->workspaceCenter_m());
  // The user holds the stylus when the program starts, as with a real device: compensation ramps
  // in (over ramp_duration_s) while the hand carries the weight, not while the end-effector falls.
  simulation_->hand().grab(simulation_->workspaceCenter_m());
  CompensationOptions compensation = options.compensation;
  // The servo loop's time is the simulation's: one period per tick on simulated time
  // (runTicks), the time that really passed on the wall clock (the servo thread).
  clock_ = std::make_shared<LoopClock>();
  compensation.clock = clock_;
  decorator_ = std::make_shared<GravityCompensatedDevice>(device_, compensation);
  if (!decorator_->open()) throw Error(options.device + ": open() through the decorator failed");
  options_.estimation.servo_period_s = options.servo_period_s;
  // The demo has no k0 option: the device-aware default, as `autograv calibrate` uses.
  options_.estimation.k0_n_per_m = defaultInitializationStiffness(simulation_->specifications());
  last_position_m_ = simulation_->truePosition_m();
  // A first snapshot so that the UI has something to draw before the first tick.
  ServoSample sample;
  sample.valid = true;
  sample.position_m = last_position_m_;
  publishSnapshot(sample);
}

DemoSession::~DemoSession() { stopRealTime(); }

void DemoSession::publishMap(std::shared_ptr<const GravityMap> map) {
  decorator_->publishMap(std::move(map));
}

void DemoSession::sendCommand(const Command& command) {
  // The queue holds 256 commands; the servo thread drains it every millisecond, so a full queue
  // means the servo thread has stopped.
  if (!commands_.push(command)) throw Error("the servo loop is not taking commands");
}

void DemoSession::grab() {
  Command command;
  command.kind = Command::Kind::kGrab;
  sendCommand(command);
}

void DemoSession::setHandTarget(const Eigen::Vector3d& target_m) {
  Command command;
  command.kind = Command::Kind::kSetTarget;
  command.position_m = target_m;
  sendCommand(command);
}

void DemoSession::release() {
  Command command;
  command.kind = Command::Kind::kRelease;
  sendCommand(command);
}

void DemoSession::setCompensationEnabled(bool enabled) noexcept {
  decorator_->setCompensationEnabled(enabled);
}

void DemoSession::setScript(const HandScript* script) { script_player_ = HandScriptPlayer(script); }

WorkspaceGrid DemoSession::calibrationGrid() const {
  if (const auto map = decorator_->publishedMap()) return map->grid();
  // Still the cube of 80 % of the inscribed cube: the fitted box of `autograv calibrate` doubles
  // the cell at 5 vertices per axis, and the demo's release test drifts 2.7 mm instead of
  // under 1 mm on it.
  const double side_m = defaultGridSide_m(simulation_->specifications().workspace_radius_m);
  return WorkspaceGrid(simulation_->workspaceCenter_m(), side_m, options_.calibration_resolution);
}

std::string DemoSession::startCalibration() {
  if (wizard_ui_ != nullptr) return "a calibration is already running (press A to abort it)";
  WizardConfig config;
  // As `autograv calibrate` and `autograv wizard` do by default: after the initialization the
  // wizard explores the workspace from the device's own data, fits the grid to it and measures
  // only inside it. The user initializes at the centre of the published map's grid, else of the
  // workspace.
  config.centre_m = calibrationGrid().center_m();
  config.grid_resolution = Eigen::Vector3i::Constant(options_.calibration_resolution);
  config.advanced.parameters = options_.estimation;
  config.map_path = options_.calibration_map_path;
  config.resume = std::filesystem::exists(options_.calibration_map_path + ".partial");
  config.verify_points = options_.calibration_verify_points;
  config.clock = clock_;  // servo time as the loop keeps it (LoopClock)
  // Opened and homed in the constructor, and ticked by the servo thread until the wizard's
  // servo half takes over: its Check must not open or home it again from this thread.
  config.advanced.device_already_open = true;
  wizards_.push_back(std::make_unique<CalibrationWizard>(device_, config));
  wizard_ui_ = wizards_.back().get();
  wizard_ui_->service();  // Check: the device is open already, so this passes at once
  wizard_status_ = wizard_ui_->status();
  last_wizard_step_ = wizard_status_.step;
  compensation_before_calibration_ = decorator_->compensationEnabled();
  decorator_->setCompensationEnabled(false);
  initialization_end_stop_hit_.store(false);
  Command command;
  command.kind = Command::Kind::kStartCalibration;
  command.wizard = wizard_ui_;
  sendCommand(command);
  return std::string("calibration: ") +
         (config.resume ? "resuming the checkpoint " + wizard_ui_->checkpointPath()
                        : "checkpoints go to " + wizard_ui_->checkpointPath());
}

void DemoSession::postCalibrationEvent(WizardEvent event) noexcept {
  if (wizard_ui_ != nullptr) wizard_ui_->post(event);
}

void DemoSession::abortCalibration() {
  if (wizard_ui_ != nullptr) wizard_ui_->post(WizardEvent::kAbort);
}

std::string DemoSession::updateCalibration() {
  if (wizard_ui_ == nullptr) return "";
  wizard_ui_->service();
  wizard_status_ = wizard_ui_->status();
  std::string message;
  if (wizard_status_.step != last_wizard_step_) {
    last_wizard_step_ = wizard_status_.step;
    message = "calibration: " + wizard_status_.title;
  }
  if (!wizard_ui_->finished()) return message;

  // Done, aborted or failed, with every checkpoint written: the application takes the device
  // back. After a saved map, compensation comes on under it while a hold fades out.
  Command command;
  command.kind = Command::Kind::kEndCalibration;
  const std::shared_ptr<const GravityMap> map = wizard_ui_->savedMap();
  if (wizard_status_.step == WizardStep::kDone && map) {
    decorator_->publishMap(map);
    decorator_->setCompensationEnabled(true);
    command.map = map.get();  // kept alive by the wizard, which the session keeps
    message = "calibration finished: " + std::to_string(map->convergedCount()) + " of " +
              std::to_string(map->grid().vertexCount()) + " vertices converged; map saved to " +
              wizard_status_.map_path + ", compensation on";
  } else if (wizard_status_.step == WizardStep::kAborted) {
    decorator_->setCompensationEnabled(compensation_before_calibration_);
    message = "calibration aborted: " + std::to_string(wizard_status_.checkpointed_converged) +
              " finished vertices kept in " + wizard_status_.checkpoint_path +
              "; press A to resume";
  } else {
    decorator_->setCompensationEnabled(compensation_before_calibration_);
    message = "calibration stopped: " + wizard_status_.fault;
  }
  sendCommand(command);
  wizard_ui_ = nullptr;
  return message;
}

void DemoSession::grabNow() noexcept {
  simulation_->hand().grab(simulation_->truePosition_m());
  released_ = false;
}

void DemoSession::releaseNow() noexcept {
  if (!simulation_->hand().holding()) return;
  simulation_->hand().release();
  released_ = true;
  release_position_m_ = last_position_m_;
  release_tick_ = ticks_;
}

void DemoSession::handleCommand(const Command& command) noexcept {
  switch (command.kind) {
    case Command::Kind::kGrab:
      grabNow();
      break;
    case Command::Kind::kSetTarget:
      simulation_->hand().setTarget(command.position_m);
      break;
    case Command::Kind::kRelease:
      releaseNow();
      break;
    case Command::Kind::kStartCalibration:
      wizard_ = command.wizard;
      mode_ = ServoMode::kCalibrating;
      end_stop_watch_ = sim::InitializationEndStopWatch();
      break;
    case Command::Kind::kEndCalibration:
      if (mode_ != ServoMode::kCalibrating) break;
      wizard_ = nullptr;
      if (command.map != nullptr) {
        // The wizard left the device floating under this map; hold it there while the
        // decorator's compensation takes over.
        hold_position_m_ = last_position_m_;
        hold_gravity_n_ = command.map->gravityAt(last_position_m_);
        mode_ = ServoMode::kHandover;
      } else {
        mode_ = ServoMode::kApplication;
      }
      break;
  }
}

void DemoSession::handleScriptEvent(const HandEvent& event) noexcept {
  switch (event.kind) {
    case HandEvent::Kind::kGrab:
      grabNow();
      break;
    case HandEvent::Kind::kMove:
      simulation_->hand().moveTo(event.position_m, event.speed_m_per_s);
      break;
    case HandEvent::Kind::kRelease:
      releaseNow();
      break;
    case HandEvent::Kind::kCompensationOn:
      decorator_->setCompensationEnabled(true);
      break;
    case HandEvent::Kind::kCompensationOff:
      decorator_->setCompensationEnabled(false);
      break;
  }
}

Eigen::Vector3d DemoSession::holdForce(const ServoSample& sample) const noexcept {
  // Paper eq. (10) with the last estimate as feedforward and eq. (11)'s gains.
  const ImpedanceHold hold = ImpedanceHold::from(options_.estimation, kHandoverMinGravityN);
  Eigen::Vector3d force_n = hold.holdForce_n(
      hold_position_m_, sample, hold.apparentMass_kg(hold_gravity_n_), hold_gravity_n_);
  clampForce(force_n, simulation_->specifications().max_linear_force_n);
  return force_n;
}

void DemoSession::catchUpWithTheWallClock() noexcept {
  // The device moved for as long as really passed since the previous tick, under the force that
  // tick sent (a zero-order hold, as a real device's while its loop is late or early); a stall
  // longer than kMaxCatchUp_s (a debugger, a suspended process) is not simulated whole.
  const auto now = std::chrono::steady_clock::now();
  const double interval_s = std::chrono::duration<double>(now - paced_last_tick_).count();
  paced_last_tick_ = now;
  if (interval_s > 0.0) advanceSimulation(std::min(interval_s, kMaxCatchUp_s));
}

void DemoSession::advanceSimulation(double dt_s) noexcept {
  simulation_->advance(dt_s);
  clock_->advance(dt_s);
}

void DemoSession::tick() noexcept {
  if (paced_) catchUpWithTheWallClock();
  Command command;
  while (commands_.pop(command)) handleCommand(command);
  const double time_s = static_cast<double>(ticks_) * options_.servo_period_s;
  while (const HandEvent* event = script_player_.nextDue(time_s)) handleScriptEvent(*event);

  const ServoSample sample = readServoSample(*decorator_);
  if (sample.valid) last_position_m_ = sample.position_m;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  switch (mode_) {
    case ServoMode::kApplication:
      // The application renders free space: it asks for no force, and the decorator adds G_hat.
      decorator_->setForce(Eigen::Vector3d::Zero());
      break;
    case ServoMode::kCalibrating:
      // The wizard reads and writes the device itself, through its own decorator.
      wizard_->servoTick();
      break;
    case ServoMode::kHandover: {
      // The decorator ramps its compensation in from wherever its level stood; the hold (with
      // the last vertex estimate as feedforward) gives way at the same pace, so the sum keeps
      // carrying the weight. Once the ramp is complete the application loop takes over.
      const double level = decorator_->compensationLevel();
      if (sample.valid) force_n = (1.0 - level) * holdForce(sample);
      decorator_->setForce(force_n);
      if (level >= 1.0 || !decorator_->compensationEnabled()) mode_ = ServoMode::kApplication;
      break;
    }
  }
  // On simulated time the next tick comes one period later; a paced loop advances the
  // simulation at the start of each tick by the time that really passed.
  if (!paced_) advanceSimulation(options_.servo_period_s);
  if (mode_ == ServoMode::kCalibrating &&
      end_stop_watch_.update(wizard_->step() == WizardStep::kRelease, *simulation_)) {
    initialization_end_stop_hit_.store(true);
  }
  ++ticks_;
  publishSnapshot(sample);
}

void DemoSession::publishSnapshot(const ServoSample& sample) noexcept {
  ServoSnapshot& s = snapshots_.writeSlot();
  s.ticks = ticks_;
  s.time_s = static_cast<double>(ticks_) * options_.servo_period_s;
  s.sample_valid = sample.valid;
  if (sample.valid) {
    s.position_m = sample.position_m;
    s.velocity_m_per_s = sample.velocity_m_per_s;
  }
  s.force_sent_n = simulation_->appliedForce_n();
  s.hand_holding = simulation_->hand().holding();
  s.hand_target_m = simulation_->hand().target_m();
  s.compensation_enabled = decorator_->compensationEnabled();
  s.compensation_level = decorator_->compensationLevel();
  s.map_in_use = decorator_->latestMapInUse();
  s.clamps = decorator_->clampCount();
  s.device_saturations = simulation_->saturationCount();
  s.faults = decorator_->faultCount();
  s.last_fault = decorator_->lastFault();
  s.released = released_;
  s.drift_m = released_ ? (last_position_m_ - release_position_m_).norm() : 0.0;
  s.since_release_s =
      released_ ? static_cast<double>(ticks_ - release_tick_) * options_.servo_period_s : 0.0;
  s.mode = mode_;
  if (wizard_ != nullptr) s.wizard_step = wizard_->step();
  s.realtime = timing_valid_;
  if (timing_valid_) s.timing = timing_.report();
  snapshots_.publish();
}

void DemoSession::runTicks(std::int64_t count) noexcept {
  for (std::int64_t i = 0; i < count; ++i) tick();
}

void DemoSession::startRealTime() {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this] { servoThreadMain(); });
}

void DemoSession::stopRealTime() {
  if (!thread_.joinable()) return;
  stop_.store(true);
  thread_.join();
  paced_ = false;  // runTicks steps simulated time again
  // The servo loop no longer runs: leave the device without force.
  device_->setForce(Eigen::Vector3d::Zero());
}

void DemoSession::servoThreadMain() {
  if (options_.realtime_priority) {
    const RealTimePriority priority = enterRealTimePriority(/*lock_memory=*/true);
    realtime_priority_.store(priority.granted);
    memory_locked_.store(priority.memory_locked);
  }
  const auto period_ns = std::llround(options_.servo_period_s * 1e9);
  timing_ = ServoTiming(period_ns);
  timing_valid_ = true;
  // Servo time starts at the first deadline (runPaced: one period from now).
  paced_last_tick_ = std::chrono::steady_clock::now() + std::chrono::nanoseconds(period_ns);
  paced_ = true;
  runPaced(period_ns, stop_, timing_, [this] { tick(); });
}

}  // namespace autograv::demo
