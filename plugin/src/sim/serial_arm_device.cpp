#include "autograv/sim/serial_arm_device.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/LU>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "sim/parameter_checks.h"
#include "sim/preset_driver.h"

namespace autograv::sim {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
// Damping of the elbow joint stop, so that a hit does not ring. Unit: [N m s/rad]
constexpr double kElbowStopDamping = 0.02;

}  // namespace

LuGreParameters omniJointFriction(FrictionLevel level) {
  // SensAble's PHANToM Omni datasheet bounds the backdrive friction at the tip by 0.26 N. With
  // 133 mm links a joint torque T is felt at the tip as about T / 0.133 m along the direction
  // that joint moves, and the force breaks a joint loose when its projection on that direction
  // does; 7 mN m per joint gives 45-55 mN along a joint's own direction and at most about
  // 120 mN where all three joints must slip together (the parallelepiped's corners), inside
  // the bound in every direction. kLow and kHigh scale it by 1/3 and 2.5 (see dryFrictionScale).
  // Sliding (Coulomb) friction is 70 % of stiction; the Stribeck speed of 0.01 rad/s (1.3 mm/s at
  // the tip) and the 0.1 mrad pre-sliding range (13 um at the tip, a quarter of an encoder count)
  // are typical of ball bearings and capstan cables, not Omni measurements.
  const Eigen::Vector3d stiction_n_m = Eigen::Vector3d::Constant(7.0e-3);
  // Joint inertias of the preset at the home pose, for the bristle damping. Unit: [kg m^2]
  const Eigen::Vector3d inertia_kg_m2(1.0e-3, 9.0e-4, 8.0e-4);
  return makeLuGreParameters(0.7 * stiction_n_m, stiction_n_m, Eigen::Vector3d::Constant(0.01),
                             Eigen::Vector3d::Constant(1.0e-4), inertia_kg_m2, 0.5,
                             Eigen::Vector3d::Constant(6.0e-3))
      .scaledDry(dryFrictionScale(level));
}

SerialArmParameters omniParameters(FrictionLevel friction) {
  SerialArmParameters parameters;
  parameters.friction = omniJointFriction(friction);
  // Each motor's amplifier: 0.45 N m (3.3 N at the tip along a joint's direction at the home
  // pose, so that near the edges of the workspace a joint saturates before the Cartesian clamp),
  // through a 12-bit DAC (0.22 mN m, about 1.7 mN at the tip, per count). ASSUMED figures.
  parameters.driver = presetDriver(0.45, 12, 0.015);
  parameters.specifications.model_name = "sim:omni";
  parameters.specifications.manufacturer = "autograv simulation (SensAble PHANToM Omni-like)";
  parameters.specifications.serial_number = "SIM-OMNI-0001";
  parameters.specifications.max_linear_force_n = 3.3;
  parameters.specifications.max_continuous_force_n = 0.88;  // datasheet, 24 h
  // SensAble quotes > 1.02 N/mm along its weakest axis.
  parameters.specifications.max_linear_stiffness_n_per_m = 1000.0;
  parameters.specifications.max_linear_damping_n_s_per_m = 3.0;
  parameters.specifications.workspace_radius_m = 0.10;
  return parameters;
}

