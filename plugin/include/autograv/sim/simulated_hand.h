#pragma once

#include <Eigen/Core>

namespace autograv::sim {

/// A simulated user's hand. While it holds the end-effector it pulls it toward a target through a
/// stiff spring-damper (a human grip); letting go removes that force entirely. The target can jump
/// or glide toward a goal at a limited speed, so scripted paths look like a person moving.
class SimulatedHand {
 public:
  /// Grip stiffness. Unit: [N/m]
  double stiffness_n_per_m = 800.0;
  /// Grip damping. Unit: [N s/m]
  double damping_n_s_per_m = 8.0;

  /// Takes hold of the end-effector where it is (the target starts at `position_m`).
  void grab(const Eigen::Vector3d& position_m) noexcept {
    holding_ = true;
    target_m_ = position_m;
    goal_m_ = position_m;
  }
  /// Lets go: no hand force from now on.
  void release() noexcept { holding_ = false; }
  /// True while the hand holds the end-effector.
  bool holding() const noexcept { return holding_; }

  /// Moves the target at once. Unit: [m]
  void setTarget(const Eigen::Vector3d& target_m) noexcept {
    target_m_ = target_m;
    goal_m_ = target_m;
  }
  /// Lets the target glide to `goal_m` at `speed_m_per_s`. Units: [m], [m/s]
  void moveTo(const Eigen::Vector3d& goal_m, double speed_m_per_s) noexcept {
    goal_m_ = goal_m;
    speed_m_per_s_ = speed_m_per_s;
  }
  /// True once the target reached the goal of moveTo().
  bool atGoal() const noexcept { return (goal_m_ - target_m_).squaredNorm() < 1e-18; }
  /// Where the hand pulls the end-effector now. Unit: [m]
  const Eigen::Vector3d& target_m() const noexcept { return target_m_; }

  /// Advances the target by `dt_s` and returns the hand's force on an end-effector at
  /// `position_m` moving at `velocity_m_per_s`. Real-time safe. Unit: [N]
  Eigen::Vector3d update(double dt_s, const Eigen::Vector3d& position_m,
                         const Eigen::Vector3d& velocity_m_per_s) noexcept {
    const Eigen::Vector3d to_goal = goal_m_ - target_m_;
    const double step_m = speed_m_per_s_ * dt_s;
    const double distance_m = to_goal.norm();
    target_m_ = distance_m <= step_m ? goal_m_
                                     : Eigen::Vector3d(target_m_ + to_goal * (step_m / distance_m));
    if (!holding_) return Eigen::Vector3d::Zero();
    return stiffness_n_per_m * (target_m_ - position_m) - damping_n_s_per_m * velocity_m_per_s;
  }

 private:
  bool holding_ = false;
  Eigen::Vector3d target_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d goal_m_ = Eigen::Vector3d::Zero();
  double speed_m_per_s_ = 0.05;
};

}  // namespace autograv::sim
