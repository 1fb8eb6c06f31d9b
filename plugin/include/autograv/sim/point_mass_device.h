#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

/// Parameters of PointMassDevice. Defaults are the "sim:omega" preset (omegaParameters()).
struct PointMassParameters {
  DriverParameters driver;
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

  /// Dry friction while sliding, at the end-effector. Unit: [N]
  double coulomb_friction_n = 0.005;
  /// Dry friction to overcome from rest (stiction). Unit: [N]
  double static_friction_n = 0.007;
  /// Unit: [N s/m]
  double viscous_friction_n_s_per_m = 0.02;
  /// Soft mechanical end stop beyond the workspace radius: a spring along the normal and, while in
  /// contact, a drag on the whole velocity (a rubber stop). Units: [N/m], [N s/m]
  double end_stop_stiffness_n_per_m = 2000.0;
  double end_stop_damping_n_s_per_m = 4.0;
  /// Position resolution of each Cartesian axis. Unit: [m]
  double encoder_resolution_m = 1e-5;
  /// Centre of the workspace sphere. Unit: [m]
  Eigen::Vector3d workspace_center_m = Eigen::Vector3d::Zero();
};

/// The "sim:omega" preset: an Omega.3-like device (12 N, 75 mm workspace radius, 14.5 N/mm),
/// 214 g apparent mass at the paper's X_D.
PointMassParameters omegaParameters();

/// The paper's model, eq. (1): M(X) Xdd + G(X) = F with M(X) = ||G(X)||/g I and a smooth,
/// position-dependent, conservative G(X) (PointMassParameters). Added to what the paper models,
/// like a real device: Coulomb friction with stiction and viscous friction, soft end stops,
/// quantized Cartesian encoders with noise, an estimated velocity and actuator saturation.
class PointMassDevice final : public SimulatedDriver {
 public:
  /// Throws autograv::Error for parameters that are not usable (say which one). Not real-time safe.
  PointMassDevice(const PointMassParameters& parameters, std::uint64_t seed);

  /// Real-time safe. Unit: [N]
  Eigen::Vector3d trueGravity(const Eigen::Vector3d& position_m) const override;
  /// ||G(X)||/g times the identity. Real-time safe. Unit: [kg]
  Eigen::Matrix3d trueApparentMass(const Eigen::Vector3d& position_m) const override;
  /// Real-time safe.
  Eigen::Vector3d truePosition_m() const noexcept override { return position_m_; }
  Eigen::Vector3d trueVelocity_m_per_s() const noexcept override { return velocity_m_per_s_; }
  Eigen::Vector3d workspaceCenter_m() const noexcept override {
    return parameters_.workspace_center_m;
  }
  /// Potential energy U(X) whose gradient is G(X) (for tests). Real-time safe. Unit: [J]
  double potentialEnergy_j(const Eigen::Vector3d& position_m) const noexcept;
  const PointMassParameters& parameters() const noexcept { return parameters_; }

 protected:
  void integrateStep(const Eigen::Vector3d& force_n, double dt_s) noexcept override;
  Eigen::Vector3d readEncoders(const Eigen::Vector3d& noise_counts) const noexcept override;
  void resetMechanism(const Eigen::Vector3d& position_m) override;
  Eigen::Vector3d mechanismGravity_n() const noexcept override;
  void applyPayload_kg(double payload_kg) override { payload_kg_ = payload_kg; }

 private:
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m) const noexcept;

  PointMassParameters parameters_;
  double vertical_offset_n_ = 0.0;  // w
  Eigen::Vector3d position_m_;
  Eigen::Vector3d velocity_m_per_s_ = Eigen::Vector3d::Zero();
  double payload_kg_ = 0.0;  // setPayload_kg
};

}  // namespace autograv::sim