SerialArmDevice::SerialArmDevice(const SerialArmParameters& parameters, std::uint64_t seed)
    : SimulatedDriver(parameters.specifications, parameters.driver, seed),
      parameters_(parameters),
      q_rad_(parameters.home_joint_angles_rad) {
  const auto& p = parameters;
  const ParameterChecks check("sim serial-arm device");
  check.armsAndMotors(p);
  check.nonNegative(p.upper_arm_axial_inertia_kg_m2, "upper_arm_axial_inertia_kg_m2");
  check.finite(p.forearm_com_m, "forearm_com_m");
  check.nonNegative(p.forearm_inertia_kg_m2, "forearm_inertia_kg_m2");
  check.nonNegative(p.forearm_axial_inertia_kg_m2, "forearm_axial_inertia_kg_m2");
  check.positive(p.tip_mass_kg, "tip_mass_kg");
  check.positive(p.turret_inertia_kg_m2, "turret_inertia_kg_m2");
  check.cogging(p.cogging_amplitude_n_m, "cogging_amplitude_n_m", p.cogging_phase_rad);
  check.nonNegative(p.cogging_cycles_per_rev, "cogging_cycles_per_rev");
  friction_ = LuGreFriction(p.friction);
  cogging_ = CoggingRipple(p.cogging_amplitude_n_m);
  check.finite(p.home_joint_angles_rad, "home_joint_angles_rad");
  check.positive(p.end_stop_stiffness_n_per_m, "end_stop_stiffness_n_per_m");
  check.nonNegative(p.end_stop_damping_n_s_per_m, "end_stop_damping_n_s_per_m");
  check.positive(p.elbow_stop_stiffness_n_m_per_rad, "elbow_stop_stiffness_n_m_per_rad");
  if (!(p.max_elbow_offset_rad > 0.0 && p.max_elbow_offset_rad < 0.5 * kTwoPi / 2.0)) {
    check.fail("max_elbow_offset_rad must be in (0, pi/2)");
  }
  counts_per_rad_ = p.joint_counts_per_rev / kTwoPi;
  // Constant parts of the dynamics, folded once so the 10 kHz step does not redo them.
  Inertia& k = inertia_;
  k.l1 = p.upper_arm_length_m;
  k.l2 = p.forearm_length_m;
  k.a3 = p.forearm_com_m;
  k.m3 = p.forearm_mass_kg;
  k.mt = p.tip_mass_kg;
  k.yaw = p.turret_inertia_kg_m2 + p.rotor_inertia_kg_m2[0] + p.upper_arm_axial_inertia_kg_m2 +
          p.forearm_axial_inertia_kg_m2;
  k.upper_yaw = p.upper_arm_mass_kg * p.upper_arm_com_m * p.upper_arm_com_m +
                p.upper_arm_inertia_kg_m2 - p.upper_arm_axial_inertia_kg_m2;
  k.forearm_yaw = p.forearm_inertia_kg_m2 - p.forearm_axial_inertia_kg_m2;
  k.m22 = p.rotor_inertia_kg_m2[1] + p.upper_arm_mass_kg * p.upper_arm_com_m * p.upper_arm_com_m +
          p.upper_arm_inertia_kg_m2 + (k.m3 + k.mt) * k.l1 * k.l1;
  k.m33 =
      p.rotor_inertia_kg_m2[2] + k.m3 * k.a3 * k.a3 + p.forearm_inertia_kg_m2 + k.mt * k.l2 * k.l2;
  k.coupling = (k.m3 * k.a3 + k.mt * k.l2) * k.l1;
  k.gravity2 = kStandardGravity * (p.upper_arm_mass_kg * p.upper_arm_com_m + (k.m3 + k.mt) * k.l1);
  k.gravity3 = kStandardGravity * (k.m3 * k.a3 + k.mt * k.l2);

  home_tip_m_.setZero();
  home_tip_m_ = tipInShoulderFrame(trig(p.home_joint_angles_rad));
  const double home_offset = std::abs(p.home_joint_angles_rad[2] - p.home_joint_angles_rad[1]);
  if (home_offset >= p.max_elbow_offset_rad || home_tip_m_.head<2>().norm() <= 0.0) {
    check.fail(
        "home_joint_angles_rad must put the tip in front of the yaw axis with |q3 - q2| below "
        "max_elbow_offset_rad");
  }
  // The whole workspace sphere (end stops included) must be reachable, away from singularities.
  const double reach_m = p.specifications.workspace_radius_m * 1.05;
  for (int i = -6; i <= 6; ++i) {
    for (int j = -6; j <= 6; ++j) {
      for (int k = -6; k <= 6; ++k) {
        Eigen::Vector3d direction(i, j, k);
        if (direction.isZero() || std::abs(direction.norm() - 6.0) > 0.5) continue;
        Eigen::Vector3d q;
        const Eigen::Vector3d point = reach_m * direction.normalized();
        if (!inverseKinematics(point, q) || std::abs(q[2] - q[1]) >= p.max_elbow_offset_rad ||
            tipInShoulderFrame(trig(q)).head<2>().norm() < 0.01) {
          check.fail("the workspace sphere (radius " +
                     std::to_string(p.specifications.workspace_radius_m * 1000.0) +
                     " mm around the home pose) leaves the arm's reach; move home_joint_angles_rad "
                     "or shrink workspace_radius_m");
        }
      }
    }
  }
  trig_ = trig(q_rad_);
  updateTip();
}

SerialArmDevice::Trig SerialArmDevice::trig(const Eigen::Vector3d& q) noexcept {
  return {std::sin(q[0]), std::cos(q[0]), std::sin(q[1]),
          std::cos(q[1]), std::sin(q[2]), std::cos(q[2])};
}

