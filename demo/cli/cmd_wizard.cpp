// autograv wizard: the guided calibration (CalibrationWizard) in a terminal, on any device. On a
// simulated one (sim:, or a simulated CHAI3D device) the user's hand is simulated too (keys move
// it, or --auto-hand lets it act alone); on hardware the user's own hand does the manual step and
// the servo loop runs on its own thread, paced by the wall clock.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <future>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <system_error>
#include <thread>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "autograv/device/real_time_priority.h"
#include "autograv/device/wall_clock_tick_source.h"
#include "autograv/devices/device_registry.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "autograv/sim/end_stop_watch.h"
#include "autograv/sim/friction_measurement.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/scripted_wizard_user.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/wizard/calibration_wizard.h"
#include "calibrate_like.h"
#include "cli_support.h"
#include "commands.h"
#include "error_translation.h"
#include "estimation_options.h"
#include "servo_timing_option.h"
#include "wizard_screen.h"
#include "wizard_terminal.h"

namespace autograv::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct WizardOptions {
  std::string device;
  std::string out_path;  // empty: the device's place in the map library
  std::string maps_dir;
  std::string report_path;
  bool resume = false;
  bool yes = false;
  std::string like;  // a prior map to correct instead of a whole calibration
  GridOptions grid;  // the options and defaults of `autograv calibrate`
  double tolerance_mm = 10.0;
  int verify_points = 3;
  // The research and simulation options (AdvancedOptions), once parsed.
  bool auto_hand = false;
  bool uncalibrated = false;
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  sim::SimulatedUnit unit;
  double speed = -1.0;  // < 0: real time on a terminal, as fast as possible otherwise
  double frame_ms = 20.0;
  int boundary_probes = WorkspaceExplorer::Options().boundary_directions;
  FieldModel field_model = kDefaultFieldModel;
  EstimationKnobs estimation;
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;
};

/// `options` with the research and simulation options of `advanced` filled in.
WizardOptions withAdvanced(WizardOptions options, const AdvancedOptions& advanced) {
  options.auto_hand = advanced.wizard().auto_hand;
  options.uncalibrated = advanced.wizard().uncalibrated;
  options.speed = advanced.wizard().speed;
  options.frame_ms = advanced.wizard().frame_ms;
  options.seed = advanced.simulation().seed;
  options.friction = advanced.simulation().friction;
  options.unit = advanced.simulation().unit;
  options.servo_timing = advanced.simulation().servo_timing;
  options.boundary_probes = advanced.run().boundary_probes;
  options.field_model = advanced.run().field_model;
  options.estimation = advanced.estimation();
  return options;
}

// One arrow key moves the simulated hand's target this far, at this speed.
constexpr double kHandStep_m = 0.005;
constexpr double kHandSpeed_m_per_s = 0.1;
// Redraw the terminal at most this often (wall time).
constexpr auto kRedrawPeriod = std::chrono::milliseconds(40);

/// The user's side of the run: keys, the simulated hand, unattended answers.
class FrontEnd {
 public:
  /// `simulation`: the simulated device whose hand the keys move; null on hardware.
  FrontEnd(const WizardOptions& options, CalibrationWizard& wizard,
           sim::SimulatedDevice* simulation, bool answer_prompts)
      : options_(options), wizard_(wizard), device_(simulation), answer_prompts_(answer_prompts) {
    if (options_.auto_hand && device_ != nullptr) auto_hand_.emplace(*device_);
  }

