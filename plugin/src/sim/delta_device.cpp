#include "autograv/sim/delta_device.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "autograv/error.h"
#include "autograv/estimation_parameters.h"

namespace autograv::sim {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
// The delta's axis: +x, toward the operator.
const Eigen::Vector3d kAxis = Eigen::Vector3d::UnitX();
// |det A| / b^3 below this is a constraint singularity (forearms coplanar): out of reach.
constexpr double kSingularDeterminant = 1e-6;
// Smallest singular-value ratio of J accepted over the workspace sphere at construction.
constexpr double kMaxJacobianCondition = 20.0;

void requirePositive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw Error(std::string("sim delta device: ") + name + " must be finite and > 0");
  }
}

void requireNonNegative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0) {
    throw Error(std::string("sim delta device: ") + name + " must be finite and >= 0");
  }
}

}  // namespace

DeltaParameters falconParameters() {
  DeltaParameters parameters;
  parameters.specifications.model_name = "sim:falcon";
  parameters.specifications.manufacturer = "autograv simulation (Novint Falcon-like)";
  parameters.specifications.serial_number = "SIM-FALCON-0001";
  // Novint's data sheet: force capability > 2 lbf.
  parameters.specifications.max_linear_force_n = 8.9;
  // Not published; an estimate of what a 1 kHz loop renders stably on this mechanism.
  parameters.specifications.max_linear_stiffness_n_per_m = 2000.0;
  parameters.specifications.max_linear_damping_n_s_per_m = 10.0;
  // The sphere inscribed in the published 4 x 4 x 4 in cube: every direction reaches it. The
  // mechanism reaches the whole cube (and a little more) before its arm stops.
  parameters.specifications.workspace_radius_m = 0.0508;
  parameters.driver.velocity_window_s = 0.015;
  parameters.driver.velocity_time_constant_s = 0.001;
  parameters.driver.noise_sigma_counts = 0.05;
  parameters.driver.noise_correlation_time_s = 0.01;
  return parameters;
}