Eigen::Vector3d SerialArmDevice::tipInShoulderFrame(const Trig& t) const noexcept {
  const double l1 = parameters_.upper_arm_length_m;
  const double l2 = parameters_.forearm_length_m;
  const double r = l1 * t.c2 + l2 * t.s3;
  const double h = l1 * t.s2 - l2 * t.c3;
  return {r * t.c1, r * t.s1, h};
}

Eigen::Vector3d SerialArmDevice::forwardKinematics(const Eigen::Vector3d& q_rad) const noexcept {
  return tipInShoulderFrame(trig(q_rad)) - home_tip_m_;
}

bool SerialArmDevice::inverseKinematics(const Eigen::Vector3d& position_m,
                                        Eigen::Vector3d& q_rad) const noexcept {
  const double l1 = parameters_.upper_arm_length_m;
  const double l2 = parameters_.forearm_length_m;
  const Eigen::Vector3d p = position_m + home_tip_m_;
  if (!p.allFinite()) return false;
  const double r = std::hypot(p.x(), p.y());
  const double h = p.z();
  if (r <= 0.0) return false;
  // |tip - shoulder|^2 = l1^2 + l2^2 + 2 l1 l2 sin(q3 - q2)
  const double s = (r * r + h * h - l1 * l1 - l2 * l2) / (2.0 * l1 * l2);
  if (!(s >= -1.0 && s <= 1.0)) return false;
  const double offset = std::asin(s);  // q3 - q2, the device's branch: |offset| <= pi/2
  // (r, h) is (l1 + l2 sin(offset), -l2 cos(offset)) rotated by q2.
  const double a = l1 + l2 * s;
  const double b = -l2 * std::cos(offset);
  const double q2 = std::atan2(h, r) - std::atan2(b, a);
  q_rad = Eigen::Vector3d(std::atan2(p.y(), p.x()), q2, q2 + offset);
  return true;
}

Eigen::Matrix3d SerialArmDevice::jacobian(const Trig& t) const noexcept {
  const double l1 = parameters_.upper_arm_length_m;
  const double l2 = parameters_.forearm_length_m;
  const double r = l1 * t.c2 + l2 * t.s3;
  Eigen::Matrix3d j;
  j << -r * t.s1, -l1 * t.s2 * t.c1, l2 * t.c3 * t.c1,  //
      r * t.c1, -l1 * t.s2 * t.s1, l2 * t.c3 * t.s1,    //
      0.0, l1 * t.c2, l2 * t.s3;
  return j;
}

Eigen::Matrix3d SerialArmDevice::jacobian(const Eigen::Vector3d& q_rad) const noexcept {
  return jacobian(trig(q_rad));
}

Eigen::Matrix3d SerialArmDevice::massMatrix(const Trig& t) const noexcept {
  const Inertia& k = inertia_;
  const double r3 = k.l1 * t.c2 + k.a3 * t.s3;  // forearm centre of mass, horizontal reach
  const double rt = k.l1 * t.c2 + k.l2 * t.s3;  // tip
  // Yaw: every body's mass at its reach, plus each link's inertia about the vertical (the upper
  // arm is at angle q2 from the horizontal, the forearm at q3 - pi/2).
  const double m11 = k.yaw + k.upper_yaw * t.c2 * t.c2 + k.forearm_yaw * t.s3 * t.s3 +
                     k.m3 * r3 * r3 + k.mt * rt * rt;
  const double m23 = k.coupling * (t.s3 * t.c2 - t.c3 * t.s2);  // K sin(q3 - q2)
  Eigen::Matrix3d m;
  m << m11, 0.0, 0.0,   //
      0.0, k.m22, m23,  //
      0.0, m23, k.m33;
  return m;
}

Eigen::Matrix3d SerialArmDevice::massMatrix(const Eigen::Vector3d& q_rad) const noexcept {
  return massMatrix(trig(q_rad));
}

Eigen::Vector3d SerialArmDevice::gravityTorque(const Trig& t) const noexcept {
  return {0.0, inertia_.gravity2 * t.c2, inertia_.gravity3 * t.s3};
}

Eigen::Vector3d SerialArmDevice::gravityTorque(const Eigen::Vector3d& q_rad) const noexcept {
  return gravityTorque(trig(q_rad));
}

