// Calibrating a device of your own with autograv, as an application does it:
//   1. a servo thread ticks the wizard's servo half (CalibrationWizard::servoTick) at 1 kHz;
//   2. the main thread calls CalibrationWizard::service() every frame, shows status() as a few
//      lines of text and posts the user's events (confirm, redo failed, abort);
//   3. the map the wizard saved is loaded again and used through GravityCompensatedDevice, and
//      the program prints how well it cancels the device's own (known) gravity.
//
//   own_device [--unattended] [--out PATH]
// Without --unattended it waits for you: Enter confirms, r + Enter redoes failed vertices,
// p + Enter pauses or resumes the automatic calibration, q + Enter (or Ctrl-C) aborts; the
// example's simulated hand still carries the end-effector. With it, the program answers for you
// and runs the servo loop 50 times faster than real time.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <autograv/compensation/gravity_compensated_device.h>
#include <autograv/device/servo_clock.h>
#include <autograv/error.h>
#include <autograv/map/map_io.h>
#include <autograv/wizard/calibration_wizard.h>

#include "point_mass_device.h"

namespace {

using autograv::WizardEvent;
using autograv::WizardStep;
using Clock = std::chrono::steady_clock;

constexpr double kServoPeriod_s = 1e-3;

std::atomic<bool> g_interrupted{false};
extern "C" void onInterrupt(int) { g_interrupted.store(true); }

/// The servo thread: one CalibrationWizard::servoTick() per period, `speed` times real time.
/// It only ticks: no allocation, no lock, no I/O happens in servoTick.
class ServoThread {
 public:
  ServoThread(autograv::CalibrationWizard& wizard, double speed)
      : thread_([this, &wizard, speed] {
          const auto period = std::chrono::duration_cast<Clock::duration>(
              std::chrono::duration<double>(kServoPeriod_s / speed));
          Clock::time_point next = Clock::now();
          while (running_.load(std::memory_order_relaxed)) {
            wizard.servoTick();
            next += period;
            // Sleeping per tick below ~20 us is not possible: sleep in chunks then.
            if (next - Clock::now() > std::chrono::microseconds(200)) {
              std::this_thread::sleep_until(next);
            } else if (Clock::now() - next > std::chrono::milliseconds(50)) {
              next = Clock::now();  // late (the machine was busy): do not catch up in a burst
            }
          }
        }) {}
  ~ServoThread() { stop(); }
  void stop() {
    running_.store(false);
    if (thread_.joinable()) thread_.join();
  }

 private:
  std::atomic<bool> running_{true};
  std::thread thread_;
};

/// Lines the user types, read on their own thread so that the main loop never blocks.
class KeyboardLines {
 public:
  KeyboardLines()
      : thread_([this] {
          std::string line;
          while (std::getline(std::cin, line)) {
            const char key = line.empty() ? '\n' : line[0];
            pending_.store(key);
          }
        }) {
    thread_.detach();  // blocked in getline until the program ends
  }
  /// The latest key ('\n' for Enter), 0 if none since the last call.
  char take() { return pending_.exchange(0); }

 private:
  std::atomic<char> pending_{0};
  std::thread thread_;
};

/// The user's side of Centre and Release, played by the example's simulated hand: carry the
/// end-effector to the centre, hold it still, confirm, let go once the field is on.
class Hand {
 public:
  explicit Hand(example::PointMassDevice& device) : device_(device) {}
  /// Acts on the wizard's latest status; with `answer_for_user`, also confirms at the centre.
  void update(const autograv::WizardStatus& status, bool answer_for_user,
              autograv::CalibrationWizard& wizard) {
    switch (status.step) {
      case WizardStep::kCentre:
        if (!device_.handHolding()) {
          device_.grab();
          device_.moveHandTo(status.centre_m);
        }
        if (answer_for_user && device_.handArrived() && status.within_tolerance && !confirmed_) {
          wizard.post(WizardEvent::kConfirm);
          confirmed_ = true;
        }
        return;
      case WizardStep::kRelease:
        confirmed_ = false;
        if (device_.handHolding() &&
            status.release_status != autograv::InitializationEstimator::Status::kRampingIn) {
          device_.release();
        }
        return;
      default:
        if (device_.handHolding()) device_.release();
        return;
    }
  }

