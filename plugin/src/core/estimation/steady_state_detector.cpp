#include "core/estimation/steady_state_detector.h"

#include <algorithm>
#include <cmath>

#include "autograv/device/servo_sample.h"
#include "autograv/error.h"

namespace autograv {

namespace {

double periodsOf(double interval_s, double period_s) noexcept {
  if (!(interval_s > 0.0) || !(interval_s < 1e300)) return 1.0;
  return interval_s / period_s;
}
}  // namespace

SteadyStateDetector::SteadyStateDetector(int required_samples, double speed_threshold_m_per_s,
                                         double min_duration_s, double period_s)
    : required_(required_samples),
      speed_threshold_m_per_s_(speed_threshold_m_per_s),
      min_periods_(static_cast<double>(std::lround(min_duration_s / period_s))),
      period_s_(period_s) {
  if (required_samples < 1)
    throw Error("steady-state detector: n_S (EstimationParameters::n_s) must be at least 1");
  if (!(speed_threshold_m_per_s > 0.0)) {
    throw Error(
        "steady-state detector: eps_S (EstimationParameters::eps_s_m_per_s) must be a "
        "positive speed in m/s");
  }
  if (!(period_s > 0.0) || !(min_duration_s >= 0.0)) {
    throw Error(
        "steady-state detector: EstimationParameters::servo_period_s must be positive, "
        "EstimationParameters::min_step_duration_s >= 0");
  }
}

SteadyStateDetector SteadyStateDetector::windowMeans(int window_ticks, int required_windows,
                                                     double speed_threshold_m_per_s,
                                                     double min_duration_s, double period_s) {
  if (window_ticks < 2) {
    throw Error("steady-state detector: an averaging window needs at least 2 servo periods");
  }
  SteadyStateDetector detector(required_windows, speed_threshold_m_per_s, min_duration_s, period_s);
  detector.window_periods_ = static_cast<double>(window_ticks);
  return detector;
}

SteadyStateDetector SteadyStateDetector::forParameters(const EstimationParameters& p) {
  if (p.method == EstimationMethod::kPaper) {
    return SteadyStateDetector(p.n_s, p.eps_s_m_per_s, p.min_step_duration_s, p.servo_period_s);
  }
  if (!(p.dither_frequency_hz > 0.0) || !(p.servo_period_s > 0.0) ||
      p.dither_periods_per_window < 1) {
    throw Error(
        "steady-state detector: the dither needs a positive "
        "EstimationParameters::dither_frequency_hz, a positive "
        "EstimationParameters::servo_period_s and EstimationParameters::dither_periods_per_window "
        ">= 1");
  }
  if (p.steady_windows < 1) {  // the window rule's n_S: say so in its own name
    throw Error("steady-state detector: EstimationParameters::steady_windows must be at least 1");
  }
  const double ticks_per_period = 1.0 / (p.dither_frequency_hz * p.servo_period_s);
  if (ticks_per_period < 4.0) {
    throw Error("steady-state detector: dither frequency " + std::to_string(p.dither_frequency_hz) +
                " Hz (EstimationParameters::dither_frequency_hz) is too high for the servo period: "
                "at most " +
                std::to_string(0.25 / p.servo_period_s) + " Hz (4 samples per period)");
  }
  // Whole dither periods in time; a length that is a whole number of servo periods but for
  // rounding is exactly that, so that an exact loop closes its windows on ticks.
  double window_periods = ticks_per_period * p.dither_periods_per_window;
  const double nearest = std::round(window_periods);
  if (std::abs(window_periods - nearest) < 1e-9 * nearest) window_periods = nearest;
  SteadyStateDetector detector =
      windowMeans(static_cast<int>(std::lround(window_periods)), p.steady_windows, p.eps_s_m_per_s,
                  p.min_step_duration_s, p.servo_period_s);
  detector.window_periods_ = window_periods;
  return detector;
}

int SteadyStateDetector::windowTicks() const noexcept {
  return static_cast<int>(std::lround(window_periods_));
}

void SteadyStateDetector::reset() noexcept {
  elapsed_periods_ = 0.0;
  settled_ = false;
  breakRun();
  window_sum_m_.setZero();
  window_fill_periods_ = 0.0;
  window_spoilt_ = false;
  spoilt_windows_ = 0;
  window_interval_sum_ = 0.0;
  window_interval_squares_ = 0.0;
  window_samples_ = 0;
  has_previous_mean_ = false;
}

void SteadyStateDetector::breakRun() noexcept {
  consecutive_ = 0;
  run_periods_ = 0.0;
  run_sum_m_.setZero();
  run_weight_ = 0.0;
}

void SteadyStateDetector::closeWindow() noexcept {
  const Eigen::Vector3d mean_m = window_sum_m_ / window_periods_;
  window_sum_m_.setZero();
  window_fill_periods_ = 0.0;
  if (window_spoilt_) {
    window_interval_sum_ = 0.0;
    window_interval_squares_ = 0.0;
    window_samples_ = 0;
    // The loop stalled in this window: its mean is not that of a symmetric dither, and the next
    // window has nothing trustworthy to agree with.
    window_spoilt_ = false;
    ++spoilt_windows_;
    breakRun();
    has_previous_mean_ = false;
    return;
  }
  const double window_s = window_periods_ * period_s_;
  // An irregular loop makes window means scatter (its ticks hold each force for a random time):
  // the tolerance widens with the spread of the intervals, relative to the nominal period (0 for
  // an exact loop, which keeps the tolerance as it is).
  double spread = 0.0;
  if (window_samples_ > 0) {
    const double mean = window_interval_sum_ / window_samples_;
    spread = std::sqrt(std::max(0.0, window_interval_squares_ / window_samples_ - mean * mean));
  }
  window_interval_sum_ = 0.0;
  window_interval_squares_ = 0.0;
  window_samples_ = 0;
  const double tolerance_m = std::max(speed_threshold_m_per_s_ * window_s, window_tolerance_m_) *
                             (1.0 + kToleranceGrowthPerSpread * spread);
  const bool agrees = has_previous_mean_ && (mean_m - previous_mean_m_).norm() <= tolerance_m;
  if (agrees) {
    // The run holds the windows that agreed with their predecessor, not the first of a pair:
    // that one still carries the transient of the last update.
    run_sum_m_ += mean_m;
    run_weight_ += 1.0;
    ++consecutive_;
  } else {
    breakRun();
  }
  previous_mean_m_ = mean_m;
  has_previous_mean_ = true;
}

bool SteadyStateDetector::update(const Eigen::Vector3d& position_m,
                                 const Eigen::Vector3d& velocity_m_per_s,
                                 double interval_s) noexcept {
  if (settled_) return true;
  // The sample stands for the interval that ends with it (exactly one period in an exact loop).
  const double periods = periodsOf(interval_s, period_s_);
  elapsed_periods_ += periods;
  if (window_periods_ == 0.0) {
    if (periods > kMaxGapPeriods) breakRun();  // nobody watched the end-effector meanwhile
    if (velocity_m_per_s.allFinite() && velocity_m_per_s.norm() <= speed_threshold_m_per_s_) {
      ++consecutive_;
      run_periods_ += periods;
      run_sum_m_ += periods * position_m;
      run_weight_ += periods;
    } else {
      breakRun();
    }
    settled_ = run_periods_ >= required_ - kServoTimeSlackPeriods &&
               elapsed_periods_ >= min_periods_ - kServoTimeSlackPeriods;
    return settled_;
  }
  const bool gap = periods > kMaxGapOfWindow * window_periods_;
  window_interval_sum_ += periods;
  window_interval_squares_ += periods * periods;
  ++window_samples_;
  double remaining = periods;
  bool closed = false;
  // Split the sample's interval at each window end it straddles.
  while (window_fill_periods_ + remaining >= window_periods_ - kServoTimeSlackPeriods) {
    const double part = std::max(0.0, window_periods_ - window_fill_periods_);
    window_sum_m_ += part * position_m;
    window_spoilt_ = window_spoilt_ || gap;
    remaining -= part;
    closeWindow();
    closed = true;
  }
  if (remaining > kServoTimeSlackPeriods) {
    window_sum_m_ += remaining * position_m;
    window_fill_periods_ += remaining;
    window_spoilt_ = window_spoilt_ || gap;
  }
  // Judged when a window ends: the estimate is read over whole windows only.
  if (closed) {
    settled_ =
        consecutive_ >= required_ && elapsed_periods_ >= min_periods_ - kServoTimeSlackPeriods;
  }
  return settled_;
}

Eigen::Vector3d SteadyStateDetector::settledPosition_m() const noexcept {
  if (!(run_weight_ > 0.0)) return Eigen::Vector3d::Constant(NAN);
  return run_sum_m_ / run_weight_;
}

double SteadyStateDetector::progress() const noexcept {
  if (window_periods_ == 0.0) return std::min(1.0, run_periods_ / required_);
  return std::min(1.0, static_cast<double>(consecutive_) / required_);
}

}  // namespace autograv