  void onKey(Key key, const WizardStatus& status) {
    switch (key) {
      case Key::kEnter:
        wizard_.post(WizardEvent::kConfirm);
        return;
      case Key::kPause:
        wizard_.post(status.paused ? WizardEvent::kResume : WizardEvent::kPause);
        return;
      case Key::kQuit:
        wizard_.post(WizardEvent::kAbort);
        return;
      case Key::kRedo:
        wizard_.post(WizardEvent::kRedoFailed);
        return;
      default:
        break;
    }
    if (device_ == nullptr) {
      notice = "This is a real device: move the end-effector with your own hand.";
      return;
    }
    if (options_.auto_hand) {
      notice = "The simulated hand is automatic (--auto-hand): hand keys are off.";
      return;
    }
    sim::SimulatedHand& hand = device_->hand();
    if (key == Key::kGrab) {
      if (hand.holding()) {
        hand.release();
      } else {
        hand.grab(device_->truePosition_m());
        hand_goal_m_ = device_->truePosition_m();
      }
      notice.clear();
      return;
    }
    if (!hand.holding()) {
      notice = "Press g to grab the end-effector first.";
      return;
    }
    // CHAI3D frame: x toward the user, y right, z up. Up arrow pushes away from the user.
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    switch (key) {
      case Key::kUp:
        step.x() = -kHandStep_m;
        break;
      case Key::kDown:
        step.x() = kHandStep_m;
        break;
      case Key::kLeft:
        step.y() = -kHandStep_m;
        break;
      case Key::kRight:
        step.y() = kHandStep_m;
        break;
      case Key::kPageUp:
        step.z() = kHandStep_m;
        break;
      case Key::kPageDown:
        step.z() = -kHandStep_m;
        break;
      default:
        break;
    }
    hand_goal_m_ += step;
    hand.moveTo(hand_goal_m_, kHandSpeed_m_per_s);
    notice.clear();
  }

  /// Once per frame, before the servo ticks.
  void beforeTicks(const WizardStatus& status) {
    if (status.step != last_step_) {
      last_step_ = status.step;
      ++step_entries_;
    }
    if (auto_hand_) auto_hand_->update(status);
    if (answer_prompts_) answer(status);
  }

  /// Set when an unattended run cannot go on (the reason is the text).
  std::string give_up;
  std::string notice;

 private:
  // What a user at the keyboard would answer, for runs nobody watches: home an uncalibrated
  // device, redo the failed vertices once, then save.
  void answer(const WizardStatus& status) {
    if (!status.waiting_for_user || answered_entry_ == step_entries_) return;
    switch (status.step) {
      case WizardStep::kCheck:
        if (status.check_issue == CheckIssue::kUncalibrated) {
          wizard_.post(WizardEvent::kConfirm);
        } else if (status.check_issue == CheckIssue::kEarlierCheckpoint) {
          give_up = status.message +
                    " Run again with --resume to continue it, or delete it to start afresh.";
        } else if (status.check_issue != CheckIssue::kNone) {
          give_up = status.message;
        }
        break;
      case WizardStep::kReview:
        if (!status.review_valid) return;
        if (offersRedo(status.review) && !redo_done_) {
          redo_done_ = true;
          wizard_.post(WizardEvent::kRedoFailed);
        } else {
          wizard_.post(WizardEvent::kConfirm);
        }
        break;
      case WizardStep::kSave:
        give_up = "could not save the map: " + status.save_error;
        break;
      default:
        return;  // Centre and Release: the simulated hand answers
    }
    answered_entry_ = step_entries_;
  }

  const WizardOptions& options_;
  CalibrationWizard& wizard_;
  sim::SimulatedDevice* device_;
  std::optional<sim::ScriptedWizardUser> auto_hand_;
  bool answer_prompts_;
  Eigen::Vector3d hand_goal_m_ = Eigen::Vector3d::Zero();
  WizardStep last_step_ = WizardStep::kCheck;
  int step_entries_ = 0;
  int answered_entry_ = -1;
  bool redo_done_ = false;
};

/// Servo time above the continuous force rating and ticks at the force limit. On a simulation,
/// what its actuators delivered and its driver clamped (what a real device would feel); on
/// hardware, what the wizard sent (WizardStatus::force), the same figures from the commands.
struct ForceWatch {
  ForceWatch(const DeviceSpecifications& specifications, const sim::SimulatedDevice* simulation)
      : continuous_n(continuousForceRating_n(specifications)),
        saturations_before(simulation != nullptr ? simulation->saturationCount() : 0) {}
  void record(const sim::SimulatedDevice& simulation, double interval_s) {
    if (simulation.appliedForce_n().norm() > continuous_n) seconds_above_continuous += interval_s;
    limit_ticks = simulation.saturationCount() - saturations_before;
  }
  /// On hardware: the forces the wizard sent, as it measured them.
  void takeSent(const WizardForces& sent) {
    seconds_above_continuous = sent.above_continuous_s;
    limit_ticks = sent.at_limit_ticks;
  }
  double continuous_n;
  std::uint64_t saturations_before;
  double seconds_above_continuous = 0.0;
  std::uint64_t limit_ticks = 0;
};

