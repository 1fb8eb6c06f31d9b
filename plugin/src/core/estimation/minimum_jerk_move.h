#pragma once

// Private to core: the paths of the calibrator's, the explorer's and the wizard's moves.

#include <Eigen/Core>

namespace autograv {

/// A minimum-jerk path between two points (quintic in time, zero velocity and acceleration at
/// both ends), used to move between grid vertices without a force step at the start.
class MinimumJerkMove {
 public:
  /// Moves from `from_m` to `to_m` in `duration_s` (> 0). Real-time safe. Units: [m], [s]
  void start(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
             double duration_s) noexcept;
  /// Desired position, velocity and acceleration at `t_s` after start (held at the end).
  /// Real-time safe. Units: [m], [m/s], [m/s^2]
  void sample(double t_s, Eigen::Vector3d& position_m, Eigen::Vector3d& velocity_m_per_s,
              Eigen::Vector3d& acceleration_m_per_s2) const noexcept;
  /// Length of the move. Unit: [s]
  double duration_s() const noexcept { return duration_s_; }

  /// The shortest duration whose peak acceleration (5.77 d / T^2) stays under
  /// `max_acceleration_m_per_s2`, and at least `min_duration_s`. Units: [m], [m/s^2], [s]
  static double durationFor(double distance_m, double max_acceleration_m_per_s2,
                            double min_duration_s) noexcept;

 private:
  Eigen::Vector3d from_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d delta_m_ = Eigen::Vector3d::Zero();
  double duration_s_ = 1.0;
};

}  // namespace autograv
