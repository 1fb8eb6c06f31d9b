#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "autograv/sim/friction.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

/// Joint friction of the "sim:omni" preset at `level` (LuGre per joint, see the .cpp for the
/// sources and the assumptions).
LuGreParameters omniJointFriction(FrictionLevel level);

/// Parameters of SerialArmDevice. Defaults are the "sim:omni" preset (omniParameters()).
///
/// Joints (CHAI3D frame, z up, x toward the operator):
///   q1  turret yaw about the vertical axis through the shoulder (positive turns the tip to +y),
///   q2  upper-arm pitch from the horizontal (positive raises the elbow),
///   q3  absolute forearm angle, measured from the downward vertical (positive swings the tip
///       toward the operator). As on every PHANToM, the forearm is driven from the base through
///       a cable/parallelogram, so its encoder measures q3 against the ground, not against the
///       upper arm (Cavusoglu, Feygin, Tendick 2002; Jarillo-Silva et al. 2009).
/// Tip in the shoulder frame: r = l1 cos q2 + l2 sin q3 (horizontal reach),
/// h = l1 sin q2 - l2 cos q3 (height), p = [r cos q1, r sin q1, h]; the reported position is
/// that minus the tip position at `home_joint_angles_rad`, so the home pose is the origin.
struct SerialArmParameters {
  /// The simulated driver: servo period, encoders, DAC, noise, delays.
  DriverParameters driver;
  /// What the device reports through specifications().
  DeviceSpecifications specifications;

  /// Link lengths l1 (shoulder to elbow) and l2 (elbow to gimbal centre). Unit: [m]
  double upper_arm_length_m = 0.13335;
  /// Length l2, elbow to gimbal centre. Unit: [m]
  double forearm_length_m = 0.13335;
  /// Upper arm: mass, centre of mass along the link from the shoulder, inertia about its centre
  /// of mass across and along the link. Units: [kg], [m], [kg m^2]
  double upper_arm_mass_kg = 0.030;
  /// Upper arm centre of mass along the link, from the shoulder. Unit: [m]
  double upper_arm_com_m = 0.050;
  /// Upper arm inertia about its centre of mass, across the link. Unit: [kg m^2]
  double upper_arm_inertia_kg_m2 = 5.0e-5;
  /// Upper arm inertia along the link. Unit: [kg m^2]
  double upper_arm_axial_inertia_kg_m2 = 4.0e-6;
  /// Forearm, same meaning, centre of mass measured from the elbow.
  double forearm_mass_kg = 0.022;
  /// Forearm centre of mass along the link, from the elbow. Unit: [m]
  double forearm_com_m = 0.060;
  /// Forearm inertia about its centre of mass, across the link. Unit: [kg m^2]
  double forearm_inertia_kg_m2 = 3.5e-5;
  /// Forearm inertia along the link. Unit: [kg m^2]
  double forearm_axial_inertia_kg_m2 = 2.0e-6;
  /// Gimbal and stylus, lumped at the tip. Unit: [kg]
  double tip_mass_kg = 0.020;
  /// Turret (with the two arm motors it carries) about the vertical axis. Unit: [kg m^2]
  double turret_inertia_kg_m2 = 4.0e-4;
  /// Motor rotor inertia reflected through each capstan (J_rotor * ratio^2). Unit: [kg m^2]
  Eigen::Vector3d rotor_inertia_kg_m2 = Eigen::Vector3d(5.0e-5, 5.0e-5, 5.0e-5);

  /// Joint friction: LuGre dry friction (pre-sliding, Stribeck) and viscous friction. The viscous
  /// term stands for motor back-EMF and amplifier damping too: about 0.35 N s/m at the tip, which
  /// is what lets a 1 kHz loop render the quoted 1 N/mm (a sampled spring k needs physical
  /// damping above k T / 2 to stay passive). Units: [N m], [rad/s], [N m/rad], [N m s/rad]
  LuGreParameters friction = omniJointFriction(FrictionLevel::kTypical);
  /// Cogging and torque ripple of each motor, seen at its joint as a position-periodic torque
  /// A sin(N q + phase): amplitude A, N cycles per joint revolution, phase. Units: [N m], [rad]
  Eigen::Vector3d cogging_amplitude_n_m = Eigen::Vector3d::Constant(2.5e-4);
  /// Cogging cycles per joint revolution (N).
  Eigen::Vector3d cogging_cycles_per_rev = Eigen::Vector3d(186.0, 186.0, 186.0);
  /// Cogging phase of each joint. Unit: [rad]
  Eigen::Vector3d cogging_phase_rad = Eigen::Vector3d(0.0, 2.1, 4.2);