/// The run's figures, as `autograv calibrate` prints them.
void printResults(const WizardStatus& status, const ForceWatch& force,
                  const DeviceSpecifications& specifications,
                  const std::optional<sim::FieldErrorReport>& field,
                  const std::optional<sim::AccuracyReport>& accuracy,
                  const AgreementText* agreement, const std::string& servo_priority) {
  std::printf("%-34s %s\n", "map", status.map_path.c_str());
  std::printf("%-34s %d / %d\n", "vertices converged", status.converged, status.vertex_count);
  if (!status.workspace.empty()) {
    std::printf("%-34s %d at the vertex, %d just inside the stops, %d beyond reach\n",
                "measurement points", status.measured_at_vertex, status.measured_off_vertex,
                status.beyond_reach);
    std::printf("%-34s %.1f s, %d directions, reach %.1f to %.1f mm\n", "workspace exploration",
                status.exploration_elapsed_s,
                static_cast<int>(status.workspace.directions().size()),
                status.workspace.minRadius_m() * 1e3, status.workspace.maxRadius_m() * 1e3);
  }
  std::printf("%-34s %.1f s\n", "device time", status.time_s);
  if (!servo_priority.empty()) std::printf("%-34s %s\n", "servo thread", servo_priority.c_str());
  if (accuracy) {
    std::printf("%-34s %.2f %% (vertex %d), worst |G_hat - G| %.1f mN\n", "worst measured point",
                100.0 * accuracy->max_error_rel, accuracy->worst_vertex,
                accuracy->max_error_n * 1e3);
  }
  // Where the measurements disagree with one another: no ground truth needed, so on hardware too.
  if (agreement != nullptr) printAgreement("leave-one-out", *agreement);
  if (field) printFieldError(*field);
  std::printf("%-34s %.1f s above %.2f N, %llu ticks at the force limit, %.2f N at most\n",
              "force on the device", force.seconds_above_continuous,
              continuousForceRating_n(specifications),
              static_cast<unsigned long long>(force.limit_ticks), status.force.peak_n);
}

nlohmann::json reportJson(const WizardOptions& options, const std::string& out_path,
                          const CalibrationWizard& wizard, const WizardStatus& status,
                          bool initialization_end_stop_hit) {
  nlohmann::json failed = nlohmann::json::array();
  for (const ReviewRow& row : status.review.failed) {
    failed.push_back({{"vertex", row.vertex},
                      {"outcome", toString(row.outcome)},
                      {"iterations", row.iterations}});
  }
  nlohmann::json verify = nlohmann::json::array();
  for (const VerifyResult& result : status.verify) {
    if (!result.finished) continue;
    verify.push_back({{"vertex", result.vertex},
                      {"drift_m", result.drift_m},
                      {"duration_s", result.duration_s},
                      {"residual_force_n", result.residual_force_n}});
  }
  const WorkspaceGrid& grid = wizard.grid();
  return {
      {"device", options.device},
      {"seed", options.seed},
      {"friction", sim::toString(options.friction)},
      {"outcome", toString(status.step)},
      {"map", status.map_saved ? out_path : ""},
      {"checkpoint", status.checkpoint_written && !status.map_saved ? status.checkpoint_path : ""},
      {"grid", gridJson(grid)},
      {"vertices", status.vertex_count},
      {"converged", status.converged},
      {"explored", !status.workspace.empty()},
      {"exploration_seconds", status.exploration_elapsed_s},
      {"exploration_directions", status.workspace.directions().size()},
      {"workspace_reach_min_m", status.workspace.empty() ? 0.0 : status.workspace.minRadius_m()},
      {"workspace_reach_max_m", status.workspace.empty() ? 0.0 : status.workspace.maxRadius_m()},
      {"measured_at_vertex", status.measured_at_vertex},
      {"measured_inside_stops", status.measured_off_vertex},
      {"beyond_reach", status.beyond_reach},
      {"restored", status.review.restored},
      {"unreachable", status.review.unreachable},
      {"failed", failed},
      {"iterations_median", status.review.iterations_median},
      {"iterations_max", status.review.iterations_max},
      {"lipschitz_n_per_m", status.review.lipschitz_n_per_m},
      {"peak_force_n", status.review.peak_force_n},
      {"initial_gravity_n", vectorJson(status.initial_gravity_n)},
      {"initialization_end_stop_hit", initialization_end_stop_hit},
      {"verify", verify},
      {"max_drift_m", status.max_drift_m},
      {"simulated_seconds", status.time_s},
      {"servo_timing", sim::toString(options.servo_timing)},
      {"servo_loop", servoLoopJson(options.servo_timing, status.servo_loop)},
      {"servo_warning", status.servo_warning},
      {"parameters", parametersJson(wizard.config().advanced.parameters)}};
}