double SerialArmDevice::potentialEnergy_j(const Eigen::Vector3d& q_rad) const noexcept {
  return inertia_.gravity2 * std::sin(q_rad[1]) - inertia_.gravity3 * std::cos(q_rad[2]);
}

Eigen::Vector3d SerialArmDevice::coriolisTorque(const Trig& t,
                                                const Eigen::Vector3d& qd) const noexcept {
  // h_i = sum_jk (dM_ij/dq_k - 1/2 dM_jk/dq_i) qd_j qd_k, with M11(q2, q3) and
  // M23 = K sin(q3 - q2) the only configuration-dependent entries.
  const Inertia& k = inertia_;
  const double r3 = k.l1 * t.c2 + k.a3 * t.s3;
  const double rt = k.l1 * t.c2 + k.l2 * t.s3;
  const double dm11_dq2 = -2.0 * t.s2 * (t.c2 * k.upper_yaw + k.l1 * (k.m3 * r3 + k.mt * rt));
  const double dm11_dq3 = 2.0 * t.c3 * (t.s3 * k.forearm_yaw + k.m3 * k.a3 * r3 + k.mt * k.l2 * rt);
  const double k_cos = k.coupling * (t.c3 * t.c2 + t.s3 * t.s2);  // K cos(q3 - q2)
  return {qd[0] * (dm11_dq2 * qd[1] + dm11_dq3 * qd[2]),
          k_cos * qd[2] * qd[2] - 0.5 * dm11_dq2 * qd[0] * qd[0],
          -k_cos * qd[1] * qd[1] - 0.5 * dm11_dq3 * qd[0] * qd[0]};
}

Eigen::Vector3d SerialArmDevice::coriolisTorque(const Eigen::Vector3d& q_rad,
                                                const Eigen::Vector3d& qd) const noexcept {
  return coriolisTorque(trig(q_rad), qd);
}

double SerialArmDevice::kineticEnergy_j(const Eigen::Vector3d& q_rad,
                                        const Eigen::Vector3d& qd) const noexcept {
  return 0.5 * qd.dot(massMatrix(q_rad) * qd);
}

Eigen::Vector3d SerialArmDevice::trueVelocity_m_per_s() const noexcept {
  // J(q) qd written out (the hand asks for it every internal step).
  const Trig& t = trig_;
  const Eigen::Vector3d& qd = qd_rad_per_s_;
  const double l1 = inertia_.l1, l2 = inertia_.l2;
  const double reach = l1 * t.c2 + l2 * t.s3;
  const double reach_rate = -l1 * t.s2 * qd[1] + l2 * t.c3 * qd[2];
  return {t.c1 * reach_rate - reach * t.s1 * qd[0], t.s1 * reach_rate + reach * t.c1 * qd[0],
          l1 * t.c2 * qd[1] + l2 * t.s3 * qd[2]};
}

void SerialArmDevice::updateTip() noexcept { tip_m_ = tipInShoulderFrame(trig_) - home_tip_m_; }

Eigen::Vector3d SerialArmDevice::trueGravity(const Eigen::Vector3d& position_m) const {
  Eigen::Vector3d q;
  if (!inverseKinematics(position_m, q)) {
    throw Error("sim:omni trueGravity: position is outside the arm's reach");
  }
  const Trig t = trig(q);
  const Eigen::Matrix3d jacobian_t = jacobian(t).transpose();
  return commandDelivering_n(jacobian_t, loadedGravity_n(jacobian_t.inverse() * gravityTorque(t)));
}

Eigen::Vector3d SerialArmDevice::mechanismGravity_n() const noexcept {
  return jacobian(trig_).transpose().inverse() * gravityTorque(trig_);
}

void SerialArmDevice::applyPayload_kg(double payload_kg) {
  // A payload is more tip mass: every folded constant is linear in it (see the constructor).
  Inertia& k = inertia_;
  const double delta_kg = parameters_.tip_mass_kg + payload_kg - k.mt;
  k.mt += delta_kg;
  k.m22 += delta_kg * k.l1 * k.l1;
  k.m33 += delta_kg * k.l2 * k.l2;
  k.coupling += delta_kg * k.l2 * k.l1;
  k.gravity2 += kStandardGravity * delta_kg * k.l1;
  k.gravity3 += kStandardGravity * delta_kg * k.l2;
}