DeltaDevice::DeltaDevice(const DeltaParameters& parameters, std::uint64_t seed)
    : SimulatedDriver(parameters.specifications, parameters.driver, seed), parameters_(parameters) {
  const auto& p = parameters;
  requirePositive(p.base_radius_m, "base_radius_m");
  requireNonNegative(p.effector_radius_m, "effector_radius_m");
  requirePositive(p.upper_arm_length_m, "upper_arm_length_m");
  requirePositive(p.forearm_length_m, "forearm_length_m");
  requirePositive(p.center_distance_m, "center_distance_m");
  requireNonNegative(p.upper_arm_mass_kg, "upper_arm_mass_kg");
  requireNonNegative(p.upper_arm_inertia_kg_m2, "upper_arm_inertia_kg_m2");
  requireNonNegative(p.forearm_mass_kg, "forearm_mass_kg");
  requireNonNegative(p.platform_mass_kg, "platform_mass_kg");
  requirePositive(p.grip_mass_kg, "grip_mass_kg");
  requirePositive(p.joint_stop_stiffness_n_m_per_rad, "joint_stop_stiffness_n_m_per_rad");
  requireNonNegative(p.joint_stop_damping_n_m_s_per_rad, "joint_stop_damping_n_m_s_per_rad");
  if (!std::isfinite(p.upper_arm_com_m)) {
    throw Error("sim delta device: upper_arm_com_m must be finite");
  }
  if (!p.leg_angles_rad.allFinite()) {
    throw Error("sim delta device: leg_angles_rad must be finite");
  }
  for (int j = 0; j < 3; ++j) {
    requireNonNegative(p.rotor_inertia_kg_m2[j], "rotor_inertia_kg_m2");
    requireNonNegative(p.viscous_friction_n_m_s_per_rad[j], "viscous_friction_n_m_s_per_rad");
    requirePositive(p.joint_counts_per_rev[j], "joint_counts_per_rev");
    requirePositive(p.max_joint_torque_n_m[j], "max_joint_torque_n_m");
    if (!std::isfinite(p.joint_min_rad[j]) || !std::isfinite(p.joint_max_rad[j]) ||
        p.joint_min_rad[j] >= p.joint_max_rad[j]) {
      throw Error("sim delta device: joint_min_rad must be finite and below joint_max_rad");
    }
  }

  counts_per_rad_ = p.joint_counts_per_rev / kTwoPi;
  double vertical_sum = 0.0;
  for (int leg = 0; leg < 3; ++leg) {
    const double phi = p.leg_angles_rad[leg];
    radial_[static_cast<std::size_t>(leg)] = Eigen::Vector3d(0.0, std::cos(phi), std::sin(phi));
    vertical_sum += std::sin(phi);
    // Height of the upper arm's centre of mass and of the knee above the hip, per cos(theta).
    arm_gravity_n_m_[leg] =
        kStandardGravity * std::sin(phi) *
        (p.upper_arm_mass_kg * p.upper_arm_com_m + 0.5 * p.forearm_mass_kg * p.upper_arm_length_m);
    arm_inertia_kg_m2_[leg] = p.rotor_inertia_kg_m2[leg] + p.upper_arm_inertia_kg_m2 +
                              p.upper_arm_mass_kg * p.upper_arm_com_m * p.upper_arm_com_m +
                              0.5 * p.forearm_mass_kg * p.upper_arm_length_m * p.upper_arm_length_m;
  }
  // The potential drops the hips' and the platform joints' constant heights, which cancel only
  // when the legs' heights do (legs 120 degrees apart).
  if (std::abs(vertical_sum) > 1e-9) {
    throw Error("sim delta device: leg_angles_rad must be 120 degrees apart");
  }
  moving_mass_kg_ = p.platform_mass_kg + p.grip_mass_kg + 1.5 * p.forearm_mass_kg;

  home_tip_m_ = p.center_distance_m * kAxis;
  theta_rad_.setZero();
  Eigen::Vector3d home_theta;
  if (!inverseKinematics(Eigen::Vector3d::Zero(), home_theta) ||
      (home_theta.array() <= p.joint_min_rad.array()).any() ||
      (home_theta.array() >= p.joint_max_rad.array()).any()) {
    throw Error(
        "sim delta device: center_distance_m puts the workspace centre out of reach or beyond the "
        "arm stops");
  }
  // The whole workspace sphere must be reachable within the arm stops, away from singularities.
  const double radius_m = p.specifications.workspace_radius_m;
  for (int i = -6; i <= 6; ++i) {
    for (int j = -6; j <= 6; ++j) {
      for (int k = -6; k <= 6; ++k) {
        const Eigen::Vector3d direction(i, j, k);
        if (direction.isZero() || std::abs(direction.norm() - 6.0) > 0.5) continue;
        const Eigen::Vector3d point = radius_m * direction.normalized();
        Eigen::Vector3d theta;
        Pose at{};
        bool usable =
            inverseKinematics(point, theta) && (theta.array() > p.joint_min_rad.array()).all() &&
            (theta.array() < p.joint_max_rad.array()).all() && pose(theta, point + home_tip_m_, at);
        if (usable) {
          const Eigen::Vector3d singular =
              Eigen::JacobiSVD<Eigen::Matrix3d>(at.jacobian).singularValues();
          usable = singular[2] * kMaxJacobianCondition > singular[0];
        }
        if (!usable) {
          throw Error("sim delta device: the workspace sphere (radius " +
                      std::to_string(radius_m * 1000.0) +
                      " mm around the centre) leaves the mechanism's reach, its arm stops or its "
                      "well-conditioned region; change the geometry or shrink workspace_radius_m");
        }
      }
    }
  }
  resetMechanism(Eigen::Vector3d::Zero());
}

Eigen::Vector3d DeltaDevice::kneeCentre(int leg, double theta_rad) const noexcept {
  // The knee moved inward by the platform joint's radius: the centre of the leg's sphere of
  // platform positions.
  const auto& p = parameters_;
  return (p.base_radius_m - p.effector_radius_m + p.upper_arm_length_m * std::cos(theta_rad)) *
             radial_[static_cast<std::size_t>(leg)] +
         p.upper_arm_length_m * std::sin(theta_rad) * kAxis;
}

