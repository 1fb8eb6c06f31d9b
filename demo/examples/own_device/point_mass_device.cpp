#include "point_mass_device.h"

#include <algorithm>
#include <cmath>

namespace example {

namespace {
constexpr double kMass_kg = 0.08;            // inertia (not |G|/g: a linkage adds weight)
constexpr double kCoulomb_n = 0.03;          // dry friction, also the breakaway force
constexpr double kViscous_n_s_per_m = 0.4;   // bearings
constexpr double kWorkspaceRadius_m = 0.08;  // the walls
constexpr double kWallStiffness_n_per_m = 4000.0;
constexpr double kWallDamping_n_s_per_m = 8.0;
constexpr double kHandStiffness_n_per_m = 1500.0;  // a firm grip
constexpr double kHandDamping_n_s_per_m = 15.0;
constexpr double kHandSpeed_m_per_s = 0.05;
constexpr double kStickSpeed_m_per_s = 1e-4;  // below it, friction may hold it still
constexpr double kEncoder_m = 5e-6;           // position resolution
constexpr int kSubsteps = 10;                 // physics steps per servo period
}  // namespace

PointMassDevice::PointMassDevice(double servo_period_s)
    : period_s_(servo_period_s), position_m_(0.0, 0.0, -0.07) {
  specs_.model_name = "example:point-mass";
  specs_.manufacturer = "autograv example";
  specs_.serial_number = "PM-0001";
  specs_.max_linear_force_n = 3.0;
  specs_.max_linear_stiffness_n_per_m = 2000.0;
  specs_.max_linear_damping_n_s_per_m = 6.0;
  specs_.workspace_radius_m = kWorkspaceRadius_m;
}

Eigen::Vector3d PointMassDevice::gravityForce_n(const Eigen::Vector3d& p) {
  // Minus the gradient of a smooth potential, as for any mechanism:
  //   U = 0.55 z + 2.5 x z + 0.75 z^2 - 0.05 y - y z + 30 (x^2 + y^2) z   [N m, with X in m]
  // 0.55 N down at the centre, heavier toward the operator (+x), a small sideways pull, and a
  // curvature a trilinear map cannot follow exactly (its residual is a few mN per 20 mm cell).
  const double x = p.x(), y = p.y(), z = p.z();
  return Eigen::Vector3d(-(2.5 * z + 60.0 * x * z), 0.05 + z - 60.0 * y * z,
                         -(0.55 + 2.5 * x + 1.5 * z - y + 30.0 * (x * x + y * y)));
}

bool PointMassDevice::open() {
  open_ = true;
  return true;
}

bool PointMassDevice::close() {
  open_ = false;
  return true;
}

bool PointMassDevice::calibrate(bool /*force*/) { return open_; }

bool PointMassDevice::getPosition(Eigen::Vector3d& position_m) {
  if (!open_) return false;
  position_m = (position_m_ / kEncoder_m).array().round().matrix() * kEncoder_m;
  return true;
}

bool PointMassDevice::getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) {
  if (!open_) return false;
  velocity_m_per_s = velocity_m_per_s_;
  return true;
}

bool PointMassDevice::getUserSwitch(int index, bool& pressed) {
  pressed = index == 0 && button_.load(std::memory_order_relaxed);
  return open_;
}

bool PointMassDevice::setForce(const Eigen::Vector3d& force_n) {
  if (!open_ || !force_n.allFinite()) return false;
  Eigen::Vector3d command_n = force_n;
  const double norm = command_n.norm();
  if (norm > specs_.max_linear_force_n) command_n *= specs_.max_linear_force_n / norm;
  for (int k = 0; k < kSubsteps; ++k) step(command_n, period_s_ / kSubsteps);
  time_s_.store(time_s_.load() + period_s_);
  return true;
}

void PointMassDevice::step(const Eigen::Vector3d& command_n, double dt_s) {
  Eigen::Vector3d force_n = command_n + gravityForce_n(position_m_);
  force_n -= kViscous_n_s_per_m * velocity_m_per_s_;
  // The walls of the workspace sphere.
  const double radius_m = position_m_.norm();
  if (radius_m > kWorkspaceRadius_m) {
    const Eigen::Vector3d normal = position_m_ / radius_m;
    const double inward_speed = velocity_m_per_s_.dot(normal);
    force_n -= normal * (kWallStiffness_n_per_m * (radius_m - kWorkspaceRadius_m) +
                         kWallDamping_n_s_per_m * std::max(0.0, inward_speed));
  }
  // The hand: a spring-damper grip whose point moves toward the target at a hand's speed.
  const bool holding = hand_holding_.load(std::memory_order_relaxed);
  if (holding) {
    if (!hand_was_holding_) hand_point_m_ = position_m_;
    const Eigen::Vector3d target(target_x_.load(std::memory_order_relaxed),
                                 target_y_.load(std::memory_order_relaxed),
                                 target_z_.load(std::memory_order_relaxed));
    const Eigen::Vector3d to_target = target - hand_point_m_;
    const double step_m = kHandSpeed_m_per_s * dt_s;
    hand_point_m_ =
        to_target.norm() <= step_m ? target : hand_point_m_ + to_target.normalized() * step_m;
    force_n += kHandStiffness_n_per_m * (hand_point_m_ - position_m_) -
               kHandDamping_n_s_per_m * velocity_m_per_s_;
    hand_arrived_.store((position_m_ - target).norm() < 1e-3, std::memory_order_relaxed);
  }
  hand_was_holding_ = holding;
  // Dry friction: a slow end-effector sticks while the other forces stay below the breakaway.
  const double speed = velocity_m_per_s_.norm();
  if (speed < kStickSpeed_m_per_s && force_n.norm() <= kCoulomb_n) {
    velocity_m_per_s_.setZero();
    return;
  }
  const Eigen::Vector3d direction = speed >= kStickSpeed_m_per_s
                                        ? Eigen::Vector3d(velocity_m_per_s_ / speed)
                                        : Eigen::Vector3d(force_n.normalized());
  force_n -= kCoulomb_n * direction;
  velocity_m_per_s_ += force_n / kMass_kg * dt_s;  // semi-implicit Euler
  position_m_ += velocity_m_per_s_ * dt_s;
}

void PointMassDevice::grab() { hand_holding_.store(true); }

void PointMassDevice::moveHandTo(const Eigen::Vector3d& target_m) {
  hand_arrived_.store(false);
  target_x_.store(target_m.x());
  target_y_.store(target_m.y());
  target_z_.store(target_m.z());
}

void PointMassDevice::release() {
  hand_holding_.store(false);
  hand_arrived_.store(false);
}

void PointMassDevice::placeAt(const Eigen::Vector3d& position_m) {
  position_m_ = position_m;
  velocity_m_per_s_.setZero();
}

}  // namespace example
