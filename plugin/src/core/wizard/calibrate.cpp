// calibrate(): a CalibrationWizard run to its end, its servo half on a thread of its own, its
// service half on the calling thread, and the answers to the prompts nobody else answers.
#include "autograv/wizard/calibrate.h"

#include <chrono>
#include <cmath>
#include <future>
#include <sstream>
#include <thread>
#include <utility>

#include "autograv/device/servo_clock.h"
#include "autograv/device/wall_clock_tick_source.h"
#include "autograv/error.h"

namespace autograv {

namespace {

using Clock = std::chrono::steady_clock;

Clock::duration wallDuration(double seconds) {
  return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
}

void refuseOptions(const CalibrateOptions& options) {
  const auto refuse = [](const char* field, double value, const char* expected) {
    std::ostringstream message;
    message << "calibrate: CalibrateOptions::" << field << " must be " << expected << ", got "
            << value;
    throw Error(message.str());
  };
  if (!(std::isfinite(options.speed) && options.speed >= 0.0)) {
    refuse("speed", options.speed, "a finite multiple of real time >= 0 (1 for a real device)");
  }
  if (!(std::isfinite(options.frame_s) && options.frame_s > 0.0 && options.frame_s <= 1.0)) {
    refuse("frame_s", options.frame_s, "a time in (0, 1] s");
  }
  if (!(std::isfinite(options.progress_period_s) && options.progress_period_s >= 0.0)) {
    refuse("progress_period_s", options.progress_period_s, "a time >= 0 in seconds");
  }
}

/// The wizard's servo half on a thread of its own, paced as CalibrateOptions::speed says. Only
/// servoTick() runs on it: no allocation, lock or I/O per tick.
class ServoThread {
 public:
  ServoThread(CalibrationWizard& wizard, double period_s, double speed, bool real_time_priority)
      : wizard_(wizard) {
    if (speed == 1.0) {
      // Refused here, on the calling thread, rather than on the servo thread.
      auto ticks = std::make_unique<WallClockTickSource>(period_s);
      std::promise<std::optional<RealTimePriority>> granted;
      std::future<std::optional<RealTimePriority>> answer = granted.get_future();
      thread_ = std::thread([this, real_time_priority, ticks = std::move(ticks),
                             granted = std::move(granted)]() mutable {
        granted.set_value(real_time_priority ? std::optional(enterRealTimePriority())
                                             : std::nullopt);
        while (!stop_.load(std::memory_order_relaxed) && ticks->waitForNextTick()) {
          wizard_.servoTick();
        }
      });
      priority_ = answer.get();
      return;
    }
    thread_ = std::thread([this, period_s, speed] {
      if (speed == 0.0) {
        while (!stop_.load(std::memory_order_relaxed)) wizard_.servoTick();
        return;
      }
      // Sleeping per tick below tens of microseconds is not possible: sleep in chunks, on
      // absolute deadlines, and do not catch up in a burst after the machine was busy.
      const Clock::duration period = wallDuration(period_s / speed);
      Clock::time_point next = Clock::now();
      while (!stop_.load(std::memory_order_relaxed)) {
        wizard_.servoTick();
        next += period;
        const Clock::time_point now = Clock::now();
        if (next - now > std::chrono::microseconds(200)) {
          std::this_thread::sleep_until(next);
        } else if (now - next > std::chrono::milliseconds(50)) {
          next = now;
        }
      }
    });
  }
  ~ServoThread() { stop(); }
  ServoThread(const ServoThread&) = delete;
  ServoThread& operator=(const ServoThread&) = delete;

  void stop() {
    stop_.store(true, std::memory_order_relaxed);
    if (thread_.joinable()) thread_.join();
  }
  const std::optional<RealTimePriority>& priority() const noexcept { return priority_; }