/// The servo loop of a hardware device on its own thread, paced by the wall clock, while the
/// terminal thread runs service() and draws (CalibrationWizard's threading contract). A null
/// wizard starts nothing: simulations are stepped in the frame loop, deterministically. The
/// thread asks for real-time priority before its first tick (a loop at normal priority ticks up
/// to a millisecond late, which the calibration pays for next to the stops); the constructor
/// returns once it has an answer.
class ServoThread {
 public:
  ServoThread(CalibrationWizard* wizard, double period_s) {
    if (wizard == nullptr) return;
    std::promise<RealTimePriority> granted;
    std::future<RealTimePriority> answer = granted.get_future();
    thread_ = std::thread([this, wizard, period_s, granted = std::move(granted)]() mutable {
      granted.set_value(enterRealTimePriority());
      WallClockTickSource ticks(period_s);
      while (!stop_.load(std::memory_order_relaxed) && ticks.waitForNextTick()) {
        wizard->servoTick();
      }
    });
    priority_ = answer.get();
  }
  ~ServoThread() { stop(); }
  ServoThread(const ServoThread&) = delete;
  ServoThread& operator=(const ServoThread&) = delete;
  void stop() {
    stop_.store(true);
    if (thread_.joinable()) thread_.join();
  }
  /// What the servo thread got; none for a simulation.
  const std::optional<RealTimePriority>& priority() const noexcept { return priority_; }

 private:
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::optional<RealTimePriority> priority_;
};

