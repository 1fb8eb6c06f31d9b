#pragma once

#include <array>
#include <cstdint>

#include <Eigen/Core>

#include "autograv/sim/friction.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

/// The shape of a delta's grip travel stops about the workspace centre.
enum class TravelStopShape : std::uint8_t {
  /// A wall on each face of a cube of half-width travel_stop_half_width_m (the "sim:falcon"
  /// preset: its published 4-inch cube).
  kBox,
  /// A vertical cylinder (a can): a flat floor and a flat ceiling across gravity at
  /// travel_stop_floor_m and travel_stop_ceiling_m and a round wall of radius
  /// travel_stop_radius_m about the vertical through the centre (the "sim:falcon-can" test
  /// device).
  kCylinder,
};

/// Parameters of DeltaDevice. Defaults are the "sim:falcon" preset (falconParameters()).
///
/// Geometry (CHAI3D frame: x toward the operator, y right, z up). The delta's axis is horizontal
/// and points at the operator, as on the Novint Falcon: the three motors sit in the body, the
/// grip hangs in front of it. The mechanism frame is the CHAI3D frame moved to the centre of the
/// base; leg i lies in the plane spanned by the axis n = +x and its radial direction
/// e_i = [0, cos phi_i, sin phi_i] (phi from +y toward +z). Its upper arm of length a turns about
/// the tangent through the hip H_i = base_radius e_i by the actuated angle theta_i (0: pointing
/// radially out, positive: swung toward the operator); the forearm is a parallelogram of length b
/// from the knee to the grip's platform, whose joints lie at effector_radius e_i from the grip
/// centre p. The parallelograms keep the platform from turning, so each leg says
///   |p - c_i(theta_i)| = b,   c_i = (base_radius - effector_radius + a cos theta_i) e_i
///                                   + a sin theta_i n,
/// three spheres whose intersection is the forward kinematics and whose one-leg solutions are the
/// inverse kinematics, both in closed form.
struct DeltaParameters {
  /// The simulated driver: servo period, encoders, DAC, noise, delays.
  DriverParameters driver;
  /// What the device reports through specifications().
  DeviceSpecifications specifications;

  /// Hip circle, platform joint circle, upper arm a and parallelogram length b. Unit: [m]
  double base_radius_m = 0.0372;
  /// Radius of the platform joint circle. Unit: [m]
  double effector_radius_m = 0.0140;
  /// Length a of each upper arm. Unit: [m]
  double upper_arm_length_m = 0.070;
  /// Length b of each parallelogram. Unit: [m]
  double forearm_length_m = 0.125;
  /// Angles phi_i of the three legs about the axis, from +y toward +z. Unit: [rad]
  Eigen::Vector3d leg_angles_rad = Eigen::Vector3d(1.8325957145940461, -0.2617993877991494,
                                                   3.9269908169872414);  // 105, -15, 225 deg
  /// Distance of the workspace centre in front of the base plane, along the axis. Unit: [m]
  double center_distance_m = 0.110;

  /// Upper arm (with its capstan drum sector): mass, centre of mass along the arm from the hip,
  /// inertia about its centre of mass across the hip axis. Units: [kg], [m], [kg m^2]
  double upper_arm_mass_kg = 0.045;
  /// Centre of mass of an upper arm along it, from the hip. Unit: [m]
  double upper_arm_com_m = 0.025;
  /// Inertia of an upper arm about its centre of mass. Unit: [kg m^2]
  double upper_arm_inertia_kg_m2 = 2.0e-5;
  /// One parallelogram (two rods and their end links): half is lumped at the knee and half at the
  /// platform (the standard reduced delta model; exact for gravity, which acts at the rods'
  /// midpoints, approximate for inertia). Unit: [kg]
  double forearm_mass_kg = 0.012;
  /// Platform (with the ball joints) and the grip on it. Unit: [kg]
  double platform_mass_kg = 0.020;
  /// The grip on the platform. Unit: [kg]
  double grip_mass_kg = 0.060;
  /// Motor rotor inertia reflected through each capstan (J_rotor * ratio^2). Unit: [kg m^2]
  Eigen::Vector3d rotor_inertia_kg_m2 = Eigen::Vector3d::Constant(1.2e-4);

  /// Joint friction of each arm (motor brushes and bearings, capstan, pivots), LuGre in the
  /// joint's units: [N m], [rad/s], [rad]. Its viscous term also stands for the motors' back-EMF
  /// and the amplifier's damping. Default: none at all (falconParameters() sets the levels).
  LuGreParameters friction;