Eigen::Matrix3d SerialArmDevice::trueApparentMass(const Eigen::Vector3d& position_m) const {
  Eigen::Vector3d q;
  if (!inverseKinematics(position_m, q)) {
    throw Error("sim:omni trueApparentMass: position is outside the arm's reach");
  }
  const Trig t = trig(q);
  const Eigen::Matrix3d inverse = jacobian(t).inverse();
  const Eigen::Matrix3d lambda = inverse.transpose() * massMatrix(t) * inverse;
  return 0.5 * (lambda + lambda.transpose());
}

void SerialArmDevice::integrateStep(const Eigen::Vector3d& motor_torque_n_m,
                                    const Eigen::Vector3d& external_force_n, double dt_s) noexcept {
  // The same model as jacobian(), massMatrix(), gravityTorque() and coriolisTorque(), written out
  // in scalars with shared subexpressions: this runs 10,000 times per simulated second.
  const auto& p = parameters_;
  const Inertia& k = inertia_;
  const Trig& t = trig_;
  const Eigen::Vector3d& qd = qd_rad_per_s_;
  Eigen::Vector3d cartesian_n = external_force_n;
  const double radius_m = p.specifications.workspace_radius_m;
  const double distance2 = tip_m_.squaredNorm();  // the workspace sphere is centred on home
  if (distance2 > radius_m * radius_m) {
    const double distance_m = std::sqrt(distance2);
    const Eigen::Vector3d normal = tip_m_ / distance_m;
    // Pushes back along the normal and drags on the whole tip velocity (a rubber stop).
    cartesian_n -= p.end_stop_stiffness_n_per_m * (distance_m - radius_m) * normal +
                   p.end_stop_damping_n_s_per_m * trueVelocity_m_per_s();
    end_stop_hit_ = true;
  }

  const double reach = k.l1 * t.c2 + k.l2 * t.s3;          // tip, horizontal distance to the axis
  const double forearm_reach = k.l1 * t.c2 + k.a3 * t.s3;  // forearm centre of mass
  const double sin_offset = t.s3 * t.c2 - t.c3 * t.s2;     // sin(q3 - q2)
  const double cos_offset = t.c3 * t.c2 + t.s3 * t.s2;
  // J^T F, with F split into radial, tangential and vertical parts.
  const double radial_n = t.c1 * cartesian_n.x() + t.s1 * cartesian_n.y();
  const double tangential_n = t.c1 * cartesian_n.y() - t.s1 * cartesian_n.x();
  // M(q) and its derivatives (Coriolis and centrifugal terms).
  const double m11 = k.yaw + k.upper_yaw * t.c2 * t.c2 + k.forearm_yaw * t.s3 * t.s3 +
                     k.m3 * forearm_reach * forearm_reach + k.mt * reach * reach;
  const double m23 = k.coupling * sin_offset;
  const double dm11_dq2 =
      -2.0 * t.s2 * (t.c2 * k.upper_yaw + k.l1 * (k.m3 * forearm_reach + k.mt * reach));
  const double dm11_dq3 =
      2.0 * t.c3 * (t.s3 * k.forearm_yaw + k.m3 * k.a3 * forearm_reach + k.mt * k.l2 * reach);
  const double k_cos = k.coupling * cos_offset;
  // Friction (LuGre, viscous included) against the velocity held over the step.
  const Eigen::Vector3d friction_n_m = friction_.step(qd, dt_s);
  Eigen::Vector3d torque(reach * tangential_n - qd[0] * (dm11_dq2 * qd[1] + dm11_dq3 * qd[2]),
                         k.l1 * (t.c2 * cartesian_n.z() - t.s2 * radial_n) - k.gravity2 * t.c2 -
                             (k_cos * qd[2] * qd[2] - 0.5 * dm11_dq2 * qd[0] * qd[0]),
                         k.l2 * (t.s3 * cartesian_n.z() + t.c3 * radial_n) - k.gravity3 * t.s3 -
                             (-k_cos * qd[1] * qd[1] - 0.5 * dm11_dq3 * qd[0] * qd[0]));
  torque += motor_torque_n_m - friction_n_m;
  torque += cogging_.at(p.cogging_cycles_per_rev.cwiseProduct(q_rad_) + p.cogging_phase_rad);
  const double offset = q_rad_[2] - q_rad_[1];
  const double excess =
      offset - std::clamp(offset, -p.max_elbow_offset_rad, p.max_elbow_offset_rad);
  if (excess != 0.0) {
    const double stop =
        p.elbow_stop_stiffness_n_m_per_rad * excess + kElbowStopDamping * (qd[2] - qd[1]);
    torque[2] -= stop;
    torque[1] += stop;
  }

  // M is block diagonal: the yaw joint is decoupled from the (q2, q3) pair.
  const double det23 = k.m22 * k.m33 - m23 * m23;
  const double scale = dt_s / (m11 * det23);  // one division for the whole inverse
  // w = dt M^-1: joint velocity change per unit of joint torque held one step.
  const double w00 = scale * det23;
  const double w11 = scale * m11 * k.m33, w12 = -scale * m11 * m23, w22 = scale * m11 * k.m22;
  const Eigen::Vector3d velocity(qd[0] + w00 * torque[0], qd[1] + w11 * torque[1] + w12 * torque[2],
                                 qd[2] + w12 * torque[1] + w22 * torque[2]);
  qd_rad_per_s_ = velocity;
  const Eigen::Vector3d step_rad = dt_s * velocity;
  q_rad_ += step_rad;
  advanceTrig(step_rad);
  updateTip();
}