/// `wizard --like MAP`: this unit's map corrected from another unit's in under a minute and a
/// half. True when it was saved; false when the correction was refused and the user asked for
/// the whole calibration instead (the caller goes on with it). Throws autograv::Error when it
/// was refused and nobody can answer, saying what to run instead.
bool runWizardLike(const WizardOptions& options, bool interactive) {
  const DeviceHandle handle =
      openDevice(options.device, options.seed, options.friction, options.unit);
  HapticDevice& device = *handle.device;
  const DeviceSpecifications specifications = device.specifications();
  TransferOptions transfer;
  transfer.parameters =
      estimationParameters(options.estimation, EstimationMethod::kDither, specifications);
  const GravityMap prior = loadPrior(options.like, options.maps_dir, specifications.model_name,
                                     specifications.serial_number, transfer, transfer.prior_source);
  const std::string out_path = options.out_path.empty()
                                   ? MapLibrary(options.maps_dir).pathFor(specifications)
                                   : options.out_path;
  checkWritable(out_path, "map");
  if (!options.report_path.empty()) checkWritable(options.report_path, "report");
  std::printf(
      "Correcting %s to this %s: a few probes of the stops, then the field at 12 to 32 "
      "points.\n",
      transfer.prior_source.c_str(), specifications.model_name.c_str());
  const Eigen::Vector3d center_m = prior.metadata().workspace.center_m();
  if (handle.simulation != nullptr) {
    // The simulated hand puts the stylus in the middle and lets go; the prior holds it.
    handle.simulation->setForce(prior.gravityAt(center_m));
    handle.simulation->advance(transfer.parameters.servo_period_s);
    handle.simulation->resetState(center_m);
  } else {
    std::printf(
        "Hold the stylus near the middle of the workspace (about [%.0f, %.0f, %.0f] mm), "
        "press Enter, and let go once it holds itself.\n",
        center_m.x() * 1e3, center_m.y() * 1e3, center_m.z() * 1e3);
    std::fflush(stdout);
    std::string ignored;
    std::getline(std::cin, ignored);
  }
  const std::optional<RealTimePriority> priority = enterServoPriority(handle);
  const auto ticks = makeTickSource(handle, transfer.parameters.servo_period_s,
                                    /*real_time=*/handle.simulation == nullptr);
  ProgressBar progress("point");
  transfer.on_progress = [&](const TransferProgress& now) {
    progress.update(now.done, now.total,
                    now.phase == TransferProgress::Phase::kProbing ? "probing the stops"
                                                                   : "measuring the field");
  };
  const TransferResult result = transferMap(device, *ticks, prior, transfer);
  progress.finish();
  device.close();
  printTransfer(result);
  nlohmann::json report = transferReportJson(result);
  report["device"] = options.device;
  addServoPriorityJson(report, priority);
  if (result.accepted) {
    saveMap(*result.map, out_path);
    report["map"] = out_path;
    if (handle.simulation != nullptr) {
      addFieldErrorJson(report, sim::measureFieldError(*result.map, *handle.simulation));
    }
    writeJsonReport(options.report_path, report);
    std::printf("Map saved to %s (%.1f s of device time).\n", out_path.c_str(), result.seconds);
    return true;
  }
  writeJsonReport(options.report_path, report);
  std::printf("No map was saved: %s.\n", result.refusal.c_str());
  if (interactive && !options.yes) {
    std::printf("Run the whole calibration now? [y/N] ");
    std::fflush(stdout);
    std::string answer;
    std::getline(std::cin, answer);
    if (!answer.empty() && (answer[0] == 'y' || answer[0] == 'Y')) return false;
  }
  throw Error(
      "the correction was refused and no map was saved; calibrate this unit whole with "
      "`autograv wizard --device " +
      options.device + "` (without --like)");
}