  /// Encoder counts per turn of an arm: 320 slots read in quadrature (4 counts each, assumed)
  /// times the capstan ratio 110 mm / 14.25 mm.
  Eigen::Vector3d joint_counts_per_rev = Eigen::Vector3d::Constant(1280.0 * 0.110 / 0.01425);

  /// Arm end stops (the arms hitting the body): a stiff rubber spring and damper on each actuated
  /// joint beyond [min, max]. Units: [rad], [N m/rad], [N m s/rad]
  Eigen::Vector3d joint_min_rad = Eigen::Vector3d::Constant(-1.309);  // -75 deg
  /// Upper joint limit of each arm. Unit: [rad]
  Eigen::Vector3d joint_max_rad = Eigen::Vector3d::Constant(1.798);  // 103 deg
  /// Stiffness of the arm end stops. Unit: [N m/rad]
  double joint_stop_stiffness_n_m_per_rad = 10.0;
  /// Damping of the arm end stops. Unit: [N m s/rad]
  double joint_stop_damping_n_m_s_per_rad = 0.02;
  /// Stops of the grip's travel about the workspace centre (the grip against the body and the
  /// parallelograms' ball joints at their limits, which keep a real Falcon in its box long before
  /// the arms reach their stops): a rubber wall on each face of a box of this half-width.
  /// 0: none. Units: [m], [N/m], [N s/m]
  double travel_stop_half_width_m = 0.0;
  double travel_stop_stiffness_n_per_m = 2000.0;  ///< Unit: [N/m]
  double travel_stop_damping_n_s_per_m = 5.0;     ///< Unit: [N s/m]
  /// Where the travel stops stand: the box above (travel_stop_half_width_m; 0: none), or a
  /// vertical cylinder whose floor and ceiling are flat across gravity. Both push along the
  /// normal of the face the grip presses into (stiffness times the depth, plus the damping times
  /// the grip's speed along that normal) and nothing along it: no friction on the face.
  TravelStopShape travel_stop_shape = TravelStopShape::kBox;
  /// kCylinder: radius of the round wall about the vertical through the workspace centre.
  /// Unit: [m]
  double travel_stop_radius_m = 0.045;
  /// kCylinder: height of the flat floor relative to the workspace centre (negative). Unit: [m]
  double travel_stop_floor_m = -0.045;
  /// kCylinder: height of the flat ceiling relative to the workspace centre (positive). Unit: [m]
  double travel_stop_ceiling_m = 0.045;
};

/// The "sim:falcon" preset: a Novint-Falcon-like delta (8.9 N, 4-inch cube, > 400 dpi) with
/// joint friction at `friction` (see falconParameters in the .cpp for the levels).
DeltaParameters falconParameters(FrictionLevel friction = FrictionLevel::kTypical);

/// The "sim:falcon-can" test device: sim:falcon's mechanism, friction, actuators, DAC, encoders
/// and delay (falconParameters(friction)) with its grip's travel stops a vertical cylinder of
/// 45 mm radius between a flat floor and a flat ceiling 45 mm below and above the centre, at
/// 3,000 N/m: a flat face across gravity, on which a hold resting on the stop looks converged, as
/// on a device with a base plate or a link landing on a bumper. Inside the can its field is
/// sim:falcon's. Not a model of a real device.
DeltaParameters falconCanParameters(FrictionLevel friction = FrictionLevel::kTypical);