namespace {
// Rotates (sine, cosine) of an angle by a small step d: errors below d^7/5040 and d^8/40320,
// under 1e-18 for |d| <= 0.01.
inline void rotateSmall(double d, double& sine, double& cosine) noexcept {
  const double d2 = d * d;
  const double sin_d = d * (1.0 - d2 / 6.0 * (1.0 - d2 / 20.0));
  const double cos_d = 1.0 - d2 / 2.0 * (1.0 - d2 / 12.0 * (1.0 - d2 / 30.0));
  const double s = sine;
  sine = s * cos_d + cosine * sin_d;
  cosine = cosine * cos_d - s * sin_d;
}
}  // namespace

void SerialArmDevice::advanceTrig(const Eigen::Vector3d& step_rad) noexcept {
  // Rotating the cached sines and cosines by the (tiny) step with a short Taylor series costs a
  // fraction of three sincos calls; an exact recomputation now and then bounds the rounding drift.
  if (++steps_since_exact_trig_ >= kExactTrigInterval || std::abs(step_rad[0]) > 0.01 ||
      std::abs(step_rad[1]) > 0.01 || std::abs(step_rad[2]) > 0.01) {
    trig_ = trig(q_rad_);
    steps_since_exact_trig_ = 0;
    return;
  }
  if (step_rad[0] != 0.0) rotateSmall(step_rad[0], trig_.s1, trig_.c1);
  if (step_rad[1] != 0.0) rotateSmall(step_rad[1], trig_.s2, trig_.c2);
  if (step_rad[2] != 0.0) rotateSmall(step_rad[2], trig_.s3, trig_.c3);
}

Eigen::Vector3d SerialArmDevice::cartesianToMotor(const Eigen::Vector3d& force_n) const noexcept {
  return jacobian(trig_).transpose() * force_n;
}

Eigen::Vector3d SerialArmDevice::motorToCartesian(
    const Eigen::Vector3d& torque_n_m) const noexcept {
  return jacobian(trig_).transpose().inverse() * torque_n_m;
}

Eigen::Vector3d SerialArmDevice::readEncoders(const Eigen::Vector3d& noise_counts) const noexcept {
  Eigen::Vector3d measured_q;
  for (int j = 0; j < 3; ++j) {
    measured_q[j] =
        std::round(q_rad_[j] * counts_per_rad_[j] + noise_counts[j]) / counts_per_rad_[j];
  }
  return forwardKinematics(measured_q);
}

bool SerialArmDevice::isReachable(const Eigen::Vector3d& position_m) const noexcept {
  Eigen::Vector3d q;
  return position_m.norm() <= parameters_.specifications.workspace_radius_m &&
         inverseKinematics(position_m, q) &&
         std::abs(q[2] - q[1]) <= parameters_.max_elbow_offset_rad;
}

void SerialArmDevice::resetMechanism(const Eigen::Vector3d& position_m) {
  Eigen::Vector3d q;
  if (position_m.norm() > parameters_.specifications.workspace_radius_m * 1.05 ||
      !inverseKinematics(position_m, q)) {
    throw Error(parameters_.specifications.model_name +
                ": resetState position is outside the workspace (radius " +
                std::to_string(parameters_.specifications.workspace_radius_m * 1000.0) +
                " mm around the centre)");
  }
  q_rad_ = q;
  qd_rad_per_s_.setZero();
  friction_.reset();
  cogging_.reset();
  trig_ = trig(q_rad_);
  steps_since_exact_trig_ = 0;
  updateTip();
}

}  // namespace autograv::sim
