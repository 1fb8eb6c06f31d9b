#include "autograv/sim/point_mass_device.h"

#include <cmath>
#include <string>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv::sim {

namespace {

// Below this apparent mass the model would stop being a device; the field never comes close.
constexpr double kMinimumMass_kg = 0.01;

void requireNonNegative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0) {
    throw Error(std::string("sim point-mass device: ") + name + " must be finite and >= 0");
  }
}

void requirePositive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0.0) {
    throw Error(std::string("sim point-mass device: ") + name + " must be finite and > 0");
  }
}

}  // namespace

PointMassParameters omegaParameters() {
  PointMassParameters parameters;
  parameters.specifications.model_name = "sim:omega";
  parameters.specifications.manufacturer = "autograv simulation (Force Dimension omega.3-like)";
  parameters.specifications.serial_number = "SIM-OMEGA-0001";
  parameters.specifications.max_linear_force_n = 12.0;
  parameters.specifications.max_linear_stiffness_n_per_m = 14500.0;
  parameters.specifications.max_linear_damping_n_s_per_m = 20.0;
  parameters.specifications.workspace_radius_m = 0.075;
  // A symmetric gradient (the field is conservative) of 3-10 N/m per entry: the 214 g of the
  // paper's point become about 150-290 g across the workspace, with x/y components of a few
  // tenths of a newton.
  parameters.gravity_gradient_n_per_m << 10.0, 2.0, 6.0,  //
      2.0, 5.0, -3.0,                                     //
      6.0, -3.0, -5.0;
  // Force Dimension's SDK estimates velocity over a 20 ms window by default.
  parameters.driver.velocity_window_s = 0.02;
  parameters.driver.velocity_time_constant_s = 0.001;
  parameters.driver.noise_sigma_counts = 0.05;
  parameters.driver.noise_correlation_time_s = 0.01;
  return parameters;
}

PointMassDevice::PointMassDevice(const PointMassParameters& parameters, std::uint64_t seed)
    : SimulatedDriver(parameters.specifications, parameters.driver, seed),
      parameters_(parameters),
      position_m_(parameters.workspace_center_m) {
  const Eigen::Matrix3d& k = parameters.gravity_gradient_n_per_m;
  if (!k.allFinite() || !k.isApprox(k.transpose(), 1e-12)) {
    throw Error(
        "sim point-mass device: gravity_gradient_n_per_m must be finite and symmetric (the "
        "gravity field of a mechanism is the gradient of its potential energy)");
  }
  if (!std::isfinite(parameters.radial_curvature_n_per_m2) ||
      !std::isfinite(parameters.vertical_curvature_n_per_m2)) {
    throw Error("sim point-mass device: curvatures must be finite");
  }
  if (!parameters.reference_point_m.allFinite() || !parameters.workspace_center_m.allFinite()) {
    throw Error("sim point-mass device: reference_point_m and workspace_center_m must be finite");
  }
  requirePositive(parameters.reference_mass_kg, "reference_mass_kg");
  requireNonNegative(parameters.coulomb_friction_n, "coulomb_friction_n");
  requireNonNegative(parameters.static_friction_n, "static_friction_n");
  if (parameters.static_friction_n < parameters.coulomb_friction_n) {
    throw Error("sim point-mass device: static_friction_n must be >= coulomb_friction_n");
  }
  requireNonNegative(parameters.viscous_friction_n_s_per_m, "viscous_friction_n_s_per_m");
  requirePositive(parameters.end_stop_stiffness_n_per_m, "end_stop_stiffness_n_per_m");
  requireNonNegative(parameters.end_stop_damping_n_s_per_m, "end_stop_damping_n_s_per_m");
  requirePositive(parameters.encoder_resolution_m, "encoder_resolution_m");

  // Solve for w: ||G(X_ref)|| = m_ref g, with G_z = w + (rest of G_z).
  vertical_offset_n_ = 0.0;
  const Eigen::Vector3d rest = gravityAt(parameters.reference_point_m);
  const double target_n = parameters.reference_mass_kg * kStandardGravity;
  const double horizontal2 = rest.x() * rest.x() + rest.y() * rest.y();
  if (horizontal2 >= target_n * target_n) {
    throw Error(
        "sim point-mass device: the gradient's horizontal force at reference_point_m exceeds "
        "reference_mass_kg * g; lower gravity_gradient_n_per_m");
  }
  vertical_offset_n_ = std::sqrt(target_n * target_n - horizontal2) - rest.z();

  // The field must keep the mass positive everywhere the end-effector can go (end stops included).
  const double reach_m = parameters.specifications.workspace_radius_m * 1.2;
  for (int ix = -4; ix <= 4; ++ix) {
    for (int iy = -4; iy <= 4; ++iy) {
      for (int iz = -4; iz <= 4; ++iz) {
        const Eigen::Vector3d offset = Eigen::Vector3d(ix, iy, iz) * (reach_m / 4.0);
        if (offset.norm() > reach_m) continue;
        const Eigen::Vector3d g = gravityAt(parameters.workspace_center_m + offset);
        if (g.z() <= 0.0 || g.norm() / kStandardGravity < 2.0 * kMinimumMass_kg) {
          throw Error(
              "sim point-mass device: the gravity field must point up with a mass above 20 g "
              "over the whole workspace; lower the gradient or the curvatures");
        }
      }
    }
  }
}