bool DeltaDevice::solveForward(const Eigen::Vector3d& theta_rad,
                               Eigen::Vector3d& tip_m) const noexcept {
  // The three spheres have the same radius b: the platform lies on the line through the
  // circumcentre of their centres, normal to their plane, on the operator's side.
  const Eigen::Vector3d c1 = kneeCentre(0, theta_rad[0]);
  const Eigen::Vector3d c2 = kneeCentre(1, theta_rad[1]);
  const Eigen::Vector3d c3 = kneeCentre(2, theta_rad[2]);
  const Eigen::Vector3d u = c1 - c3;
  const Eigen::Vector3d v = c2 - c3;
  const Eigen::Vector3d normal = u.cross(v);
  const double normal2 = normal.squaredNorm();
  const double b = parameters_.forearm_length_m;
  if (!(normal2 > 1e-12 * b * b * b * b)) return false;  // knees in a line
  const Eigen::Vector3d circumcentre =
      c3 + (u.squaredNorm() * v - v.squaredNorm() * u).cross(normal) / (2.0 * normal2);
  const double height2 = b * b - (c1 - circumcentre).squaredNorm();
  if (!(height2 >= 0.0)) return false;
  const Eigen::Vector3d unit_normal = normal / std::sqrt(normal2);
  const double side = unit_normal.dot(kAxis) >= 0.0 ? 1.0 : -1.0;
  tip_m = circumcentre + side * std::sqrt(height2) * unit_normal;
  return true;
}

bool DeltaDevice::forwardKinematics(const Eigen::Vector3d& theta_rad,
                                    Eigen::Vector3d& position_m) const noexcept {
  Eigen::Vector3d tip;
  if (!theta_rad.allFinite() || !solveForward(theta_rad, tip)) return false;
  position_m = tip - home_tip_m_;
  return true;
}

bool DeltaDevice::inverseKinematics(const Eigen::Vector3d& position_m,
                                    Eigen::Vector3d& theta_rad) const noexcept {
  const auto& p = parameters_;
  const Eigen::Vector3d tip = position_m + home_tip_m_;
  if (!tip.allFinite()) return false;
  const double a = p.upper_arm_length_m;
  const double b = p.forearm_length_m;
  Eigen::Vector3d theta;
  for (int leg = 0; leg < 3; ++leg) {
    // The platform seen from the hip, moved out by the platform joint's radius: radial part u,
    // axial part w. The leg closes when u cos(theta) + w sin(theta) = k.
    const Eigen::Vector3d q =
        tip - (p.base_radius_m - p.effector_radius_m) * radial_[static_cast<std::size_t>(leg)];
    const double u = q.dot(radial_[static_cast<std::size_t>(leg)]);
    const double w = q.dot(kAxis);
    const double k = (q.squaredNorm() + a * a - b * b) / (2.0 * a);
    const double reach = std::hypot(u, w);
    if (!(reach > 0.0) || std::abs(k) > reach) return false;
    // The device's branch: the knee outside the line from the hip to the platform.
    theta[leg] = std::atan2(w, u) - std::acos(k / reach);
  }
  theta_rad = theta;
  return true;
}

bool DeltaDevice::pose(const Eigen::Vector3d& theta_rad, const Eigen::Vector3d& tip_m,
                       Pose& out) const noexcept {
  const double a = parameters_.upper_arm_length_m;
  for (int leg = 0; leg < 3; ++leg) {
    const auto i = static_cast<std::size_t>(leg);
    const double s = std::sin(theta_rad[leg]), c = std::cos(theta_rad[leg]);
    out.forearm[i] = tip_m - kneeCentre(leg, theta_rad[leg]);
    out.knee_rate[i] = a * (c * kAxis - s * radial_[i]);
    out.constraint.row(leg) = out.forearm[i].transpose();
    out.drive[leg] = out.forearm[i].dot(out.knee_rate[i]);
  }
  const double b = parameters_.forearm_length_m;
  const double determinant = out.constraint.determinant();
  if (!(std::abs(determinant) > kSingularDeterminant * b * b * b)) return false;
  // d_i . pd = (d_i . dc_i/dtheta_i) thetad_i for every leg: A pd = B thetad.
  out.jacobian = out.constraint.inverse() * out.drive.asDiagonal();
  return true;
}

void DeltaDevice::requirePose(const Eigen::Vector3d& position_m, Eigen::Vector3d& theta_rad,
                              Pose& out, const char* what) const {
  if (!inverseKinematics(position_m, theta_rad) ||
      !pose(theta_rad, position_m + home_tip_m_, out)) {
    throw Error(parameters_.specifications.model_name + " " + what +
                ": position is outside the mechanism's reach");
  }
}

