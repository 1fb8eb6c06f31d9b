#pragma once

// Private to core: the steady-state rules of the VertexEstimator and the
// InitializationEstimator.

#include <Eigen/Core>

#include "autograv/estimation/estimation_parameters.h"

namespace autograv {

/// When one iteration (or the initialization) has reached its steady state, by one of two rules:
///
/// - slow samples (paper Section III): n_S consecutive velocity samples with ||Xd|| <= eps_S, and
///   (Section V) not before a minimum duration. X_inf is the mean position of that run, which
///   removes most encoder noise.
/// - window means (the dither method): the positions are averaged over windows of whole dither
///   periods; the steady state is `required_windows` consecutive windows whose mean moved by at
///   most eps_S times the window duration (the mean position moves slower than eps_S), or by at
///   most a tolerance the caller sets from what the position is used for (setWindowTolerance_m).
///   X_inf is the mean over that run of windows. A dithered, limit-cycling or noisy end-effector
///   never has n_S slow velocity samples, but its mean position settles.
///
/// Every duration is servo time, not a count of ticks: each sample carries the interval since the
/// previous one (ServoSample::interval_s), a run of slow samples must last n_S nominal periods,
/// a window spans whole dither periods in seconds (a sample whose interval straddles a window's
/// end is split between the two windows), and window means are time-weighted. A gap longer than
/// kMaxGapOfWindow of a window (a stalled loop: the force was held that long, so the dither was
/// not symmetric) spoils the windows it falls in: they neither count nor start a new pair. With
/// intervals of exactly one nominal period the arithmetic is that of counting ticks.
class SteadyStateDetector {
 public:
  /// Slow-samples rule: `required_samples` = n_S >= 1, `speed_threshold_m_per_s` = eps_S [m/s],
  /// `min_duration_s` lower bound [s], `period_s` nominal servo period [s]. Throws
  /// autograv::Error.
  SteadyStateDetector(int required_samples, double speed_threshold_m_per_s, double min_duration_s,
                      double period_s);

  /// Window-means rule over windows of `window_ticks` nominal servo periods. Throws
  /// autograv::Error.
  static SteadyStateDetector windowMeans(int window_ticks, int required_windows,
                                         double speed_threshold_m_per_s, double min_duration_s,
                                         double period_s);

  /// The rule that `parameters.method` calls for (window = whole dither periods for kDither).
  /// Throws autograv::Error on bad parameters. Not real-time safe.
  static SteadyStateDetector forParameters(const EstimationParameters& parameters);

  /// Starts a new observation (time 0, no samples). Real-time safe.
  void reset() noexcept;
  /// Window-means rule: window means that moved by at most `tolerance_m` also agree, whatever
  /// eps_S allows (e.g. the displacement that would change eq. 12's update by a fraction of
  /// eps_G). Kept across reset(). Real-time safe. Unit: [m]
  void setWindowTolerance_m(double tolerance_m) noexcept { window_tolerance_m_ = tolerance_m; }
  /// Consecutive agreeing samples or windows that make a steady state from now on (>= 1; smaller
  /// values are taken as 1). Kept across reset(). Real-time safe.
  void setRequired(int required) noexcept { required_ = required < 1 ? 1 : required; }
  /// Feeds one servo sample taken `interval_s` after the previous one (<= 0 or NaN: one nominal
  /// period); returns true once the steady state is reached (and stays true for further calls
  /// until reset). Real-time safe.
  bool update(const Eigen::Vector3d& position_m, const Eigen::Vector3d& velocity_m_per_s,
              double interval_s = 0.0) noexcept;

  /// True once the steady state is reached (until reset()). Real-time safe.
  bool settled() const noexcept { return settled_; }
  /// Mean position over the settled run (samples, or windows). Unit: [m]
  Eigen::Vector3d settledPosition_m() const noexcept;
  /// Servo time since reset. Unit: [s]
  double elapsed_s() const noexcept { return elapsed_periods_ * period_s_; }
  /// Progress toward the steady state: consecutive slow samples (slow-samples rule) or
  /// consecutive agreeing windows (window-means rule).
  int consecutiveSlowSamples() const noexcept { return consecutive_; }
  /// Progress toward the steady state in [0, 1], for progress displays.
  double progress() const noexcept;
  /// Window length of the window-means rule in nominal servo periods, rounded; 0 for the
  /// slow-samples rule.
  int windowTicks() const noexcept;
  /// Window length of the window-means rule; 0 for the slow-samples rule. Unit: [s]
  double window_s() const noexcept { return window_periods_ * period_s_; }
  /// Windows spoilt by a gap since reset (window-means rule).
  int spoiltWindows() const noexcept { return spoilt_windows_; }

  /// A gap longer than this fraction of the window spoils the windows it touches; the 3-5 ms late
  /// ticks of a desktop loop (a tenth of a 50 ms window) do not, a 20 ms stall does.
  static constexpr double kMaxGapOfWindow = 0.2;
  /// Window-means rule: the agreement tolerance grows by this factor per unit of spread of the
  /// window's servo intervals (their standard deviation in nominal periods): a desktop loop, late
  /// by 0-1 ms, has a spread of about 0.4 and makes window means scatter beyond the exact loop's
  /// tolerance. Wider (10 did) lets a steep-field vertex take a steady state while it still
  /// creeps, and eq. (12) then swings around its fixed point for dozens of iterations; none (0)
  /// doubles a desktop calibration's time (README, "Servo timing"). Accuracy stays with eq. 12's
  /// n_G small updates.
  static constexpr double kToleranceGrowthPerSpread = 3.0;
  /// Slow-samples rule: a gap longer than this many nominal periods breaks the run.
  static constexpr double kMaxGapPeriods = 10.0;

 private:
  void closeWindow() noexcept;
  void breakRun() noexcept;

  int required_;
  double speed_threshold_m_per_s_;
  double min_periods_;
  double period_s_;
  double window_periods_ = 0.0;  // 0: slow-samples rule
  double window_tolerance_m_ = 0.0;
  double elapsed_periods_ = 0.0;
  int consecutive_ = 0;
  bool settled_ = false;
  // Slow-samples rule: how long the current run of slow samples lasts, in nominal periods.
  double run_periods_ = 0.0;
  // Time-weighted sum over the current run of slow samples, or plain sum of agreeing window means.
  Eigen::Vector3d run_sum_m_ = Eigen::Vector3d::Zero();
  double run_weight_ = 0.0;
  // Window-means rule: the window being filled (time-weighted sum, time so far) and the mean of
  // the previous one.
  Eigen::Vector3d window_sum_m_ = Eigen::Vector3d::Zero();
  double window_fill_periods_ = 0.0;
  bool window_spoilt_ = false;
  double window_interval_sum_ = 0.0;      // the window's servo intervals, in nominal periods
  double window_interval_squares_ = 0.0;  // and their squares
  int window_samples_ = 0;
  int spoilt_windows_ = 0;
  Eigen::Vector3d previous_mean_m_ = Eigen::Vector3d::Zero();
  bool has_previous_mean_ = false;
};

}  // namespace autograv