Eigen::Vector3d PointMassDevice::gravityAt(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d p = position_m - parameters_.workspace_center_m;
  const double c_r = parameters_.radial_curvature_n_per_m2;
  const double c_z = parameters_.vertical_curvature_n_per_m2;
  Eigen::Vector3d g = parameters_.gravity_gradient_n_per_m * p;
  g.x() += 2.0 * c_r * p.x() * p.z();
  g.y() += 2.0 * c_r * p.y() * p.z();
  g.z() += vertical_offset_n_ + c_r * (p.x() * p.x() + p.y() * p.y()) + 3.0 * c_z * p.z() * p.z();
  g.z() += payload_kg_ * kStandardGravity;  // a point load; the mass |G|/g follows
  return g;
}

double PointMassDevice::potentialEnergy_j(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d p = position_m - parameters_.workspace_center_m;
  const double c_r = parameters_.radial_curvature_n_per_m2;
  const double c_z = parameters_.vertical_curvature_n_per_m2;
  return vertical_offset_n_ * p.z() + 0.5 * p.dot(parameters_.gravity_gradient_n_per_m * p) +
         c_r * (p.x() * p.x() + p.y() * p.y()) * p.z() + c_z * p.z() * p.z() * p.z();
}

Eigen::Vector3d PointMassDevice::trueGravity(const Eigen::Vector3d& position_m) const {
  return loadedGravity_n(gravityAt(position_m));
}

Eigen::Matrix3d PointMassDevice::trueApparentMass(const Eigen::Vector3d& position_m) const {
  const double mass_kg = std::max(kMinimumMass_kg, gravityAt(position_m).norm() / kStandardGravity);
  return mass_kg * Eigen::Matrix3d::Identity();
}

Eigen::Vector3d PointMassDevice::mechanismGravity_n() const noexcept {
  return gravityAt(position_m_);
}

void PointMassDevice::integrateStep(const Eigen::Vector3d& force_n, double dt_s) noexcept {
  const Eigen::Vector3d gravity_n = gravityAt(position_m_);
  const double mass_kg = std::max(kMinimumMass_kg, gravity_n.norm() / kStandardGravity);
  Eigen::Vector3d net_n =
      force_n - gravity_n - parameters_.viscous_friction_n_s_per_m * velocity_m_per_s_;

  const Eigen::Vector3d from_center = position_m_ - parameters_.workspace_center_m;
  const double radius_m = parameters_.specifications.workspace_radius_m;
  const double distance2 = from_center.squaredNorm();
  if (distance2 > radius_m * radius_m) {
    const double distance_m = std::sqrt(distance2);
    const Eigen::Vector3d normal = from_center / distance_m;
    const double penetration_m = distance_m - radius_m;
    // The rubber stop pushes back along the normal and drags on the whole velocity, so an
    // end-effector resting on it settles instead of sliding round the sphere.
    net_n -= parameters_.end_stop_stiffness_n_per_m * penetration_m * normal +
             parameters_.end_stop_damping_n_s_per_m * velocity_m_per_s_;
    end_stop_hit_ = true;
  }

  // Semi-implicit Euler; dry friction enters as an impulse bounded by the friction level, which
  // sticks exactly (velocity 0) instead of chattering around zero.
  const double impulse_scale = dt_s / mass_kg;
  const Eigen::Vector3d free_velocity = velocity_m_per_s_ + impulse_scale * net_n;
  const bool at_rest = velocity_m_per_s_.isZero(0.0);
  const double friction_n =
      at_rest ? parameters_.static_friction_n : parameters_.coulomb_friction_n;
  const double friction_step = impulse_scale * friction_n;
  const double free_speed = free_velocity.norm();
  if (free_speed <= friction_step) {
    velocity_m_per_s_.setZero();
  } else {
    velocity_m_per_s_ = free_velocity * (1.0 - friction_step / free_speed);
  }
  position_m_ += dt_s * velocity_m_per_s_;
}

Eigen::Vector3d PointMassDevice::readEncoders(const Eigen::Vector3d& noise_counts) const noexcept {
  const double resolution_m = parameters_.encoder_resolution_m;
  Eigen::Vector3d measured;
  for (int axis = 0; axis < 3; ++axis) {
    measured[axis] =
        std::round(position_m_[axis] / resolution_m + noise_counts[axis]) * resolution_m;
  }
  return measured;
}

void PointMassDevice::resetMechanism(const Eigen::Vector3d& position_m) {
  const double limit_m = parameters_.specifications.workspace_radius_m * 1.2;
  if ((position_m - parameters_.workspace_center_m).norm() > limit_m) {
    throw Error(parameters_.specifications.model_name +
                ": resetState position is outside the reachable workspace (radius " +
                std::to_string(parameters_.specifications.workspace_radius_m * 1000.0) +
                " mm around the centre)");
  }
  position_m_ = position_m;
  velocity_m_per_s_.setZero();
}

}  // namespace autograv::sim