/// A delta parallel mechanism (three actuated upper arms at 120 degrees, parallelogram forearms)
/// with joint-space dynamics in the actuated angles theta, the standard reduced model
///   (I + m_p J^T J) thetadd + m_p J^T Jd thetad + g(theta) + friction = tau_motors + J^T F_hand,
/// where I holds each arm's rotor, upper arm and half forearm about its hip, m_p the platform, the
/// grip and the other forearm halves, and J = dp/dtheta. Its end-effector gravity
/// G(X) = J^-T g(theta(X)) and apparent mass J^-T (I + m_p J^T J) J^-1 = m_p + J^-T I J^-1 are
/// position dependent and anisotropic.
///
/// Published (Novint Falcon data sheet): workspace 4 x 4 x 4 in (101.6 mm cube), force capability
/// > 2 lbf (8.9 N), position resolution > 400 dpi (0.064 mm).
/// Measured by others: libnifalcon's FalconGeometry.h (K. Ouellet, Nonpolynomial Labs) gives the
/// geometry after R. E. Stamper, "A three degree of freedom parallel manipulator with only
/// translational degrees of freedom", PhD thesis, U. Maryland, 1997: upper arm 60 mm, parallelogram
/// 102.5 mm plus 2 x 11.25 mm joint offsets, hips at about 37 mm, platform joints at 14 mm, legs at
/// 105, -15 and 225 degrees; 320-slot motor encoder wheels; 14.25 mm motor shaft on a 110 mm drum.
/// ESTIMATES, not published or measured values: folding Stamper's offsets into the closed-form
/// delta above (forearm 125 mm), the upper arm lengthened to 70 mm so that the published 4-inch
/// cube is reachable (with libnifalcon's 60 mm this form reaches a 95 mm cube), the centre 110 mm
/// in front of the base, every mass and inertia, the motor torque, the friction and the arm
/// stops. They give 1.05 N of gravity at the grip at the centre, 0.6 to 1.25 N over the
/// cube (about 250 g of moving parts, the arms partly hanging from their hips), an apparent mass
/// of about 140 g across the axis and 170 g along it at the centre, and 0.04 mm per encoder count
/// at the grip at the centre (under 0.07 mm over the cube).
/// Not modelled: the limits of the parallelograms' ball joints. With only the arm stops the grip
/// can travel about 110 mm from the centre across the axis (60 mm back, 85 mm forward), more than
/// a real Falcon allows; inside the 4-inch cube this changes nothing.
class DeltaDevice final : public SimulatedDriver {
 public:
  /// Throws autograv::Error for parameters that are not usable (say which one). Not real-time safe.
  DeltaDevice(const DeltaParameters& parameters, std::uint64_t seed);

  /// J^-T g(theta(X)). Throws autograv::Error outside the mechanism's reach. Not real-time safe.
  /// Unit: [N]
  Eigen::Vector3d trueGravity(const Eigen::Vector3d& position_m) const override;
  /// J^-T M(theta) J^-1 at theta(X): symmetric, not isotropic. Throws autograv::Error outside the
  /// mechanism's reach. Not real-time safe. Unit: [kg]
  Eigen::Matrix3d trueApparentMass(const Eigen::Vector3d& position_m) const override;
  /// Real-time safe.
  Eigen::Vector3d truePosition_m() const noexcept override { return tip_m_; }
  /// True, unquantized end-effector velocity. Unit: [m/s]
  Eigen::Vector3d trueVelocity_m_per_s() const noexcept override { return velocity_m_per_s_; }
  Eigen::Vector3d workspaceCenter_m() const noexcept override { return Eigen::Vector3d::Zero(); }
  /// Inside the published 4-inch cube (kBox) or inside the cylinder of travel stops (kCylinder),
  /// where the legs close with every arm clear of its stops. The cube is what bounds a real
  /// Falcon (its parallelograms' ball joints); those limits are not modelled here (see above), so
  /// the mechanism itself would reach further across the axis. Real-time safe.
  bool isReachable(const Eigen::Vector3d& position_m) const noexcept override;
  /// The force the grip's travel stops put on it at `position_m` (relative to the workspace
  /// centre, as truePosition_m()) moving at `velocity_m_per_s`: zero inside them; beyond a face,
  /// along its inward normal, stiffness times the depth beyond the face plus damping times the
  /// velocity out through it (a drag either way while in contact). What integrateStep adds to the
  /// hand's force. Real-time safe. Unit: [N]
  Eigen::Vector3d travelStopForce_n(const Eigen::Vector3d& position_m,
                                    const Eigen::Vector3d& velocity_m_per_s) const noexcept;