  /// Encoder counts per joint revolution (motor encoder counts times the capstan ratio).
  Eigen::Vector3d joint_counts_per_rev = Eigen::Vector3d(15360.0, 15360.0, 15360.0);
  /// Pose whose tip is the origin: the centre of the workspace sphere. Unit: [rad]
  Eigen::Vector3d home_joint_angles_rad = Eigen::Vector3d(0.0, 0.4802, 0.1634);

  /// Soft mechanical end stop beyond the workspace radius (Cartesian, applied through J^T): a
  /// spring along the normal and, while in contact, a drag on the whole tip velocity.
  /// Units: [N/m], [N s/m]
  double end_stop_stiffness_n_per_m = 1500.0;
  /// Drag on the whole tip velocity while in contact with the end stop. Unit: [N s/m]
  double end_stop_damping_n_s_per_m = 1.5;
  /// The forearm cannot fold onto or stretch in line with the upper arm: |q3 - q2| is limited by
  /// a joint stop (the kinematics are singular at +-pi/2). Units: [rad], [N m/rad]
  double max_elbow_offset_rad = 1.35;
  /// Stiffness of the elbow stop. Unit: [N m/rad]
  double elbow_stop_stiffness_n_m_per_rad = 5.0;
};

/// The "sim:omni" preset: a PHANToM-Omni-like 3R arm (3.3 N, about 0.10 m workspace radius) with
/// joint friction at `friction`.
SerialArmParameters omniParameters(FrictionLevel friction = FrictionLevel::kTypical);

/// A 3R arm with PHANToM kinematics and rigid-body dynamics in joint space,
///   M(q) qdd + C(q, qd) qd + g(q) + friction(qd) = J(q)^T (F_actuators + F_hand),
/// whose end-effector gravity G(X) = J^-T g(q(X)) and apparent mass J^-T M(q) J^-1 are
/// position dependent and anisotropic: the paper's isotropic point-mass model is only an
/// approximation of it, as it is of a real device.
///
/// Sources: kinematics (l1 = l2 = 133.35 mm, absolute forearm angle) as in A. Jarillo-Silva,
/// O. Dominguez-Ramirez, V. Parra-Vega, J. Ordaz-Oliver, "PHANToM OMNI haptic device: kinematic
/// and manipulability", CERMA 2009; dynamic structure (lumped links, base-driven forearm) as in
/// M. C. Cavusoglu, D. Feygin, F. Tendick, "A critical study of the mechanical and electrical
/// properties of the PHANToM haptic interface", Presence 11(6), 2002 (the paper's ref. [7]).
/// ESTIMATES, not published Omni values: every mass, centre of mass, inertia, friction level and
/// capstan ratio above. They were chosen so that the apparent mass at the tip is about the 45 g
/// SensAble quotes for the Omni, the tip gravity is about 0.5 N (within the Omni's 0.88 N
/// continuous force), the breakaway force at the tip is 40-120 mN depending on the direction
/// (within SensAble's < 0.26 N backdrive friction), and the encoders resolve about 0.055 mm at
/// the tip (SensAble's nominal "> 450 dpi").
class SerialArmDevice final : public SimulatedDriver {
 public:
  /// Throws autograv::Error for parameters that are not usable (say which one). Not real-time safe.
  SerialArmDevice(const SerialArmParameters& parameters, std::uint64_t seed);

  /// J^-T g(q(X)). Throws autograv::Error outside the arm's reach. Not real-time safe. Unit: [N]
  Eigen::Vector3d trueGravity(const Eigen::Vector3d& position_m) const override;
  /// J^-T M(q) J^-1 at q(X): symmetric, not isotropic. Throws autograv::Error outside the arm's
  /// reach. Not real-time safe. Unit: [kg]
  Eigen::Matrix3d trueApparentMass(const Eigen::Vector3d& position_m) const override;
  /// Real-time safe.
  Eigen::Vector3d truePosition_m() const noexcept override { return tip_m_; }
  /// True, unquantized end-effector velocity. Unit: [m/s]
  Eigen::Vector3d trueVelocity_m_per_s() const noexcept override;
  Eigen::Vector3d workspaceCenter_m() const noexcept override { return Eigen::Vector3d::Zero(); }
  /// Inside the workspace sphere, on the arm's inverse-kinematics branch, and with the elbow
  /// offset |q3 - q2| within its joint stop. Real-time safe.
  bool isReachable(const Eigen::Vector3d& position_m) const noexcept override;

