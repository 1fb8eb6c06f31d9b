#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "autograv/sim/friction.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

/// Friction of the "sim:omega" preset at `level`, per Cartesian axis (see the .cpp for the
/// assumptions).
LuGreParameters omegaAxisFriction(FrictionLevel level);

/// The shape of a point-mass device's workspace: where its end stops stand.
enum class WorkspaceShape : std::uint8_t {
  kSphere,     ///< A sphere of specifications.workspace_radius_m (the Omega-like preset).
  kBox,        ///< A box of half-widths workspace_half_extents_m: a wall on each face.
  kEllipsoid,  ///< An ellipsoid of semi-axes workspace_half_extents_m.
};

/// Parameters of PointMassDevice. Defaults are the "sim:omega" preset (omegaParameters()).
struct PointMassParameters {
  /// The simulated driver: servo period, encoders, DAC, noise, delays.
  DriverParameters driver;
  /// What the device reports through specifications().
  DeviceSpecifications specifications;

  /// The apparent gravity is the gradient of a smooth potential, as it is for any mechanism:
  ///   U(X) = w z + 1/2 X^T K X + c_r (x^2 + y^2) z + c_z z^3
  ///   G(X) = grad U = w e_z + K X + [2 c_r x z, 2 c_r y z, c_r (x^2 + y^2) + 3 c_z z^2]
  /// with X relative to the workspace centre. K is symmetric. Unit: [N/m]
  Eigen::Matrix3d gravity_gradient_n_per_m;
  /// c_r. Unit: [N/m^2]
  double radial_curvature_n_per_m2 = 30.0;
  /// c_z. Unit: [N/m^2]
  double vertical_curvature_n_per_m2 = 20.0;
  /// w is chosen so that the apparent mass ||G||/g at `reference_point_m` is `reference_mass_kg`.
  Eigen::Vector3d reference_point_m = Eigen::Vector3d(0.0, 0.0, -0.030);
  /// Unit: [kg]
  double reference_mass_kg = 0.214;

  /// Inertia reflected to the end-effector, symmetric positive definite and position dependent:
  ///   M(X) = m_b I + sum_i m_r (1 + u_i . (X - c) / L)^2 u_i u_i^T
  /// m_b: handle, links and parallelograms moving with the end-effector; for each of the three
  /// motors, m_r: its rotor and arm inertia reflected along u_i, the direction its arm drives the
  /// end-effector (unit vectors, columns of actuator_directions), growing as the arm's lever
  /// shortens over a length L. Units: [kg], [kg], [m]
  double base_mass_kg = 0.12;
  /// m_r: each motor's rotor and arm inertia reflected along its direction. Unit: [kg]
  double rotor_mass_kg = 0.07;
  /// u_i: the direction each motor drives the end-effector (columns, unit vectors).
  Eigen::Matrix3d actuator_directions = Eigen::Matrix3d::Identity();
  /// L: the lever length over which m_r grows. Unit: [m]
  double inertia_length_m = 0.12;

  /// Friction per Cartesian axis (LuGre: pre-sliding, Stribeck, viscous). Units: [N], [m/s],
  /// [N/m], [N s/m]
  LuGreParameters friction = omegaAxisFriction(FrictionLevel::kTypical);
  /// Cogging and torque ripple per axis, a position-periodic force A sin(2 pi x / period + phase).
  /// Units: [N], [m], [rad]
  Eigen::Vector3d cogging_amplitude_n = Eigen::Vector3d::Constant(1.5e-3);
  /// Period of the cogging along each axis. Unit: [m]
  Eigen::Vector3d cogging_period_m = Eigen::Vector3d::Constant(0.004);
  /// Phase of the cogging along each axis. Unit: [rad]
  Eigen::Vector3d cogging_phase_rad = Eigen::Vector3d(0.0, 2.1, 4.2);
  /// Soft mechanical end stop beyond the workspace radius: a spring along the normal and, while in
  /// contact, a drag on the whole velocity (a rubber stop). Units: [N/m], [N s/m]
  double end_stop_stiffness_n_per_m = 2000.0;
  /// Drag on the whole velocity while in contact with the end stop. Unit: [N s/m]
  double end_stop_damping_n_s_per_m = 4.0;
  /// Position resolution of each Cartesian axis. Unit: [m]
  double encoder_resolution_m = 1e-5;
  /// Centre of the workspace. Unit: [m]
  Eigen::Vector3d workspace_center_m = Eigen::Vector3d(0.0, 0.0, -0.030);
  /// Where the end stops stand: a sphere of specifications.workspace_radius_m, or a box or an
  /// ellipsoid of workspace_half_extents_m around the centre.
  WorkspaceShape workspace_shape = WorkspaceShape::kSphere;
  /// Half-widths of the box, or semi-axes of the ellipsoid, along x, y, z. Unit: [m]
  Eigen::Vector3d workspace_half_extents_m = Eigen::Vector3d::Constant(0.055);
  /// A smooth holding force that is not the gradient of a potential, added to G(X): amplitude a
  /// (per component), wavelength L and phases phi of
  ///   S(X) = [a_x sin(2 pi y / L + phi_x), a_y sin(2 pi z / L + phi_y), a_z sin(2 pi x / L +
  ///   phi_z)]
  /// (X from the workspace centre), whose curl is not zero: what unequal motor gains on a
  /// parallel mechanism, or a driver effect nobody modelled, leave in the force that holds the
  /// end-effector still. A device built to break a map that assumes a potential. Zero on every
  /// preset that stands for a real model. Units: [N], [m], [rad]
  Eigen::Vector3d swirl_amplitude_n = Eigen::Vector3d::Zero();
  /// L above. Unit: [m]
  double swirl_wavelength_m = 0.3;
  /// phi above. Unit: [rad]
  Eigen::Vector3d swirl_phase_rad = Eigen::Vector3d(0.4, 1.3, -0.7);
};

