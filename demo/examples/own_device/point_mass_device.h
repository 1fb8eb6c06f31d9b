#pragma once

// The example's own haptic device: a point mass in a spherical workspace with gravity, dry
// friction and a hand that can hold it. It stands for the driver of your device: autograv only
// sees the HapticDevice interface, never this physics.

#include <atomic>

#include <Eigen/Core>

#include <autograv/device/haptic_device.h>

namespace example {

/// A 3-DoF point mass of 80 g moving inside a sphere of radius 80 mm. Its "gravity" is that of a
/// handle on a linkage: 0.55 N down at the centre, varying smoothly with the position
/// (gravityForce_n). Dry friction of 30 mN (sticking below it), light viscous damping, stiff
/// walls at the sphere. Each setForce() advances its physics by one servo period, so the device
/// runs as fast as the servo loop ticks it, in simulated time.
///
/// Threads: the servo thread calls the HapticDevice methods; any thread may move the hand
/// (grab, moveHandTo, release) and press the stylus button (setButton), through atomics.
class PointMassDevice final : public autograv::HapticDevice {
 public:
  /// `servo_period_s`: the time one setForce() advances. Unit: [s]
  explicit PointMassDevice(double servo_period_s = 1e-3);

  bool open() override;
  bool close() override;
  bool calibrate(bool force = false) override;
  bool getPosition(Eigen::Vector3d& position_m) override;
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override;
  bool getUserSwitch(int index, bool& pressed) override;
  bool setForce(const Eigen::Vector3d& force_n) override;
  const autograv::DeviceSpecifications& specifications() const override { return specs_; }

  /// The force gravity (and the linkage) exerts on the end-effector at `position_m`: what a
  /// perfect map cancels is its opposite. Unit: [N]
  static Eigen::Vector3d gravityForce_n(const Eigen::Vector3d& position_m);

  // --- The simulated hand (any thread) --------------------------------------------------------
  /// The hand takes the end-effector where it is and carries it toward moveHandTo's target.
  void grab();
  /// Where the hand carries it, at 50 mm/s. Unit: [m]
  void moveHandTo(const Eigen::Vector3d& target_m);
  void release();
  bool handHolding() const { return hand_holding_.load(); }
  /// True when the hand holds the end-effector within 1 mm of its target.
  bool handArrived() const { return hand_arrived_.load(); }
  /// Presses (true) or lets up (false) the stylus button, user switch 0.
  void setButton(bool pressed) { button_.store(pressed); }
  bool buttonPressed() const { return button_.load(); }

  /// Puts the end-effector at rest at `position_m` (between runs, with no servo loop running).
  void placeAt(const Eigen::Vector3d& position_m);
  /// Simulated time so far. Unit: [s]
  double time_s() const { return time_s_.load(); }

 private:
  void step(const Eigen::Vector3d& command_n, double dt_s);

  autograv::DeviceSpecifications specs_;
  double period_s_;
  bool open_ = false;
  // Servo-thread state.
  Eigen::Vector3d position_m_;
  Eigen::Vector3d velocity_m_per_s_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d hand_point_m_ = Eigen::Vector3d::Zero();  ///< Where the hand's grip is now.
  bool hand_was_holding_ = false;
  // Set by the hand's thread, read by the servo thread.
  std::atomic<bool> hand_holding_{false};
  std::atomic<bool> hand_arrived_{false};
  std::atomic<bool> button_{false};
  std::atomic<double> target_x_{0.0}, target_y_{0.0}, target_z_{0.0};
  std::atomic<double> time_s_{0.0};
};

}  // namespace example