  // The model, for tests and reports. All real-time safe.
  /// Tip position. Unit: [m]
  Eigen::Vector3d forwardKinematics(const Eigen::Vector3d& q_rad) const noexcept;
  /// Analytic inverse on the device's branch (tip in front of the yaw axis, elbow offset within
  /// +-pi/2). False when `position_m` is out of reach.
  bool inverseKinematics(const Eigen::Vector3d& position_m, Eigen::Vector3d& q_rad) const noexcept;
  /// d(tip)/dq. Unit: [m/rad]
  Eigen::Matrix3d jacobian(const Eigen::Vector3d& q_rad) const noexcept;
  /// Joint-space inertia M(q). Unit: [kg m^2]
  Eigen::Matrix3d massMatrix(const Eigen::Vector3d& q_rad) const noexcept;
  /// g(q) = dU/dq. Unit: [N m]
  Eigen::Vector3d gravityTorque(const Eigen::Vector3d& q_rad) const noexcept;
  /// C(q, qd) qd. Unit: [N m]
  Eigen::Vector3d coriolisTorque(const Eigen::Vector3d& q_rad,
                                 const Eigen::Vector3d& qd_rad_per_s) const noexcept;
  /// Gravitational potential energy (zero with both links horizontal). Unit: [J]
  double potentialEnergy_j(const Eigen::Vector3d& q_rad) const noexcept;
  /// Unit: [J]
  double kineticEnergy_j(const Eigen::Vector3d& q_rad,
                         const Eigen::Vector3d& qd_rad_per_s) const noexcept;
  /// Unit: [rad], [rad/s]
  const Eigen::Vector3d& jointAngles_rad() const noexcept { return q_rad_; }
  /// Joint angular velocities. Unit: [rad/s]
  const Eigen::Vector3d& jointVelocities_rad_per_s() const noexcept { return qd_rad_per_s_; }
  /// The parameters the device was made with.
  const SerialArmParameters& parameters() const noexcept { return parameters_; }

 protected:
  void integrateStep(const Eigen::Vector3d& motor_torque_n_m,
                     const Eigen::Vector3d& external_force_n, double dt_s) noexcept override;
  /// J^T F at the current pose. Unit: [N m]
  Eigen::Vector3d cartesianToMotor(const Eigen::Vector3d& force_n) const noexcept override;
  /// J^-T tau at the current pose. Unit: [N]
  Eigen::Vector3d motorToCartesian(const Eigen::Vector3d& torque_n_m) const noexcept override;
  Eigen::Vector3d readEncoders(const Eigen::Vector3d& noise_counts) const noexcept override;
  void resetMechanism(const Eigen::Vector3d& position_m) override;
  Eigen::Vector3d mechanismGravity_n() const noexcept override;
  void applyPayload_kg(double payload_kg) override;

 private:
  struct Trig {
    double s1, c1, s2, c2, s3, c3;
  };
  static Trig trig(const Eigen::Vector3d& q_rad) noexcept;
  Eigen::Vector3d tipInShoulderFrame(const Trig& t) const noexcept;
  Eigen::Matrix3d jacobian(const Trig& t) const noexcept;
  Eigen::Matrix3d massMatrix(const Trig& t) const noexcept;
  Eigen::Vector3d gravityTorque(const Trig& t) const noexcept;
  Eigen::Vector3d coriolisTorque(const Trig& t, const Eigen::Vector3d& qd) const noexcept;
  void updateTip() noexcept;
  void advanceTrig(const Eigen::Vector3d& step_rad) noexcept;

  static constexpr int kExactTrigInterval = 1024;

  // Constants of the dynamics folded from the parameters (see massMatrix in the .cpp).
  struct Inertia {
    double l1 = 0, l2 = 0, a3 = 0, m3 = 0, mt = 0;
    double yaw = 0, upper_yaw = 0, forearm_yaw = 0;  // M11 = yaw + upper_yaw c2^2 + ...
    double m22 = 0, m33 = 0, coupling = 0;           // M23 = coupling sin(q3 - q2)
    double gravity2 = 0, gravity3 = 0;               // g(q) = [0, gravity2 c2, gravity3 s3]
  };

  SerialArmParameters parameters_;
  Eigen::Vector3d home_tip_m_;  // tip at the home pose, in the shoulder frame
  Eigen::Vector3d q_rad_;
  Eigen::Vector3d qd_rad_per_s_ = Eigen::Vector3d::Zero();
  Trig trig_{};  // sines and cosines of q_rad_
  int steps_since_exact_trig_ = 0;
  Eigen::Vector3d tip_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d counts_per_rad_;
  Inertia inertia_;
  LuGreFriction friction_;
  CoggingRipple cogging_;
};

}  // namespace autograv::sim