void runWizardCommand(const WizardOptions& options) {
  const bool interactive = interactiveTerminal();
  if (!options.like.empty() && runWizardLike(options, interactive || options.auto_hand)) return;
  if (!interactive && !options.auto_hand) {
    throw Error(
        "standard input or output is not a terminal, so nobody can press keys or move the "
        "simulated hand: add --auto-hand to let the simulated hand do the manual step (prompts "
        "are then answered automatically: failed vertices are redone once, then the map is "
        "saved)");
  }
  const DeviceHandle handle =
      makeDevice(options.device, options.seed, options.friction, options.unit);
  const std::shared_ptr<HapticDevice>& device = handle.device;
  sim::SimulatedDevice* simulation = handle.simulation.get();
  if (simulation == nullptr && (options.auto_hand || options.uncalibrated)) {
    throw Error(std::string(options.auto_hand ? "--auto-hand" : "--uncalibrated") +
                " needs a simulated device; on " + options.device +
                " your own hand does the manual step");
  }
  if (options.uncalibrated) simulation->setCalibrated(false);
  if (simulation == nullptr && options.servo_timing != sim::ServoTiming::kExact) {
    throw Error("--servo-timing " + std::string(sim::toString(options.servo_timing)) +
                " shapes a simulated loop; on " + options.device +
                " the servo thread keeps the wall clock's time (drop the option)");
  }
  // A CHAI3D device's specifications are valid only once it has been opened: read them now; the
  // wizard's Check step opens it again.
  if (!device->open()) {
    throw Error("cannot open " + options.device + " to read its model and limits");
  }
  const DeviceSpecifications specifications = device->specifications();
  device->close();
  std::string out_path = options.out_path;
  if (out_path.empty()) {  // the device's place in the map library, where every tool looks
    const MapLibrary library(options.maps_dir);
    std::error_code error;
    std::filesystem::create_directories(library.dir(), error);
    if (error) {
      throw Error("cannot create the map library '" + library.dir() + "': " + error.message() +
                  "; choose another with --maps, or name the map with --out");
    }
    out_path = library.pathFor(specifications);
  }
  // Refuse now, not after the whole grid, when the files cannot be written.
  checkWritable(out_path, "map");
  checkWritable(out_path + ".partial", "checkpoint");
  if (!options.report_path.empty()) checkWritable(options.report_path, "report");
  // A handle change does not need the whole grid again: say so before the long run.
  const std::string retare_offer =
      std::filesystem::exists(out_path) && !options.resume
          ? "A map for this device exists (" + out_path +
                "). If only the handle changed, `autograv retare --device " + options.device +
                "` re-tares it in seconds; this run replaces it."
          : std::string();

  WizardConfig config;
  // The grid of `autograv calibrate`, so that either command resumes the other's run: by
  // default the box around the workspace the device explores first, the user initializing near
  // the workspace's centre (a simulation's, or the origin where CHAI3D centres its positions);
  // with --box-mm or --side-mm that box, measured inside the explored workspace.
  if (gridFromWorkspace(options.grid)) {
    config.centre_m =
        simulation != nullptr ? simulation->workspaceCenter_m() : Eigen::Vector3d::Zero();
    config.grid_resolution = gridResolution(options.grid);
  } else {
    double workspace_coverage = 0.0;
    const WorkspaceGrid grid = resolveGrid(options.grid, *device, simulation, workspace_coverage);
    config.centre_m = grid.center_m();
    config.advanced.box_size_m = grid.size_m();
    config.grid_resolution = grid.resolution();
  }
  // The same device-aware k0 as `autograv calibrate`: the paper's 500 N/m makes the Omni's arm
  // buzz in the field instead of settling.
  config.advanced.parameters =
      estimationParameters(options.estimation, EstimationMethod::kDither, specifications);
  config.map_path = out_path;
  config.resume = options.resume;
  config.advanced.centre_tolerance_m = options.tolerance_mm * 1e-3;
  config.verify_points = options.verify_points;
  config.advanced.explorer.boundary_directions = options.boundary_probes;
  config.advanced.field_model = options.field_model;
  const double period_s = config.advanced.parameters.servo_period_s;
  // The simulated loop's ticks, as --servo-timing draws them; an exact loop needs no clock (the
  // wizard then counts exact periods). Hardware runs on the wall clock's time.
  sim::ServoTimingModel timing(options.servo_timing, options.seed, period_s);
  if (simulation == nullptr) {
    config.clock = std::make_shared<SteadyServoClock>();
  } else if (options.servo_timing != sim::ServoTiming::kExact) {
    config.clock = std::make_shared<sim::ServoTimingClock>(timing);
  }
  CalibrationWizard wizard(device, config);

  const int ticks_per_frame =
      std::max(1, static_cast<int>(std::lround(options.frame_ms * 1e-3 / period_s)));
  const double frame_s = ticks_per_frame * period_s;
  // Hardware keeps its own time: the servo thread below paces it, the frames only redraw.
  const double speed = simulation == nullptr  ? 1.0
                       : options.speed >= 0.0 ? options.speed
                                              : (interactive ? 1.0 : 0.0);
  FrontEnd front_end(options, wizard, simulation, !interactive || options.yes);
  if (!retare_offer.empty()) {
    front_end.notice = retare_offer;
    std::fprintf(stderr, "%s\n", retare_offer.c_str());
  }
  ServoThread servo(simulation == nullptr ? &wizard : nullptr, period_s);
  const std::string servo_priority = servo.priority() ? describe(*servo.priority()) : "";
  if (servo.priority()) warnIfNormalPriority(*servo.priority());

  installInterruptHandlers();
  struct HandlersGuard {
    ~HandlersGuard() { removeInterruptHandlers(); }
  } handlers_guard;
  std::optional<RawTerminal> terminal;
  if (interactive) terminal.emplace();
  TerminalScreen screen;
  PlainLog log(stdout);
  KeyDecoder decoder;
  ScreenContext context;
  context.device_name = options.device;
  context.simulated_hand = simulation != nullptr;
  context.auto_hand = options.auto_hand;
  int interrupts_seen = 0;
  bool left_at_once = false;
  Clock::time_point last_draw = Clock::now() - kRedrawPeriod;
  WizardStep drawn_step = WizardStep::kCheck;

  WizardStatus status = inCommandLineTerms(wizard.status());
  if (!terminal) log.update(status);
  // Eq. (7) assumes the end-effector settled in the k0 field alone. The wizard judges that from
  // driver data once the workspace is explored; on a simulation the report also says whether it
  // really touched a stop (ground truth, for scoring only).
  bool initialization_end_stop_hit = false;
  sim::InitializationEndStopWatch end_stop_watch;
  ForceWatch force_watch(specifications, simulation);
  while (true) {
    const Clock::time_point frame_start = Clock::now();
    const int interrupts = g_interrupts.load();
    if (interrupts > interrupts_seen) {
      interrupts_seen = interrupts;
      if (interrupts >= 2) {
        left_at_once = true;
        break;
      }
      wizard.post(WizardEvent::kAbort);
      front_end.notice =
          "Stopping: finished vertices are kept in the checkpoint. Ctrl-C again leaves at once.";
    }
    if (terminal) {
      std::vector<Key> keys;
      decoder.feed(terminal->readAvailable(), keys);
      for (Key key : keys) front_end.onKey(key, status);
    }
    front_end.beforeTicks(status);
    if (!front_end.give_up.empty()) break;
    if (simulation != nullptr && options.servo_timing == sim::ServoTiming::kExact) {
      for (int i = 0; i < ticks_per_frame; ++i) {
        wizard.servoTick();
        simulation->advance(timing.nextInterval_s());
        force_watch.record(*simulation, timing.lastInterval_s());
      }
    } else if (simulation != nullptr) {
      const double frame_end_s = timing.now_s() + frame_s;
      while (timing.now_s() < frame_end_s) {
        wizard.servoTick();
        simulation->advance(timing.nextInterval_s());
        force_watch.record(*simulation, timing.lastInterval_s());
      }
    }
    wizard.service();
    status = inCommandLineTerms(wizard.status());
    if (simulation != nullptr &&
        end_stop_watch.update(status.step == WizardStep::kRelease, *simulation)) {
      initialization_end_stop_hit = true;
    }

    if (terminal) {
      const Clock::time_point now = Clock::now();
      if (now - last_draw >= kRedrawPeriod || status.step != drawn_step || wizard.finished()) {
        if (simulation != nullptr) {
          context.hand_holding = simulation->hand().holding();
          context.hand_target_m = simulation->hand().target_m();
        }
        context.notice = front_end.notice;
        int columns = 80, rows = 24;
        terminalSize(columns, rows);
        screen.draw(renderScreen(status, context, columns, rows));
        last_draw = now;
        drawn_step = status.step;
      }
    } else {
      log.update(status);
    }
    if (wizard.finished()) break;
    if (speed > 0.0) {
      std::this_thread::sleep_until(frame_start +
                                    std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(frame_s / speed)));
    }
  }
  servo.stop();
  terminal.reset();  // back to the normal screen before the last words

  if (simulation == nullptr) force_watch.takeSent(status.force);
  nlohmann::json report =
      reportJson(options, out_path, wizard, status, initialization_end_stop_hit);
  report["continuous_force_n"] = continuousForceRating_n(specifications);
  report["peak_force_n"] = status.force.peak_n;
  report["seconds_above_continuous_force"] = force_watch.seconds_above_continuous;
  report["force_limit_ticks"] = force_watch.limit_ticks;
  addServoPriorityJson(report, servo.priority());
  if (const std::shared_ptr<const GravityMap> saved = wizard.savedMap()) {
    addReviewedJson(report, *saved);
  }
  // On a simulation, the field where the hand can be against its ground truth (scoring only),
  // as `autograv calibrate` reports it.
  std::optional<sim::FieldErrorReport> field;
  std::optional<sim::AccuracyReport> accuracy;
  if (simulation != nullptr && status.map_saved && wizard.savedMap()) {
    // Where the error beats the breakaway force, measured on a fresh copy of a sim: device (a
    // simulation behind another driver, as CHAI3D's stand-in, has no copy to measure).
    double breakaway_n = 0.0;
    if (options.device.rfind("sim:", 0) == 0) {
      auto bench =
          openSimulatedDevice(options.device, options.seed, options.friction, options.unit);
      breakaway_n = sim::measureFriction(*bench).breakaway_force_n;
    }
    field = sim::measureFieldError(*wizard.savedMap(), *simulation, sim::kFieldErrorSamples,
                                   options.seed, 5e-3, breakaway_n);
    accuracy = sim::measureAccuracy(*wizard.savedMap(), *simulation, 1000, options.seed);
    report["max_error_rel"] = accuracy->max_error_rel;
    report["worst_vertex"] = accuracy->worst_vertex;
    report["max_error_n"] = accuracy->max_error_n;
    addFieldErrorJson(report, *field);
  }
  std::optional<AgreementText> agreement;
  if (status.map_saved && wizard.savedMap()) {
    const MapAgreement judged = judgeAgreement(*wizard.savedMap());
    addAgreementJson(report, judged);
    addFieldModelJson(report, *wizard.savedMap());
    agreement = describeAgreement(*wizard.savedMap(), judged);
  }
  writeJsonReport(options.report_path, report);
  if (status.map_saved) {
    printResults(status, force_watch, specifications, field, accuracy,
                 agreement ? &*agreement : nullptr, servo_priority);
    if (const std::shared_ptr<const GravityMap> saved = wizard.savedMap()) {
      std::printf("%-34s %s\n", "motors warming (thermal drift)",
                  describeThermalDrift(saved->metadata().thermal_drift).c_str());
    }
  }
  if (left_at_once) {
    throw Error("interrupted twice: left at once; vertices finished before are in " +
                wizard.checkpointPath() + " (resume with --resume)");
  }
  if (!front_end.give_up.empty()) throw Error(front_end.give_up);
  if (interactive) std::printf("%s\n%s\n", status.title.c_str(), status.message.c_str());
  if (status.step == WizardStep::kAborted) throw Error("stopped: " + status.message);
  if (status.step == WizardStep::kFault) throw Error(status.message);
}

void addWizardCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<WizardOptions>();
  CLI::App* command = app.add_subcommand(
      "wizard",
      "Guided calibration in the terminal: check, centre, release, auto-calibration, review, "
      "save, verify (resumable)");
  addDeviceOption(*command, options->device);
  command->add_option("--out", options->out_path,
                      "Map file to write (JSON; default: the device's place in the map library); "
                      "checkpoints go to <out>.partial");
  addMapsOption(*command, options->maps_dir);
  command->add_flag("--resume", options->resume,
                    "Continue an interrupted run (of wizard or calibrate) from <out>.partial");
  command->add_flag("--yes", options->yes,
                    "Answer the prompts automatically (redo failed vertices once, then save)");
  addGridOptions(*command, options->grid);
  addLikeOption(*command, options->like);
  command
      ->add_option("--tolerance-mm", options->tolerance_mm,
                   "How close to the centre the Centre step accepts [mm]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--verify-points", options->verify_points,
                   "Release tests in the Verify step (0 skips it)")
      ->check(CLI::Range(0, kMaxVerifyPoints))
      ->capture_default_str();
  addReportOption(*command, options->report_path);
  advanced->accept(*command, {knob::kSimulatedDevice, knob::kServoTiming, knob::kEstimation,
                              knob::kBoundaryProbes, knob::kFieldModel, knob::kSimulatedWizard});
  command->callback([options, advanced] { runWizardCommand(withAdvanced(*options, *advanced)); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(60, addWizardCommand);

}  // namespace autograv::cli
