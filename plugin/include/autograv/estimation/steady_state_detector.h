#pragma once

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
class SteadyStateDetector {
 public:
  /// Slow-samples rule: `required_samples` = n_S >= 1, `speed_threshold_m_per_s` = eps_S [m/s],
  /// `min_duration_s` lower bound [s], `period_s` servo period [s]. Throws autograv::Error.
  SteadyStateDetector(int required_samples, double speed_threshold_m_per_s, double min_duration_s,
                      double period_s);

  /// Window-means rule over windows of `window_ticks` servo periods. Throws autograv::Error.
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
  /// Feeds one servo sample; returns true once the steady state is reached (and stays true for
  /// further calls until reset). Real-time safe.
  bool update(const Eigen::Vector3d& position_m, const Eigen::Vector3d& velocity_m_per_s) noexcept;

  /// True once the steady state is reached (until reset()). Real-time safe.
  bool settled() const noexcept { return settled_; }
  /// Mean position over the settled run (samples, or windows). Unit: [m]
  Eigen::Vector3d settledPosition_m() const noexcept;
  /// Time since reset. Unit: [s]
  double elapsed_s() const noexcept { return elapsed_ticks_ * period_s_; }
  /// Progress toward the steady state: consecutive slow samples (slow-samples rule) or
  /// consecutive agreeing windows (window-means rule).
  int consecutiveSlowSamples() const noexcept { return consecutive_; }
  /// Progress toward the steady state in [0, 1], for progress displays.
  double progress() const noexcept;
  /// Window length of the window-means rule in servo ticks; 0 for the slow-samples rule.
  int windowTicks() const noexcept { return window_ticks_; }

 private:
  int required_;
  double speed_threshold_m_per_s_;
  long min_ticks_;
  double period_s_;
  int window_ticks_ = 0;  // 0: slow-samples rule
  double window_tolerance_m_ = 0.0;
  long elapsed_ticks_ = 0;
  int consecutive_ = 0;
  bool settled_ = false;
  // Sum over the current run of slow samples, or of agreeing window means.
  Eigen::Vector3d run_sum_m_ = Eigen::Vector3d::Zero();
  int run_count_ = 0;
  // Window-means rule: the window being filled and the mean of the previous one.
  Eigen::Vector3d window_sum_m_ = Eigen::Vector3d::Zero();
  int window_fill_ = 0;
  Eigen::Vector3d previous_mean_m_ = Eigen::Vector3d::Zero();
  bool has_previous_mean_ = false;
};

}  // namespace autograv