/// The "sim:omega" preset: an Omega.3-like device (12 N, 14.5 N/mm, a 55 mm workspace radius
/// centred on the paper's X_D), |G|/g = 214 g at X_D, friction at `friction`.
PointMassParameters omegaParameters(FrictionLevel friction = FrictionLevel::kTypical);

/// The "sim:swirl-cube" test device: the Omega-like mechanism in a box of +/-40 mm (stops on six
/// flat faces, so corners and edges), whose holding force has a swirl of 60 mN per component
/// over a 0.1 m wavelength (about 3 % of |G|) that no potential explains. Built to break what only
/// our model devices satisfy: a conservative field and a round workspace. Not a model of any real
/// device.
PointMassParameters swirlCubeParameters(FrictionLevel friction = FrictionLevel::kTypical);
/// The "sim:swirl-ellipsoid" test device: the same mechanism in an ellipsoid of 80 x 60 x 35 mm
/// semi-axes (an Omni's 160 x 120 x 70 mm workspace), with the same kind of swirl.
PointMassParameters swirlEllipsoidParameters(FrictionLevel friction = FrictionLevel::kTypical);

/// The paper's model, eq. (1), M(X) Xdd + C(X, Xd) Xd + G(X) = F, with a smooth,
/// position-dependent, conservative G(X), and an inertia M(X) of its own (rotor and arm inertia
/// reflected to the end-effector, anisotropic and position dependent), not the paper's
/// assumption ||G(X)||/g I. ASSUMPTION: the Omega.3 is a parallel (delta) mechanism; this model
/// keeps its Cartesian structure and applies friction, cogging and the motors per Cartesian axis.
/// Added to what the paper models, like a real device: LuGre friction, cogging, soft end stops,
/// quantized Cartesian encoders with noise, an estimated velocity, and (in SimulatedDriver) force
/// DAC quantization, one servo period of transport delay and actuator saturation.
class PointMassDevice final : public SimulatedDriver {
 public:
  /// Throws autograv::Error for parameters that are not usable (say which one). Not real-time safe.
  PointMassDevice(const PointMassParameters& parameters, std::uint64_t seed);

  /// Real-time safe. Unit: [N]
  Eigen::Vector3d trueGravity(const Eigen::Vector3d& position_m) const override;
  /// M(X). Real-time safe. Unit: [kg]
  Eigen::Matrix3d trueApparentMass(const Eigen::Vector3d& position_m) const override;
  /// Real-time safe.
  Eigen::Vector3d truePosition_m() const noexcept override { return position_m_; }
  /// True, unquantized end-effector velocity. Unit: [m/s]
  Eigen::Vector3d trueVelocity_m_per_s() const noexcept override { return velocity_m_per_s_; }
  Eigen::Vector3d workspaceCenter_m() const noexcept override {
    return parameters_.workspace_center_m;
  }
  /// Inside the workspace's shape (WorkspaceShape). Real-time safe.
  bool isReachable(const Eigen::Vector3d& position_m) const noexcept override;
  /// Potential energy U(X) whose gradient is G(X) without its swirl (for tests). Real-time
  /// safe. Unit: [J]
  double potentialEnergy_j(const Eigen::Vector3d& position_m) const noexcept;
  /// The parameters the device was made with.
  const PointMassParameters& parameters() const noexcept { return parameters_; }

 protected:
  void integrateStep(const Eigen::Vector3d& motor_force_n, const Eigen::Vector3d& external_force_n,
                     double dt_s) noexcept override;
  /// The motors act per Cartesian axis: the identity.
  Eigen::Vector3d cartesianToMotor(const Eigen::Vector3d& force_n) const noexcept override {
    return force_n;
  }
  Eigen::Vector3d motorToCartesian(const Eigen::Vector3d& command) const noexcept override {
    return command;
  }
  Eigen::Vector3d readEncoders(const Eigen::Vector3d& noise_counts) const noexcept override;
  void resetMechanism(const Eigen::Vector3d& position_m) override;
  Eigen::Vector3d mechanismGravity_n() const noexcept override;
  void applyPayload_kg(double payload_kg) override { payload_kg_ = payload_kg; }

 private:
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m) const noexcept;
  /// How far `from_center_m` presses into the stops, along their outward normal (per face for a
  /// box): zero inside. Real-time safe. Unit: [m]
  Eigen::Vector3d stopPenetration_m(const Eigen::Vector3d& from_center_m) const noexcept;
  Eigen::Matrix3d massAt(const Eigen::Vector3d& position_m) const noexcept;

  PointMassParameters parameters_;
  double vertical_offset_n_ = 0.0;  // w
  Eigen::Vector3d position_m_;
  Eigen::Vector3d velocity_m_per_s_ = Eigen::Vector3d::Zero();
  LuGreFriction friction_;
  CoggingRipple cogging_;
  double payload_kg_ = 0.0;  // setPayload_kg
};

}  // namespace autograv::sim
