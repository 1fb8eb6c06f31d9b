#pragma once

#include <cstdint>
#include <memory>
#include <utility>

#include "autograv/device/servo_clock.h"

namespace autograv {

/// Measures how long each servo tick lasts on the decorator's clock, read once per tick.
/// Internal to core; the servo thread's only. Real-time safe when the clock is.
class ServoTickTimer {
 public:
  /// `max_interval_s`: the longest a tick counts for. Unit: [s]
  ServoTickTimer(std::shared_ptr<ServoClock> clock, double max_interval_s) noexcept
      : clock_(std::move(clock)), max_interval_s_(max_interval_s) {}

  /// Reads the clock: the time since the previous tick, clamped to [0, max_interval_s]. The
  /// first tick has nothing to measure from and counts for 0, as does a clock going backwards
  /// (or NaN). Unit: [s]
  double tick() noexcept;
  /// The clock reading of the latest tick(). Unit: [s]
  double now_s() const noexcept { return last_time_s_; }
  /// The next tick counts for nothing (after open or close).
  void restart() noexcept { has_last_time_ = false; }

 private:
  std::shared_ptr<ServoClock> clock_;
  double max_interval_s_;
  double last_time_s_ = 0.0;
  bool has_last_time_ = false;
};

/// Watches a fade in progress for a clock that does not advance: the rule behind
/// GravityCompensatedDevice::fadeStalled. Internal to core; the servo thread's only.
/// Real-time safe.
class FadeStallWatch {
 public:
  /// One tick: `fading` whether a fade is in progress, `tick` the tick's number and `now_s` its
  /// clock reading. Returns true when `stall_ticks` ticks of a fade passed within less than
  /// `stall_span_s` of the clock. Once the caller has recorded a stall it passes
  /// `fading` = false. Unit: [s]
  bool stalled(bool fading, std::uint64_t tick, double now_s, int stall_ticks,
               double stall_span_s) noexcept {
    if (!fading) {
      watching_ = false;
      return false;
    }
    if (!watching_ || !(now_s - start_s_ < stall_span_s)) {
      // A new span begins whenever the clock has moved on by the span: a real loop never
      // gathers stall_ticks in one.
      watching_ = true;
      start_tick_ = tick;
      start_s_ = now_s;
      return false;
    }
    return tick - start_tick_ >= static_cast<std::uint64_t>(stall_ticks);
  }
  /// Starts afresh on the next fade (after open or close).
  void reset() noexcept { watching_ = false; }

 private:
  bool watching_ = false;
  std::uint64_t start_tick_ = 0;  ///< The tick the watched span began at.
  double start_s_ = 0.0;          ///< The clock reading it began at. Unit: [s]
};

}  // namespace autograv