Eigen::Matrix3d DeltaDevice::jacobian(const Eigen::Vector3d& theta_rad) const noexcept {
  Eigen::Vector3d tip;
  Pose at{};
  if (!solveForward(theta_rad, tip) || !pose(theta_rad, tip, at)) {
    return Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return at.jacobian;
}

Eigen::Matrix3d DeltaDevice::massMatrix(const Pose& at) const noexcept {
  Eigen::Matrix3d m = moving_mass_kg_ * at.jacobian.transpose() * at.jacobian;
  m.diagonal() += arm_inertia_kg_m2_;
  return m;
}

Eigen::Matrix3d DeltaDevice::massMatrix(const Eigen::Vector3d& theta_rad) const noexcept {
  Eigen::Vector3d tip;
  Pose at{};
  if (!solveForward(theta_rad, tip) || !pose(theta_rad, tip, at)) {
    return Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return massMatrix(at);
}

Eigen::Vector3d DeltaDevice::gravityTorque(const Eigen::Vector3d& theta_rad,
                                           const Pose& at) const noexcept {
  // U = sum_i k_i cos(theta_i) + m_p g z_p: the arms' part per joint, the platform's through J.
  const Eigen::Vector3d arms = -arm_gravity_n_m_.cwiseProduct(theta_rad.array().sin().matrix());
  return arms + moving_mass_kg_ * kStandardGravity * at.jacobian.row(2).transpose();
}

Eigen::Vector3d DeltaDevice::gravityTorque(const Eigen::Vector3d& theta_rad) const noexcept {
  Eigen::Vector3d tip;
  Pose at{};
  if (!solveForward(theta_rad, tip) || !pose(theta_rad, tip, at)) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return gravityTorque(theta_rad, at);
}

double DeltaDevice::potentialEnergy_j(const Eigen::Vector3d& theta_rad) const noexcept {
  Eigen::Vector3d tip;
  if (!solveForward(theta_rad, tip)) return std::numeric_limits<double>::quiet_NaN();
  return arm_gravity_n_m_.dot(theta_rad.array().cos().matrix()) +
         moving_mass_kg_ * kStandardGravity * tip.z();
}

double DeltaDevice::kineticEnergy_j(const Eigen::Vector3d& theta_rad,
                                    const Eigen::Vector3d& thetad_rad_per_s) const noexcept {
  return 0.5 * thetad_rad_per_s.dot(massMatrix(theta_rad) * thetad_rad_per_s);
}

Eigen::Vector3d DeltaDevice::trueGravity(const Eigen::Vector3d& position_m) const {
  Eigen::Vector3d theta;
  Pose at{};
  requirePose(position_m, theta, at, "trueGravity");
  return at.jacobian.transpose().inverse() * gravityTorque(theta, at);
}

Eigen::Matrix3d DeltaDevice::trueApparentMass(const Eigen::Vector3d& position_m) const {
  Eigen::Vector3d theta;
  Pose at{};
  requirePose(position_m, theta, at, "trueApparentMass");
  const Eigen::Matrix3d inverse = at.jacobian.inverse();
  const Eigen::Matrix3d lambda = inverse.transpose() * massMatrix(at) * inverse;
  return 0.5 * (lambda + lambda.transpose());
}

void DeltaDevice::integrateStep(const Eigen::Vector3d& motor_command,
                                const Eigen::Vector3d& external_force_n, double dt_s) noexcept {
  const Eigen::Vector3d force_n = motor_command + external_force_n;
  const auto& p = parameters_;
  const Eigen::Vector3d tip = tip_m_ + home_tip_m_;
  Pose at{};
  if (!pose(theta_rad_, tip, at)) {  // cannot happen inside the arm stops; stay put if it does
    thetad_rad_per_s_.setZero();
    velocity_m_per_s_.setZero();
    return;
  }
  const Eigen::Vector3d& theta = theta_rad_;
  const Eigen::Vector3d& thetad = thetad_rad_per_s_;
  const Eigen::Matrix3d jacobian_t = at.jacobian.transpose();

  // The motors make J^T F_actuators, each clamped to its own torque limit; the hand pushes on the
  // grip directly.
  const Eigen::Vector3d actuator_n = appliedForce_n();
  Eigen::Vector3d motor_n_m = jacobian_t * actuator_n;
  bool saturated = false;
  for (int j = 0; j < 3; ++j) {
    const double clamped =
        std::clamp(motor_n_m[j], -p.max_joint_torque_n_m[j], p.max_joint_torque_n_m[j]);
    saturated = saturated || clamped != motor_n_m[j];
    motor_n_m[j] = clamped;
  }
  if (saturated) ++joint_saturation_steps_;
  Eigen::Vector3d torque = motor_n_m + jacobian_t * (force_n - actuator_n) -
                           gravityTorque(theta, at) -
                           p.viscous_friction_n_m_s_per_rad.cwiseProduct(thetad);

  // Arm stops: a rubber spring and damper while an arm presses beyond its range.
  for (int j = 0; j < 3; ++j) {
    const double beyond = theta[j] - std::clamp(theta[j], p.joint_min_rad[j], p.joint_max_rad[j]);
    if (beyond != 0.0) {
      torque[j] -= p.joint_stop_stiffness_n_m_per_rad * beyond +
                   p.joint_stop_damping_n_m_s_per_rad * thetad[j];
      end_stop_hit_ = true;
    }
  }

  // Velocity-product terms: differentiating A pd = B thetad gives A pdd = B thetadd + h with
  //   h_i = thetad_i^2 d_i . d2c_i/dtheta_i^2 - |pd - dc_i/dtheta_i thetad_i|^2,
  // and the platform's inertia force m_p J^T (J thetadd + A^-1 h).
  const double a = p.upper_arm_length_m;
  Eigen::Vector3d h;
  for (int leg = 0; leg < 3; ++leg) {
    const auto i = static_cast<std::size_t>(leg);
    const Eigen::Vector3d knee_curvature =
        -a * (std::cos(theta[leg]) * radial_[i] + std::sin(theta[leg]) * kAxis);
    h[leg] = thetad[leg] * thetad[leg] * at.forearm[i].dot(knee_curvature) -
             (velocity_m_per_s_ - at.knee_rate[i] * thetad[leg]).squaredNorm();
  }
  const Eigen::Vector3d bias_m_per_s2 = at.constraint.inverse() * h;
  torque -= moving_mass_kg_ * (jacobian_t * bias_m_per_s2);
  const Eigen::Vector3d thetadd = massMatrix(at).inverse() * torque;

  // Semi-implicit Euler: new velocity, then the position with it.
  const Eigen::Vector3d next_thetad = thetad + dt_s * thetadd;
  const Eigen::Vector3d next_theta = theta + dt_s * next_thetad;
  Eigen::Vector3d next_tip;
  Pose next{};
  if (!solveForward(next_theta, next_tip) || !pose(next_theta, next_tip, next)) {
    thetad_rad_per_s_.setZero();  // a singular pose: the mechanism locks, as a real one would
    velocity_m_per_s_.setZero();
    return;
  }
  theta_rad_ = next_theta;
  thetad_rad_per_s_ = next_thetad;
  tip_m_ = next_tip - home_tip_m_;
  velocity_m_per_s_ = next.jacobian * next_thetad;
}

Eigen::Vector3d DeltaDevice::readEncoders(const Eigen::Vector3d& noise_counts) const noexcept {
  Eigen::Vector3d measured_theta;
  for (int j = 0; j < 3; ++j) {
    measured_theta[j] =
        std::round(theta_rad_[j] * counts_per_rad_[j] + noise_counts[j]) / counts_per_rad_[j];
  }
  Eigen::Vector3d position;
  // A count away from a reachable pose is reachable; keep the last truth if it ever is not.
  return forwardKinematics(measured_theta, position) ? position : tip_m_;
}

void DeltaDevice::resetMechanism(const Eigen::Vector3d& position_m) {
  const auto& p = parameters_;
  Eigen::Vector3d theta;
  Pose at{};
  if (!inverseKinematics(position_m, theta) || !pose(theta, position_m + home_tip_m_, at) ||
      (theta.array() < p.joint_min_rad.array()).any() ||
      (theta.array() > p.joint_max_rad.array()).any()) {
    throw Error(p.specifications.model_name +
                ": resetState position is outside the workspace (beyond the arm stops)");
  }
  theta_rad_ = theta;
  thetad_rad_per_s_.setZero();
  Eigen::Vector3d tip;
  solveForward(theta, tip);
  tip_m_ = tip - home_tip_m_;
  velocity_m_per_s_.setZero();
}

}  // namespace autograv::sim
