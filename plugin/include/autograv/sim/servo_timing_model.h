#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "autograv/device/servo_clock.h"

namespace autograv::sim {

/// How a simulated servo loop's ticks arrive (README, "Servo timing"):
enum class ServoTiming : std::uint8_t {
  /// Exactly every nominal period (1 kHz): the published figures.
  kExact,
  /// A desktop Linux thread paced at 1 kHz on absolute deadlines: each tick late by 0-1 ms
  /// (uniform), 1 % of them by 3-5 ms, and every 10-30 s a 20 ms stall; late ticks are followed by
  /// the catch-up ticks of the deadlines they missed, back to back.
  kDesktop,
  /// The same thread at real-time priority (SCHED_FIFO, as the tools ask for on hardware:
  /// enterRealTimePriority): each tick late by 0-0.2 ms, 0.1 % of them by 3-5 ms, the same
  /// stalls. A 1 kHz SCHED_FIFO loop on a machine busy building on both cores measured p50
  /// 0.04 ms, p99 0.2 ms, longest 1.2 ms late (README, "Servo timing").
  kRealTime,
  /// A free-running loop (a CHAI3D haptic thread): its rate wanders over 2-8 kHz, each interval
  /// a further +-15 % about it.
  kFree,
};

/// "exact", "desktop", "realtime", "free".
const char* toString(ServoTiming timing) noexcept;
/// Inverse of toString; throws autograv::Error listing the valid names.
ServoTiming parseServoTiming(const std::string& name);
std::vector<std::string> servoTimingNames();

/// The tick times of a servo loop of a given ServoTiming, drawn from a seed: the same seed gives
/// the same ticks, bit for bit. Time starts at 0 at construction. A simulated loop advances its
/// device by nextInterval_s() before each tick and hands the interval to the estimators
/// (ServoSample::interval_s).
class ServoTimingModel {
 public:
  /// Throws autograv::Error for a nominal period outside (0, 0.1] s. Not real-time safe.
  /// Unit: [s]
  explicit ServoTimingModel(ServoTiming timing = ServoTiming::kExact, std::uint64_t seed = 1,
                            double nominal_period_s = 1e-3);

  /// Draws the next tick and returns its interval after the previous one (exactly the nominal
  /// period for kExact). Real-time safe. Unit: [s]
  double nextInterval_s() noexcept;
  /// Interval that ended the latest tick; the nominal period before the first. Unit: [s]
  double lastInterval_s() const noexcept { return last_interval_s_; }
  /// How late the latest tick was: after its deadline (kDesktop, kRealTime), after the loop's
  /// current nominal period (kFree), 0 for kExact. Unit: [s]
  double lastLateness_s() const noexcept { return last_lateness_s_; }
  /// Time of the latest tick since construction. Unit: [s]
  double now_s() const noexcept { return now_s_; }
  /// The model's kind of loop.
  ServoTiming timing() const noexcept { return timing_; }
  /// The loop's nominal period. Unit: [s]
  double nominalPeriod_s() const noexcept { return nominal_period_s_; }

  /// Desktop and real-time: the stall, its spacing, the rare late ticks, every tick's lateness.
  /// Units: [s], fraction
  static constexpr double kStall_s = 0.020;
  static constexpr double kStallSpacingMin_s = 10.0;          ///< Unit: [s]
  static constexpr double kStallSpacingMax_s = 30.0;          ///< Unit: [s]
  static constexpr double kRareLateFraction = 0.01;           ///< Of the ticks, 3-5 ms late.
  static constexpr double kLateness_s = 1e-3;                 ///< Every tick: 0 to this. Unit: [s]
  static constexpr double kRealTimeRareLateFraction = 0.001;  ///< kRealTime: 3-5 ms late.
  static constexpr double kRealTimeLateness_s = 0.2e-3;       ///< kRealTime's kLateness_s.
  /// Shortest interval: even a catch-up tick takes this long. Unit: [s]
  static constexpr double kMinInterval_s = 20e-6;
  /// Free-running band. Unit: [Hz]
  static constexpr double kFreeMinRate_hz = 2000.0;
  static constexpr double kFreeMaxRate_hz = 8000.0;  ///< Unit: [Hz]

 private:
  double uniform() noexcept;  // [0, 1)

  ServoTiming timing_;
  double nominal_period_s_;
  std::mt19937_64 random_;
  double now_s_ = 0.0;
  double last_interval_s_;
  double last_lateness_s_ = 0.0;
  long long ticks_ = 0;
  double next_stall_s_ = 0.0;
  double log_rate_ = 0.0;  // free-running: ln(rate / 1 Hz)
};

/// A ServoClock that reads a ServoTimingModel's time: reading does not advance it, so the
/// decorator and the loop around it can share it. Real-time safe.
class ServoTimingClock final : public ServoClock {
 public:
  /// Reads `model`, which must outlive the clock.
  explicit ServoTimingClock(const ServoTimingModel& model) noexcept : model_(model) {}
  double now_s() noexcept override { return model_.now_s(); }

 private:
  const ServoTimingModel& model_;
};

}  // namespace autograv::sim
