#pragma once

#include <Eigen/Core>

namespace autograv {

/// Paper Section III: the steady state is reached when n_S consecutive velocity samples satisfy
/// ||Xd|| <= eps_S, and (Section V) not before a minimum duration. While settled it also averages
/// the positions of the settled window, which removes most encoder noise from X_inf.
class SteadyStateDetector {
 public:
  /// `required_samples` = n_S >= 1, `speed_threshold_m_per_s` = eps_S [m/s],
  /// `min_duration_s` lower bound [s], `period_s` servo period [s]. Throws autograv::Error.
  SteadyStateDetector(int required_samples, double speed_threshold_m_per_s, double min_duration_s,
                      double period_s);

  /// Starts a new observation (time 0, no samples). Real-time safe.
  void reset() noexcept;
  /// Feeds one servo sample; returns true once the steady state is reached (and stays true for
  /// further calls until reset). Real-time safe.
  bool update(const Eigen::Vector3d& position_m, const Eigen::Vector3d& velocity_m_per_s) noexcept;

  bool settled() const noexcept { return settled_; }
  /// Mean position over the settled window (the last n_S samples). Unit: [m]
  Eigen::Vector3d settledPosition_m() const noexcept;
  /// Time since reset. Unit: [s]
  double elapsed_s() const noexcept { return elapsed_ticks_ * period_s_; }
  /// Number of consecutive slow samples so far.
  int consecutiveSlowSamples() const noexcept { return consecutive_; }

 private:
  int required_samples_;
  double speed_threshold_m_per_s_;
  long min_ticks_;
  double period_s_;
  long elapsed_ticks_ = 0;
  int consecutive_ = 0;
  bool settled_ = false;
  Eigen::Vector3d position_sum_m_ = Eigen::Vector3d::Zero();
};

}  // namespace autograv