 private:
  example::PointMassDevice& device_;
  bool confirmed_ = false;
};

/// A few lines of text: the step when it changes, the prompt, and the calibration's progress.
class TextUi {
 public:
  void show(const autograv::WizardStatus& status) {
    if (status.step != step_ || status.prompt != prompt_ || !started_) {
      started_ = true;
      step_ = status.step;
      prompt_ = status.prompt;
      const std::string first_line = status.message.substr(0, status.message.find('\n'));
      std::printf("[%d/%d] %s: %s\n", status.step_number, autograv::WizardStatus::kStepCount,
                  status.title.c_str(), first_line.c_str());
      if (!status.prompt.empty()) std::printf("      > %s\n", status.prompt.c_str());
      std::fflush(stdout);
    }
    if (status.step == WizardStep::kAutoCalibration) {
      const auto now = Clock::now();
      if (now - last_progress_ > std::chrono::seconds(1)) {
        last_progress_ = now;
        std::printf("      vertex %d of %d, %d converged\n", status.vertex_ordinal,
                    status.vertices_to_visit, status.converged);
        std::fflush(stdout);
      }
    }
  }

 private:
  bool started_ = false;
  WizardStep step_ = WizardStep::kCheck;
  std::string prompt_;
  Clock::time_point last_progress_ = Clock::now();
};

struct Options {
  bool unattended = false;
  std::string map_path;
};

/// Steps 1 and 2: the wizard, from Check to Done. Returns the step it ended in.
WizardStep calibrate(const std::shared_ptr<example::PointMassDevice>& device,
                     const Options& options) {
  autograv::WizardConfig config;  // the library's defaults, but for a small, quick grid:
  config.centre_m = Eigen::Vector3d::Zero();
  config.advanced.box_size_m = Eigen::Vector3d::Constant(0.04);  // 40 mm cube
  config.grid_resolution = Eigen::Vector3i::Constant(3);         // 3 x 3 x 3 vertices
  // That box, not one fitted to the workspace the wizard explores first; it is still measured
  // only inside what the exploration reached.
  // config.advanced.parameters: the defaults, the dither method that calibrates through friction.
  config.advanced.parameters.servo_period_s = kServoPeriod_s;
  config.map_path = options.map_path;
  autograv::CalibrationWizard wizard(device, config);  // throws autograv::Error for bad settings

  ServoThread servo(wizard, options.unattended ? 50.0 : 1.0);
  // Never freed: its thread blocks in getline until the program ends.
  KeyboardLines* keyboard = options.unattended ? nullptr : new KeyboardLines;
  Hand hand(*device);
  TextUi ui;
  bool redo_offered = false;
  while (true) {
    const auto frame_start = Clock::now();
    wizard.service();  // the non-real-time half: checks, files, review, map publication
    const autograv::WizardStatus status = wizard.status();
    ui.show(status);
    if (wizard.finished()) break;

    if (g_interrupted.exchange(false)) wizard.post(WizardEvent::kAbort);
    hand.update(status, options.unattended, wizard);
    if (keyboard != nullptr) {
      switch (keyboard->take()) {
        case '\n':
          wizard.post(WizardEvent::kConfirm);
          break;
        case 'r':
          wizard.post(WizardEvent::kRedoFailed);
          break;
        case 'q':
          wizard.post(WizardEvent::kAbort);
          break;
        case 'p':
          wizard.post(status.paused ? WizardEvent::kResume : WizardEvent::kPause);
          break;
        default:
          break;
      }
    } else if (status.step == WizardStep::kReview && status.review_valid) {
      // Redo the failed vertices once, then save what there is.
      const bool failed = !status.review.failed.empty();
      wizard.post(failed && !redo_offered ? WizardEvent::kRedoFailed : WizardEvent::kConfirm);
      redo_offered = redo_offered || failed;
    } else if (status.step == WizardStep::kCheck &&
               status.check_issue == autograv::CheckIssue::kEarlierCheckpoint) {
      wizard.post(WizardEvent::kConfirm);  // start afresh
    }
    std::this_thread::sleep_until(frame_start + std::chrono::milliseconds(20));
  }
  servo.stop();
  const autograv::WizardStatus status = wizard.status();
  if (!status.fault.empty()) std::printf("%s\n", status.fault.c_str());
  if (status.review_valid) {
    std::printf("calibrated %d of %d vertices in %.1f s of servo time\n", status.review.converged,
                status.review.vertex_count, status.review.estimation_seconds);
  }
  return status.step;
}

/// Step 3: the saved map, loaded as an application loads it, compensating the device.
int useTheMap(const std::shared_ptr<example::PointMassDevice>& device, const Options& options) {
  autograv::MapLoadOptions load;
  load.expected_device_model = device->specifications().model_name;
  const auto map =
      std::make_shared<const autograv::GravityMap>(autograv::loadMap(options.map_path, load));

  // This loop runs in simulated time (each setForce advances the device by 1 ms, much faster
  // than the wall clock): it must give the decorator a clock that says so.
  autograv::CompensationOptions compensation;
  compensation.clock = std::make_shared<autograv::FixedPeriodServoClock>(kServoPeriod_s);
  autograv::GravityCompensatedDevice compensated(device, compensation);
  if (!compensated.open()) return 1;
  compensated.publishMap(map);

  // Residual of the map against the device's own gravity, at points all over the grid.
  std::vector<double> residuals_n;
  const int n = 9;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d p =
            0.02 * Eigen::Vector3d(2.0 * i / (n - 1) - 1.0, 2.0 * j / (n - 1) - 1.0,
                                   2.0 * k / (n - 1) - 1.0);
        residuals_n.push_back(
            (map->gravityAt(p) + example::PointMassDevice::gravityForce_n(p)).norm());
      }
    }
  }
  std::sort(residuals_n.begin(), residuals_n.end());
  const double median_n = residuals_n[residuals_n.size() / 2];
  const double max_n = residuals_n.back();

  // Release tests: the hand lets go at a point; the application sends no force of its own.
  const std::vector<Eigen::Vector3d> points = {
      {0.0, 0.0, 0.0}, {0.015, -0.01, 0.01}, {-0.015, 0.015, -0.015}, {0.01, 0.015, 0.015}};
  std::printf("release tests (0.5 s, application force zero):\n");
  double worst_drift_m = 0.0;
  for (const Eigen::Vector3d& point : points) {
    double drift_m[2] = {0.0, 0.0};
    for (const bool enabled : {true, false}) {
      compensated.setCompensationEnabled(enabled);
      device->placeAt(point);
      for (int t = 0; t < 600; ++t) {  // let the compensation fade fully in (or out)
        device->placeAt(point);
        compensated.setForce(Eigen::Vector3d::Zero());
      }
      for (int t = 0; t < 500; ++t) compensated.setForce(Eigen::Vector3d::Zero());
      Eigen::Vector3d end_m;
      compensated.getPosition(end_m);
      drift_m[enabled ? 0 : 1] = (end_m - point).norm();
    }
    worst_drift_m = std::max(worst_drift_m, drift_m[0]);
    std::printf("  at (%+5.1f, %+5.1f, %+5.1f) mm: drift %5.2f mm compensated, %5.1f mm without\n",
                point.x() * 1e3, point.y() * 1e3, point.z() * 1e3, drift_m[0] * 1e3,
                drift_m[1] * 1e3);
  }
  std::printf(
      "residual of the map against the device's gravity (|G| about %.2f N) at %zu points of the "
      "grid: median %.1f mN, max %.1f mN\n",
      example::PointMassDevice::gravityForce_n(Eigen::Vector3d::Zero()).norm(), residuals_n.size(),
      median_n * 1e3, max_n * 1e3);
  std::printf("worst drift compensated: %.2f mm; faults %llu; fade stalled: %s\n",
              worst_drift_m * 1e3, static_cast<unsigned long long>(compensated.faultCount()),
              compensated.fadeStalled() ? "yes" : "no");
  compensated.close();
  // The figures a user would feel: far below the 30 mN friction, the end-effector stays put.
  return max_n < 0.03 && worst_drift_m < 1e-3 && !compensated.fadeStalled() ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  options.map_path =
      (std::filesystem::temp_directory_path() / "autograv_own_device_map.json").string();
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--unattended") == 0) {
      options.unattended = true;
    } else if (std::strcmp(argv[i], "--out") == 0 && i + 1 < argc) {
      options.map_path = argv[++i];
    } else {
      std::fprintf(stderr, "usage: %s [--unattended] [--out PATH]\n", argv[0]);
      return 2;
    }
  }
  std::signal(SIGINT, onInterrupt);
  std::error_code ignored;
  std::filesystem::remove(options.map_path + ".partial", ignored);  // each run starts afresh

  const auto device = std::make_shared<example::PointMassDevice>(kServoPeriod_s);
  try {
    const WizardStep end = calibrate(device, options);
    if (end != WizardStep::kDone) {
      std::printf("the wizard ended in step '%s', no map to use\n", autograv::toString(end));
      return 1;
    }
    std::printf("map saved to %s\n", options.map_path.c_str());
    return useTheMap(device, options);
  } catch (const autograv::Error& error) {
    // The library's messages name its parameters (WizardConfig::..., EstimationParameters::...).
    std::fprintf(stderr, "own_device: %s\n", error.what());
    return 1;
  }
}
