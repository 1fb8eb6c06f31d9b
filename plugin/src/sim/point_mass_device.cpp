#include "autograv/sim/point_mass_device.h"

#include <cmath>
#include <string>

#include <Eigen/LU>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "sim/parameter_checks.h"
#include "sim/preset_driver.h"

namespace autograv::sim {

namespace {

// Below this apparent mass the model would stop being a device; the field never comes close.
constexpr double kMinimumMass_kg = 0.01;

}  // namespace

LuGreParameters omegaAxisFriction(FrictionLevel level) {
  // Force Dimension publishes no friction figure for the omega.3. ASSUMED: its direct capstan
  // drives and ball bearings make it smoother than the PHANToM Omni (backdrive friction
  // < 0.26 N, SensAble), about 30 mN of stiction per axis, i.e. a breakaway of 30 mN along an
  // axis and 52 mN along a diagonal, sliding friction 70 % of that, a 2 mm/s Stribeck speed and
  // 5 um of pre-sliding (half an encoder count). kLow and kHigh scale it (dryFrictionScale).
  // The viscous term is the motors' back-EMF and the amplifiers' damping, kept at every level:
  // 1.5 N s/m, ASSUMED, what a spring of k = 500 N/m (the paper's k0) rendered at 1 kHz with one
  // period of transport delay needs to stay passive (more than k (T/2 + T) = 0.75 N s/m); a real
  // omega.3 renders 14.5 N/mm through its own faster loop.
  const Eigen::Vector3d stiction_n = Eigen::Vector3d::Constant(0.030);
  return makeLuGreParameters(0.7 * stiction_n, stiction_n, Eigen::Vector3d::Constant(0.002),
                             Eigen::Vector3d::Constant(5e-6), Eigen::Vector3d::Constant(0.2), 0.5,
                             Eigen::Vector3d::Constant(1.5))
      .scaledDry(dryFrictionScale(level));
}

PointMassParameters omegaParameters(FrictionLevel friction) {
  PointMassParameters parameters;
  parameters.friction = omegaAxisFriction(friction);
  // Force Dimension quotes the omega.3's workspace as 160 mm across by 110 mm high: the sphere
  // that fits its height, 55 mm, centred on the paper's X_D = [0, -30, 0] mm (paper frame), holds
  // the paper's start point [-9.2, -68.3, 11.6] mm 41 mm from the centre, about 45 mm after the
  // sag in the k0 field.
  parameters.specifications.workspace_radius_m = 0.055;
  parameters.workspace_center_m = Eigen::Vector3d(0.0, 0.0, -0.030);
  // The three motors drive the end-effector along directions 120 degrees apart around the
  // vertical, tilted 30 degrees up (a delta's arms); with 120 g moving with the handle and 70 g of
  // rotor and arm inertia per motor the end-effector weighs about 200 g across and 170 g along the
  // vertical at the centre, 120-400 g over the workspace. ASSUMED figures, not published ones.
  constexpr double kTilt_rad = 0.5235987755982988;  // 30 degrees
  for (int i = 0; i < 3; ++i) {
    const double azimuth_rad = 2.0943951023931957 * i;  // 120 degrees apart
    parameters.actuator_directions.col(i) =
        Eigen::Vector3d(std::cos(azimuth_rad) * std::cos(kTilt_rad),
                        std::sin(azimuth_rad) * std::cos(kTilt_rad), std::sin(kTilt_rad));
  }
  // One amplifier per axis over the full force range through a 14-bit DAC (1.5 mN per count).
  // ASSUMED: Force Dimension does not publish its electronics' resolution. Its SDK estimates
  // velocity over a 20 ms window by default.
  parameters.driver = presetDriver(12.0, 14, 0.02);
  parameters.specifications.model_name = "sim:omega";
  parameters.specifications.manufacturer = "autograv simulation (Force Dimension omega.3-like)";
  parameters.specifications.serial_number = "SIM-OMEGA-0001";
  parameters.specifications.max_linear_force_n = 12.0;
  parameters.specifications.max_linear_stiffness_n_per_m = 14500.0;
  parameters.specifications.max_linear_damping_n_s_per_m = 20.0;
  // A symmetric gradient (the field is conservative) of 3-10 N/m per entry: the 214 g of the
  // paper's point become about 150-290 g across the workspace, with x/y components of a few
  // tenths of a newton.
  parameters.gravity_gradient_n_per_m << 10.0, 2.0, 6.0,  //
      2.0, 5.0, -3.0,                                     //
      6.0, -3.0, -5.0;
  return parameters;
}

namespace {

/// The Omega-like mechanism as a test device: a workspace of `shape` and the swirl that no
/// potential explains. Its centre is the workspace centre, so the paper's reference point and
/// the gradient's figures stay those of the preset.
PointMassParameters swirlParameters(FrictionLevel friction, WorkspaceShape shape,
                                    const Eigen::Vector3d& half_extents_m, const char* name) {
  PointMassParameters parameters = omegaParameters(friction);
  parameters.specifications.model_name = name;
  parameters.specifications.manufacturer = "autograv simulation (test device, not a real model)";
  parameters.specifications.serial_number = "SIM-TEST-0001";
  parameters.workspace_shape = shape;
  parameters.workspace_half_extents_m = half_extents_m;
  // The explorer probes up to 1.75 times this radius: the mean half-extent reaches every corner.
  parameters.specifications.workspace_radius_m = half_extents_m.mean();
  parameters.reference_point_m = parameters.workspace_center_m;
  // 60 mN along each component, about 3 % of the 2.1 N of |G| (at most 104 mN together), over a
  // wavelength of 0.1 m: it turns through most of a period across the workspace, which a map's
  // conservative fit misses by 5 % of |G| at the 90th percentile and 8 % at the 99th.
  parameters.swirl_amplitude_n = Eigen::Vector3d::Constant(0.060);
  parameters.swirl_wavelength_m = 0.1;
  return parameters;
}

}  // namespace

PointMassParameters swirlCubeParameters(FrictionLevel friction) {
  return swirlParameters(friction, WorkspaceShape::kBox, Eigen::Vector3d::Constant(0.040),
                         "sim:swirl-cube");
}

PointMassParameters swirlEllipsoidParameters(FrictionLevel friction) {
  return swirlParameters(friction, WorkspaceShape::kEllipsoid, Eigen::Vector3d(0.080, 0.060, 0.035),
                         "sim:swirl-ellipsoid");
}

PointMassDevice::PointMassDevice(const PointMassParameters& parameters, std::uint64_t seed)
    : SimulatedDriver(parameters.specifications, parameters.driver, seed),
      parameters_(parameters),
      position_m_(parameters.workspace_center_m) {
  const ParameterChecks check("sim point-mass device");
  const Eigen::Matrix3d& k = parameters.gravity_gradient_n_per_m;
  if (!k.allFinite() || !k.isApprox(k.transpose(), 1e-12)) {
    check.fail(
        "gravity_gradient_n_per_m must be finite and symmetric (the gravity field of a mechanism "
        "is the gradient of its potential energy)");
  }
  check.finite(parameters.radial_curvature_n_per_m2, "radial_curvature_n_per_m2");
  check.finite(parameters.vertical_curvature_n_per_m2, "vertical_curvature_n_per_m2");
  check.finite(parameters.reference_point_m, "reference_point_m");
  check.finite(parameters.workspace_center_m, "workspace_center_m");
  check.positive(parameters.reference_mass_kg, "reference_mass_kg");
  check.positive(parameters.base_mass_kg, "base_mass_kg");
  check.nonNegative(parameters.rotor_mass_kg, "rotor_mass_kg");
  check.positive(parameters.inertia_length_m, "inertia_length_m");
  for (int i = 0; i < 3; ++i) {
    if (!parameters.actuator_directions.col(i).allFinite() ||
        std::abs(parameters.actuator_directions.col(i).norm() - 1.0) > 1e-9) {
      check.fail("actuator_directions must be unit column vectors");
    }
  }
  check.cogging(parameters.cogging_amplitude_n, "cogging_amplitude_n",
                parameters.cogging_phase_rad);
  check.positive(parameters.cogging_period_m, "cogging_period_m");
  check.friction(parameters.friction);
  friction_ = LuGreFriction(parameters.friction);
  cogging_ = CoggingRipple(parameters.cogging_amplitude_n);
  check.positive(parameters.end_stop_stiffness_n_per_m, "end_stop_stiffness_n_per_m");
  check.nonNegative(parameters.end_stop_damping_n_s_per_m, "end_stop_damping_n_s_per_m");
  check.positive(parameters.encoder_resolution_m, "encoder_resolution_m");
  check.positive(parameters.workspace_half_extents_m, "workspace_half_extents_m");
  check.finite(parameters.swirl_amplitude_n, "swirl_amplitude_n");
  check.finite(parameters.swirl_phase_rad, "swirl_phase_rad");
  check.positive(parameters.swirl_wavelength_m, "swirl_wavelength_m");

  // Solve for w: ||G(X_ref)|| = m_ref g, with G_z = w + (rest of G_z).
  vertical_offset_n_ = 0.0;
  const Eigen::Vector3d rest = gravityAt(parameters.reference_point_m);
  const double target_n = parameters.reference_mass_kg * kStandardGravity;
  const double horizontal2 = rest.x() * rest.x() + rest.y() * rest.y();
  if (horizontal2 >= target_n * target_n) {
    check.fail(
        "the gradient's horizontal force at reference_point_m exceeds reference_mass_kg * g; "
        "lower gravity_gradient_n_per_m");
  }
  vertical_offset_n_ = std::sqrt(target_n * target_n - horizontal2) - rest.z();

  // The field must keep the mass positive everywhere the end-effector can go (end stops included).
  const double reach_m = 1.2 * (parameters.workspace_shape == WorkspaceShape::kSphere
                                    ? parameters.specifications.workspace_radius_m
                                    : parameters.workspace_half_extents_m.norm());
  for (int ix = -4; ix <= 4; ++ix) {
    for (int iy = -4; iy <= 4; ++iy) {
      for (int iz = -4; iz <= 4; ++iz) {
        const Eigen::Vector3d offset = Eigen::Vector3d(ix, iy, iz) * (reach_m / 4.0);
        if (offset.norm() > reach_m) continue;
        const Eigen::Vector3d g = gravityAt(parameters.workspace_center_m + offset);
        if (g.z() <= 0.0 || g.norm() / kStandardGravity < 2.0 * kMinimumMass_kg) {
          check.fail(
              "the gravity field must point up with a mass above 20 g over the whole workspace; "
              "lower the gradient or the curvatures");
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
  if (!parameters_.swirl_amplitude_n.isZero()) {
    constexpr double kTwoPi = 6.283185307179586476925286766559;
    const double k = kTwoPi / parameters_.swirl_wavelength_m;
    const Eigen::Vector3d& phase = parameters_.swirl_phase_rad;
    g += parameters_.swirl_amplitude_n.cwiseProduct(
        Eigen::Vector3d(std::sin(k * p.y() + phase.x()), std::sin(k * p.z() + phase.y()),
                        std::sin(k * p.x() + phase.z())));
  }
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
  return commandDelivering_n(Eigen::Matrix3d::Identity(), loadedGravity_n(gravityAt(position_m)));
}

Eigen::Matrix3d PointMassDevice::massAt(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d p = position_m - parameters_.workspace_center_m;
  Eigen::Matrix3d mass = (parameters_.base_mass_kg + payload_kg_) * Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d u = parameters_.actuator_directions.col(i);
    const double lever = 1.0 + u.dot(p) / parameters_.inertia_length_m;
    mass += (parameters_.rotor_mass_kg * lever * lever) * (u * u.transpose());
  }
  return mass;
}

Eigen::Matrix3d PointMassDevice::trueApparentMass(const Eigen::Vector3d& position_m) const {
  return massAt(position_m);
}

Eigen::Vector3d PointMassDevice::mechanismGravity_n() const noexcept {
  return gravityAt(position_m_);
}

void PointMassDevice::integrateStep(const Eigen::Vector3d& motor_force_n,
                                    const Eigen::Vector3d& external_force_n, double dt_s) noexcept {
  const Eigen::Vector3d& v = velocity_m_per_s_;
  const Eigen::Vector3d from_center = position_m_ - parameters_.workspace_center_m;
  // Friction against the velocity held over the step (semi-implicit Euler).
  Eigen::Vector3d net_n =
      motor_force_n + external_force_n - gravityAt(position_m_) - friction_.step(v, dt_s);
  // Coriolis and centrifugal forces of M(X): with M = m_b I + sum_i c_i(X) u_i u_i^T,
  // C(X, Xd) Xd = dM/dt Xd - 1/2 d(Xd^T M Xd)/dX = sum_i 1/2 (dc_i/dX . u_i) (u_i . Xd)^2 u_i.
  Eigen::Matrix3d mass = (parameters_.base_mass_kg + payload_kg_) * Eigen::Matrix3d::Identity();
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d u = parameters_.actuator_directions.col(i);
    const double lever = 1.0 + u.dot(from_center) / parameters_.inertia_length_m;
    const double along = u.dot(v);
    mass += (parameters_.rotor_mass_kg * lever * lever) * (u * u.transpose());
    net_n -= (parameters_.rotor_mass_kg * lever / parameters_.inertia_length_m * along * along) * u;
  }
  constexpr double kTwoPi = 6.283185307179586476925286766559;
  net_n += cogging_.at(kTwoPi * from_center.cwiseQuotient(parameters_.cogging_period_m) +
                       parameters_.cogging_phase_rad);

  const Eigen::Vector3d penetration_m = stopPenetration_m(from_center);
  if (!penetration_m.isZero()) {
    // The rubber stop pushes back along the normal and drags on the whole velocity, so an
    // end-effector resting on it settles instead of sliding round the sphere.
    net_n -= parameters_.end_stop_stiffness_n_per_m * penetration_m +
             parameters_.end_stop_damping_n_s_per_m * v;
    end_stop_hit_ = true;
  }
  velocity_m_per_s_ += dt_s * (mass.inverse() * net_n);  // closed-form 3x3 inverse
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

Eigen::Vector3d PointMassDevice::stopPenetration_m(
    const Eigen::Vector3d& from_center_m) const noexcept {
  const Eigen::Vector3d& half = parameters_.workspace_half_extents_m;
  switch (parameters_.workspace_shape) {
    case WorkspaceShape::kBox:
      // One wall per face: at an edge or a corner, two or three push at once.
      return from_center_m - from_center_m.cwiseMax(-half).cwiseMin(half);
    case WorkspaceShape::kEllipsoid: {
      // rho = |D^-1 p| is 1 on the surface; (rho - 1) / |grad rho| is the depth to first order.
      const Eigen::Vector3d scaled = from_center_m.cwiseQuotient(half);
      const double rho = scaled.norm();
      if (rho <= 1.0) return Eigen::Vector3d::Zero();
      const Eigen::Vector3d gradient = scaled.cwiseQuotient(half) / rho;
      return ((rho - 1.0) / gradient.squaredNorm()) * gradient;
    }
    case WorkspaceShape::kSphere:
      break;
  }
  const double radius_m = parameters_.specifications.workspace_radius_m;
  const double distance_m = from_center_m.norm();
  if (distance_m <= radius_m) return Eigen::Vector3d::Zero();
  return (distance_m - radius_m) / distance_m * from_center_m;
}

bool PointMassDevice::isReachable(const Eigen::Vector3d& position_m) const noexcept {
  return stopPenetration_m(position_m - parameters_.workspace_center_m).isZero();
}

void PointMassDevice::resetMechanism(const Eigen::Vector3d& position_m) {
  const Eigen::Vector3d penetration_m =
      stopPenetration_m(position_m - parameters_.workspace_center_m);
  const double limit_m = parameters_.specifications.workspace_radius_m * 0.2;
  if (!position_m.allFinite() || penetration_m.norm() > limit_m) {
    throw Error(parameters_.specifications.model_name +
                ": resetState position lies beyond the end stops by more than " +
                std::to_string(limit_m * 1000.0) + " mm");
  }
  position_m_ = position_m;
  velocity_m_per_s_.setZero();
  friction_.reset();
  cogging_.reset();
}

}  // namespace autograv::sim
