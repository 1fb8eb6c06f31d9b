#include "autograv/estimation/steady_state_detector.h"

#include <algorithm>
#include <cmath>

#include "autograv/error.h"

namespace autograv {

SteadyStateDetector::SteadyStateDetector(int required_samples, double speed_threshold_m_per_s,
                                         double min_duration_s, double period_s)
    : required_(required_samples),
      speed_threshold_m_per_s_(speed_threshold_m_per_s),
      min_ticks_(std::lround(min_duration_s / period_s)),
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
  detector.window_ticks_ = window_ticks;
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
  const int window_ticks =
      static_cast<int>(std::lround(ticks_per_period * p.dither_periods_per_window));
  return windowMeans(window_ticks, p.steady_windows, p.eps_s_m_per_s, p.min_step_duration_s,
                     p.servo_period_s);
}

void SteadyStateDetector::reset() noexcept {
  elapsed_ticks_ = 0;
  consecutive_ = 0;
  settled_ = false;
  run_sum_m_.setZero();
  run_count_ = 0;
  window_sum_m_.setZero();
  window_fill_ = 0;
  has_previous_mean_ = false;
}

bool SteadyStateDetector::update(const Eigen::Vector3d& position_m,
                                 const Eigen::Vector3d& velocity_m_per_s) noexcept {
  if (settled_) return true;
  ++elapsed_ticks_;
  if (window_ticks_ == 0) {
    if (velocity_m_per_s.allFinite() && velocity_m_per_s.norm() <= speed_threshold_m_per_s_) {
      ++consecutive_;
      run_sum_m_ += position_m;
      ++run_count_;
    } else {
      consecutive_ = 0;
      run_sum_m_.setZero();
      run_count_ = 0;
    }
  } else {
    window_sum_m_ += position_m;
    if (++window_fill_ < window_ticks_) return false;
    const Eigen::Vector3d mean_m = window_sum_m_ / window_ticks_;
    window_sum_m_.setZero();
    window_fill_ = 0;
    const double window_s = window_ticks_ * period_s_;
    const double tolerance_m = std::max(speed_threshold_m_per_s_ * window_s, window_tolerance_m_);
    const bool agrees = has_previous_mean_ && (mean_m - previous_mean_m_).norm() <= tolerance_m;
    if (agrees) {
      // The run holds the windows that agreed with their predecessor, not the first of a pair:
      // that one still carries the transient of the last update.
      run_sum_m_ += mean_m;
      ++run_count_;
      ++consecutive_;
    } else {
      consecutive_ = 0;
      run_sum_m_.setZero();
      run_count_ = 0;
    }
    previous_mean_m_ = mean_m;
    has_previous_mean_ = true;
  }
  settled_ = consecutive_ >= required_ && elapsed_ticks_ >= min_ticks_;
  return settled_;
}

Eigen::Vector3d SteadyStateDetector::settledPosition_m() const noexcept {
  if (run_count_ == 0) return Eigen::Vector3d::Constant(NAN);
  return run_sum_m_ / run_count_;
}

double SteadyStateDetector::progress() const noexcept {
  return std::min(1.0, static_cast<double>(consecutive_) / required_);
}

}  // namespace autograv