 private:
  CalibrationWizard& wizard_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::optional<RealTimePriority> priority_;
};

/// CalibrateOptions::answer_prompts: what an unattended run answers, frame by frame.
class PromptAnswers {
 public:
  /// Posts the answer to `status`, if any; returns false when the run should give up now.
  bool answer(const WizardStatus& status, CalibrationWizard& wizard) {
    switch (status.step) {
      case WizardStep::kCheck:
        // Nobody is there to plug the device in, home it, change a setting or decide about an
        // earlier run's checkpoint: the status of Check says what to do.
        return status.check_issue == CheckIssue::kNone;
      case WizardStep::kReview:
        if (!status.review_valid || !status.waiting_for_user) return true;
        if (!redo_posted_ && offersRedo(status.review)) {
          redo_posted_ = true;
          wizard.post(WizardEvent::kRedoFailed);
        } else {
          // Posted every frame until it is taken: the wizard ignores it in the steps after.
          wizard.post(WizardEvent::kConfirm);
        }
        return true;
      case WizardStep::kSave:
        // Stop, keeping the checkpoint, rather than retry a write that failed.
        if (!status.save_error.empty() && status.waiting_for_user) {
          wizard.post(WizardEvent::kAbort);
        }
        return true;
      default:
        return true;
    }
  }

 private:
  bool redo_posted_ = false;
};

/// CalibrateOptions::on_progress: when the step or the prompt changes, and every period between.
class ProgressCalls {
 public:
  explicit ProgressCalls(const CalibrateOptions& options) : options_(options) {}
  void update(const WizardStatus& status) {
    if (!options_.on_progress) return;
    const Clock::time_point now = Clock::now();
    const bool changed = !called_ || status.step != step_ || status.prompt != prompt_;
    if (!changed && now - last_ < wallDuration(options_.progress_period_s)) return;
    called_ = true;
    step_ = status.step;
    prompt_ = status.prompt;
    last_ = now;
    options_.on_progress(status);
  }

 private:
  const CalibrateOptions& options_;
  bool called_ = false;
  WizardStep step_ = WizardStep::kCheck;
  std::string prompt_;
  Clock::time_point last_;
};

}  // namespace

CalibrateResult calibrate(std::shared_ptr<HapticDevice> device, WizardConfig config,
                          const CalibrateOptions& options) {
  refuseOptions(options);
  // A loop paced by the wall clock keeps the wall clock's time; a faster one, simulated time.
  if (!config.clock && options.speed == 1.0) config.clock = std::make_shared<SteadyServoClock>();
  const double period_s = config.advanced.parameters.servo_period_s;
  CalibrationWizard wizard(std::move(device), std::move(config));
  CalibrateResult result;
  {
    ServoThread servo(wizard, period_s, options.speed, options.real_time_priority);
    result.servo_priority = servo.priority();
    PromptAnswers answers;
    ProgressCalls progress(options);
    while (true) {
      const Clock::time_point frame_start = Clock::now();
      if (options.stop_requested != nullptr && options.stop_requested->load()) {
        wizard.post(WizardEvent::kAbort);  // again each frame: ignored once it has stopped
      }
      wizard.service();
      // Finished first, then the status: the servo thread may end the run between the two reads,
      // and the last status a program sees must then be the end (Done, Aborted or Fault).
      const bool finished = wizard.finished();
      const WizardStatus status = wizard.status();
      if (options.on_status) options.on_status(status, wizard);
      progress.update(status);
      if (finished) break;
      if (options.answer_prompts && !answers.answer(status, wizard)) break;
      std::this_thread::sleep_until(frame_start + wallDuration(options.frame_s));
    }
    servo.stop();
  }
  // The servo thread has stopped: nothing holds the end-effector any more, so nothing is sent.
  // A device the wizard did not open stays open for its owner.
  if (wizard.step() != WizardStep::kCheck) {
    wizard.device().innerDevice().setForce(Eigen::Vector3d::Zero());
  }
  result.status = wizard.status();
  result.map = wizard.savedMap();
  return result;
}

CalibrateResult calibrate(std::shared_ptr<HapticDevice> device, const std::string& map_path,
                          const CalibrateOptions& options) {
  WizardConfig config;
  config.map_path = map_path;
  return calibrate(std::move(device), std::move(config), options);
}

std::string progressLine(const WizardStatus& status) {
  std::ostringstream line;
  if (status.step_number > 0) {
    line << "[" << status.step_number << "/" << WizardStatus::kStepCount << "] ";
  }
  line << status.title;
  const std::string first = status.message.substr(0, status.message.find('\n'));
  if (!first.empty()) line << ": " << first;
  if (!status.prompt.empty()) line << " > " << status.prompt;
  return line.str();
}

}  // namespace autograv