  // The model, for tests and reports. All real-time safe.
  /// Grip position relative to the workspace centre; false where the legs cannot close (out of
  /// reach). Unit: [m]
  bool forwardKinematics(const Eigen::Vector3d& theta_rad,
                         Eigen::Vector3d& position_m) const noexcept;
  /// Closed-form inverse on the device's branch (knees outside the forearms); false out of reach.
  bool inverseKinematics(const Eigen::Vector3d& position_m,
                         Eigen::Vector3d& theta_rad) const noexcept;
  /// dp/dtheta at the arm angles theta; NaN where the legs cannot close. Unit: [m/rad]
  Eigen::Matrix3d jacobian(const Eigen::Vector3d& theta_rad) const noexcept;
  /// Joint-space inertia M(theta) = I + m_p J^T J. Unit: [kg m^2]
  Eigen::Matrix3d massMatrix(const Eigen::Vector3d& theta_rad) const noexcept;
  /// g(theta) = dU/dtheta. Unit: [N m]
  Eigen::Vector3d gravityTorque(const Eigen::Vector3d& theta_rad) const noexcept;
  /// Gravitational potential energy (zero at the base centre's height). Unit: [J]
  double potentialEnergy_j(const Eigen::Vector3d& theta_rad) const noexcept;
  /// Unit: [J]
  double kineticEnergy_j(const Eigen::Vector3d& theta_rad,
                         const Eigen::Vector3d& thetad_rad_per_s) const noexcept;
  /// Unit: [rad], [rad/s]
  const Eigen::Vector3d& jointAngles_rad() const noexcept { return theta_rad_; }
  /// Arm angular velocities. Unit: [rad/s]
  const Eigen::Vector3d& jointVelocities_rad_per_s() const noexcept { return thetad_rad_per_s_; }
  /// The parameters the device was made with.
  const DeltaParameters& parameters() const noexcept { return parameters_; }

 protected:
  /// `motor_command`: each arm's motor torque. Units: [N m], [N], [s]
  void integrateStep(const Eigen::Vector3d& motor_command, const Eigen::Vector3d& external_force_n,
                     double dt_s) noexcept override;
  /// J^T F at the current pose. Unit: [N m]
  Eigen::Vector3d cartesianToMotor(const Eigen::Vector3d& force_n) const noexcept override;
  /// J^-T tau at the current pose. Unit: [N]
  Eigen::Vector3d motorToCartesian(const Eigen::Vector3d& command) const noexcept override;
  Eigen::Vector3d readEncoders(const Eigen::Vector3d& noise_counts) const noexcept override;
  void resetMechanism(const Eigen::Vector3d& position_m) override;
  Eigen::Vector3d mechanismGravity_n() const noexcept override;
  void applyPayload_kg(double payload_kg) override;

 private:
  /// Everything the dynamics need at one pose, in the mechanism frame.
  struct Pose {
    Eigen::Vector3d sin_theta = Eigen::Vector3d::Zero();
    Eigen::Vector3d cos_theta = Eigen::Vector3d::Zero();
    Eigen::Vector3d tip_m = Eigen::Vector3d::Zero();
    std::array<Eigen::Vector3d, 3> forearm{};         // d_i = p - c_i, each of length b
    std::array<Eigen::Vector3d, 3> knee_rate{};       // dc_i/dtheta_i
    Eigen::Vector3d drive = Eigen::Vector3d::Zero();  // diagonal of B: d_i . dc_i/dtheta_i
    Eigen::Matrix3d constraint_inverse = Eigen::Matrix3d::Zero();  // A^-1, A's rows d_i^T
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();            // A^-1 B
  };
  Eigen::Vector3d kneeCentre(int leg, double sin_theta, double cos_theta) const noexcept;
  bool intersectLegs(const std::array<Eigen::Vector3d, 3>& knee,
                     Eigen::Vector3d& tip_m) const noexcept;
  /// Forward kinematics and the pose's derivatives; false out of reach or at a singularity.
  bool solvePose(const Eigen::Vector3d& theta_rad, Pose& out) const noexcept;
  /// The pose at a position; throws autograv::Error out of reach (`what` names the caller).
  void requirePose(const Eigen::Vector3d& position_m, Pose& out, const char* what) const;
  Eigen::Matrix3d massMatrix(const Pose& pose) const noexcept;
  Eigen::Vector3d gravityTorque(const Pose& pose) const noexcept;

  DeltaParameters parameters_;
  std::array<Eigen::Vector3d, 3> radial_{};  // e_i
  Eigen::Vector3d arm_inertia_kg_m2_;        // I: rotor, upper arm and half forearm about the hip
  double moving_mass_kg_ = 0.0;              // m_p: platform, grip and the forearm halves there
  Eigen::Vector3d arm_gravity_n_m_;          // g(theta)_i from the arm = -this_i sin theta_i
  Eigen::Vector3d home_tip_m_;               // workspace centre in the mechanism frame
  Eigen::Vector3d counts_per_rad_;
  Eigen::Vector3d theta_rad_;
  Eigen::Vector3d thetad_rad_per_s_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d tip_m_ = Eigen::Vector3d::Zero();  // relative to the workspace centre
  Eigen::Vector3d velocity_m_per_s_ = Eigen::Vector3d::Zero();
  Pose pose_;  // of theta_rad_
  LuGreFriction friction_;
};

}  // namespace autograv::sim
