#include "autograv/sim/delta_device.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "sim/parameter_checks.h"
#include "sim/preset_driver.h"

namespace autograv::sim {

namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;
// The delta's axis: +x, toward the operator.
const Eigen::Vector3d kAxis = Eigen::Vector3d::UnitX();
// |det A| / b^3 below this is a constraint singularity (forearms coplanar): out of reach.
constexpr double kSingularDeterminant = 1e-6;
// Smallest singular-value ratio of J accepted over the workspace sphere at construction.
constexpr double kMaxJacobianCondition = 20.0;

/// Adds the force of the grip's travel stops at `offset_m` from the workspace centre to
/// `force_n`; `velocity()` gives the grip's velocity, asked for only on contact. True on contact.
template <class Velocity>
bool pushTravelStops(const DeltaParameters& p, const Eigen::Vector3d& offset_m,
                     const Velocity& velocity, Eigen::Vector3d& force_n) noexcept {
  Eigen::Vector3d grip_velocity;
  bool touching = false;
  if (p.travel_stop_shape == TravelStopShape::kCylinder) {
    // The round wall pushes along the horizontal normal through the axis...
    const double radius_m = std::hypot(offset_m.x(), offset_m.y());
    const double beyond_wall_m = radius_m - p.travel_stop_radius_m;
    if (beyond_wall_m > 0.0) {
      grip_velocity = velocity();
      touching = true;
      const Eigen::Vector3d normal(offset_m.x() / radius_m, offset_m.y() / radius_m, 0.0);
      force_n -= (p.travel_stop_stiffness_n_per_m * beyond_wall_m +
                  p.travel_stop_damping_n_s_per_m * normal.dot(grip_velocity)) *
                 normal;
    }
    // ...and the floor and the ceiling straight up and down, whatever x and y.
    const double beyond_m =
        offset_m.z() - std::clamp(offset_m.z(), p.travel_stop_floor_m, p.travel_stop_ceiling_m);
    if (beyond_m != 0.0) {
      if (!touching) grip_velocity = velocity();
      touching = true;
      force_n.z() -= p.travel_stop_stiffness_n_per_m * beyond_m +
                     p.travel_stop_damping_n_s_per_m * grip_velocity.z();
    }
    return touching;
  }
  if (!(p.travel_stop_half_width_m > 0.0)) return false;
  for (int axis = 0; axis < 3; ++axis) {
    const double beyond_m = offset_m[axis] - std::clamp(offset_m[axis], -p.travel_stop_half_width_m,
                                                        p.travel_stop_half_width_m);
    if (beyond_m == 0.0) continue;
    if (!touching) grip_velocity = velocity();
    touching = true;
    force_n[axis] -= p.travel_stop_stiffness_n_per_m * beyond_m +
                     p.travel_stop_damping_n_s_per_m * grip_velocity[axis];
  }
  return touching;
}

}  // namespace

DeltaParameters falconParameters(FrictionLevel friction) {
  DeltaParameters parameters;
  // Joint friction. The Falcon's arms are driven by cable capstans (no gear backlash or gear
  // friction) from small brushed DC motors: the dry friction is mostly the motors' brushes and
  // bearings plus the arm and parallelogram pivots. Novint publishes no friction figure, so the
  // levels are ESTIMATES: at `typical`, 2.4 mN m of stiction and 1.6 mN m of Coulomb friction per
  // arm, which gives a breakaway force at the grip of about 35 to 40 mN across the axis and up to
  // about 75 mN along it (all three arms turn together), median about 42 mN, at the workspace
  // centre: tens of mN like other capstan-driven desktop devices, at least the 30 mN asked of
  // every simulated device and well under the 0.26 N bound SensAble publishes for the PHANToM
  // Omni's backdrive friction. Stribeck speed 0.01 rad/s (about 0.7 mm/s at the grip),
  // pre-sliding 0.2 mrad (about 13 um at the grip), bristles critically damped on the arm's
  // inertia. The viscous 5 mN m s/rad per arm, about 1 N s/m at the grip, is kept at every level:
  // it is the motors' back-EMF and the amplifier as much as friction.
  const LuGreParameters typical = makeLuGreParameters(
      Eigen::Vector3d::Constant(1.6e-3), Eigen::Vector3d::Constant(2.4e-3),
      Eigen::Vector3d::Constant(0.01), Eigen::Vector3d::Constant(2.0e-4),
      Eigen::Vector3d::Constant(2.0e-4), 1.0, Eigen::Vector3d::Constant(5.0e-3));
  parameters.friction = typical.scaledDry(dryFrictionScale(friction));
  // Each motor's amplifier: 0.6 N m at an arm, just enough for 8.9 N in every direction at the
  // centre, so that away from it some directions saturate a motor before the Cartesian clamp;
  // through a 12-bit DAC (0.3 mN m, about 5 mN at the grip, per count). ASSUMED figures.
  parameters.driver = presetDriver(0.6, 12, 0.015);
  parameters.specifications.model_name = "sim:falcon";
  parameters.specifications.manufacturer = "autograv simulation (Novint Falcon-like)";
  parameters.specifications.serial_number = "SIM-FALCON-0001";
  // Novint's data sheet: force capability > 2 lbf.
  parameters.specifications.max_linear_force_n = 8.9;
  // Not published; an estimate of what a 1 kHz loop renders stably on this mechanism.
  parameters.specifications.max_linear_stiffness_n_per_m = 2000.0;
  parameters.specifications.max_linear_damping_n_s_per_m = 10.0;
  // The sphere inscribed in the published 4 x 4 x 4 in cube: every direction reaches it. The
  // mechanism reaches the whole cube (and a little more) before its arm stops; the grip's travel
  // stops hold it in the cube.
  parameters.specifications.workspace_radius_m = 0.0508;
  parameters.travel_stop_half_width_m = 0.0508;
  return parameters;
}

DeltaParameters falconCanParameters(FrictionLevel friction) {
  DeltaParameters parameters = falconParameters(friction);
  parameters.specifications.model_name = "sim:falcon-can";
  parameters.specifications.manufacturer = "autograv simulation (test device, not a real model)";
  parameters.specifications.serial_number = "SIM-TEST-0001";
  // A can 90 mm across and 90 mm high about the centre, inside the published 4-inch cube, which
  // the mechanism reaches with every arm clear of its stops: the floor, the ceiling and the wall
  // are what the grip meets moving down, up or out, never an arm stop. Each flat face is a disc
  // of 64 cm^2 across the whole workspace, where sim:falcon's gravity is 0.6-1.25 N. A test
  // device's shape, not a measured one.
  parameters.travel_stop_shape = TravelStopShape::kCylinder;
  parameters.travel_stop_half_width_m = 0.0;
  parameters.travel_stop_radius_m = 0.045;
  parameters.travel_stop_floor_m = -0.045;
  parameters.travel_stop_ceiling_m = 0.045;
  // ASSUMED, 3,000 N/m at the grip: a stop on a desktop device (a rubber bumper, a plastic stop,
  // a base plate) is felt through the mechanism in series with it. A rubber pad alone is stiff:
  // Shore 50A rubber has E of about 2.5 MPa (A. N. Gent, "On the relation between indentation
  // hardness and Young's modulus", Trans. IRI 34, 1958), so a pad 10 mm across and 5 mm thick is
  // E A / t = 39 N/mm. The structure in series is what yields: 1.02 N/mm at the PHANToM Omni's
  // tip along its weakest axis (SensAble's datasheet), 14.5 N/mm at the omega.3's (Force
  // Dimension's), which with the pad make 1.0 to 10.5 N/mm. 3 N/mm lies in that band, toward the
  // low-cost end the Falcon belongs to, and 1.5 times the model devices' 2 N/mm stops: a hold
  // resting on this floor sinks less into it, the harder case for telling it from a converged
  // one. The damping stays sim:falcon's 5 N s/m (assumed there).
  parameters.travel_stop_stiffness_n_per_m = 3000.0;
  // The sphere inscribed in the can: every direction reaches it. The explorer probes up to 1.75
  // times it, beyond the can's rim (64 mm from the centre); the scoring's bounds (1.05 times it
  // for coverage) hold the whole can.
  parameters.specifications.workspace_radius_m = 0.045;
  return parameters;
}

DeltaDevice::DeltaDevice(const DeltaParameters& parameters, std::uint64_t seed)
    : SimulatedDriver(parameters.specifications, parameters.driver, seed), parameters_(parameters) {
  const auto& p = parameters;
  const ParameterChecks check("sim delta device");
  check.armsAndMotors(p);
  check.positive(p.base_radius_m, "base_radius_m");
  check.nonNegative(p.effector_radius_m, "effector_radius_m");
  check.nonNegative(p.travel_stop_half_width_m, "travel_stop_half_width_m");
  check.positive(p.travel_stop_stiffness_n_per_m, "travel_stop_stiffness_n_per_m");
  check.nonNegative(p.travel_stop_damping_n_s_per_m, "travel_stop_damping_n_s_per_m");
  if (p.travel_stop_shape == TravelStopShape::kCylinder) {
    check.positive(p.travel_stop_radius_m, "travel_stop_radius_m");
    if (!(p.travel_stop_floor_m < 0.0) || !(p.travel_stop_ceiling_m > 0.0) ||
        !std::isfinite(p.travel_stop_floor_m) || !std::isfinite(p.travel_stop_ceiling_m)) {
      check.fail(
          "travel_stop_floor_m must be below the workspace centre and travel_stop_ceiling_m "
          "above it");
    }
  }
  check.positive(p.center_distance_m, "center_distance_m");
  check.finite(p.leg_angles_rad, "leg_angles_rad");
  check.nonNegative(p.platform_mass_kg, "platform_mass_kg");
  check.positive(p.grip_mass_kg, "grip_mass_kg");
  check.positive(p.joint_stop_stiffness_n_m_per_rad, "joint_stop_stiffness_n_m_per_rad");
  check.nonNegative(p.joint_stop_damping_n_m_s_per_rad, "joint_stop_damping_n_m_s_per_rad");
  check.finite(p.joint_min_rad, "joint_min_rad");
  check.finite(p.joint_max_rad, "joint_max_rad");
  if ((p.joint_min_rad.array() >= p.joint_max_rad.array()).any()) {
    check.fail("joint_min_rad must be below joint_max_rad");
  }
  friction_ = LuGreFriction(p.friction);
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
    check.fail("leg_angles_rad must be 120 degrees apart");
  }
  moving_mass_kg_ = p.platform_mass_kg + p.grip_mass_kg + 1.5 * p.forearm_mass_kg;

  home_tip_m_ = p.center_distance_m * kAxis;
  theta_rad_.setZero();
  Eigen::Vector3d home_theta;
  if (!inverseKinematics(Eigen::Vector3d::Zero(), home_theta) ||
      (home_theta.array() <= p.joint_min_rad.array()).any() ||
      (home_theta.array() >= p.joint_max_rad.array()).any()) {
    check.fail("center_distance_m puts the workspace centre out of reach or beyond the arm stops");
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
        bool usable = inverseKinematics(point, theta) &&
                      (theta.array() > p.joint_min_rad.array()).all() &&
                      (theta.array() < p.joint_max_rad.array()).all() && solvePose(theta, at);
        if (usable) {
          const Eigen::Vector3d singular =
              Eigen::JacobiSVD<Eigen::Matrix3d>(at.jacobian).singularValues();
          usable = singular[2] * kMaxJacobianCondition > singular[0];
        }
        if (!usable) {
          check.fail("the workspace sphere (radius " + std::to_string(radius_m * 1000.0) +
                     " mm around the centre) leaves the mechanism's reach, its arm stops or its "
                     "well-conditioned region; change the geometry or shrink workspace_radius_m");
        }
      }
    }
  }
  // A can of travel stops must lie within the arms' stops, so that its faces are what the grip
  // meets: its rims at the floor, halfway and at the ceiling, and the middle of each flat face.
  if (p.travel_stop_shape == TravelStopShape::kCylinder) {
    for (const double height_m :
         {p.travel_stop_floor_m, 0.5 * (p.travel_stop_floor_m + p.travel_stop_ceiling_m),
          p.travel_stop_ceiling_m}) {
      for (int step = 0; step <= 24; ++step) {
        const double angle = kTwoPi * step / 24.0;
        // step 24: the face's middle.
        const double radius_m = step < 24 ? p.travel_stop_radius_m : 0.0;
        const Eigen::Vector3d point(radius_m * std::cos(angle), radius_m * std::sin(angle),
                                    height_m);
        Eigen::Vector3d theta;
        if (!inverseKinematics(point, theta) || (theta.array() < p.joint_min_rad.array()).any() ||
            (theta.array() > p.joint_max_rad.array()).any()) {
          check.fail(
              "the cylinder of travel stops (travel_stop_radius_m, travel_stop_floor_m, "
              "travel_stop_ceiling_m) leaves the mechanism's reach or its arm stops; make it "
              "smaller");
        }
      }
    }
  }
  resetMechanism(Eigen::Vector3d::Zero());
}

Eigen::Vector3d DeltaDevice::kneeCentre(int leg, double sin_theta,
                                        double cos_theta) const noexcept {
  // The knee moved inward by the platform joint's radius: the centre of the leg's sphere of
  // platform positions.
  const auto& p = parameters_;
  return (p.base_radius_m - p.effector_radius_m + p.upper_arm_length_m * cos_theta) *
             radial_[static_cast<std::size_t>(leg)] +
         p.upper_arm_length_m * sin_theta * kAxis;
}

bool DeltaDevice::intersectLegs(const std::array<Eigen::Vector3d, 3>& knee,
                                Eigen::Vector3d& tip_m) const noexcept {
  // The three spheres have the same radius b: the platform lies on the line through the
  // circumcentre of their centres, normal to their plane, on the operator's side.
  const Eigen::Vector3d u = knee[0] - knee[2];
  const Eigen::Vector3d v = knee[1] - knee[2];
  const Eigen::Vector3d normal = u.cross(v);
  const double normal2 = normal.squaredNorm();
  const double b = parameters_.forearm_length_m;
  if (!(normal2 > 1e-12 * b * b * b * b)) return false;  // knees in a line
  const Eigen::Vector3d circumcentre =
      knee[2] + (u.squaredNorm() * v - v.squaredNorm() * u).cross(normal) / (2.0 * normal2);
  const double height2 = b * b - (knee[0] - circumcentre).squaredNorm();
  if (!(height2 >= 0.0)) return false;
  const double side = normal.x() >= 0.0 ? 1.0 : -1.0;  // normal.x() = normal . kAxis
  tip_m = circumcentre + (side * std::sqrt(height2 / normal2)) * normal;
  return true;
}

bool DeltaDevice::solvePose(const Eigen::Vector3d& theta_rad, Pose& out) const noexcept {
  if (!theta_rad.allFinite()) return false;
  std::array<Eigen::Vector3d, 3> knee;
  for (int leg = 0; leg < 3; ++leg) {
    out.sin_theta[leg] = std::sin(theta_rad[leg]);
    out.cos_theta[leg] = std::cos(theta_rad[leg]);
    knee[static_cast<std::size_t>(leg)] = kneeCentre(leg, out.sin_theta[leg], out.cos_theta[leg]);
  }
  if (!intersectLegs(knee, out.tip_m)) return false;
  const double a = parameters_.upper_arm_length_m;
  Eigen::Matrix3d constraint;  // A: rows d_i^T
  for (int leg = 0; leg < 3; ++leg) {
    const auto i = static_cast<std::size_t>(leg);
    out.forearm[i] = out.tip_m - knee[i];
    out.knee_rate[i] = a * (out.cos_theta[leg] * kAxis - out.sin_theta[leg] * radial_[i]);
    constraint.row(leg) = out.forearm[i].transpose();
    out.drive[leg] = out.forearm[i].dot(out.knee_rate[i]);
  }
  const double b = parameters_.forearm_length_m;
  double determinant = 0.0;
  bool invertible = false;
  constraint.computeInverseAndDetWithCheck(out.constraint_inverse, determinant, invertible);
  if (!invertible || !(std::abs(determinant) > kSingularDeterminant * b * b * b)) return false;
  // d_i . pd = (d_i . dc_i/dtheta_i) thetad_i for every leg: A pd = B thetad.
  out.jacobian = out.constraint_inverse * out.drive.asDiagonal();
  return true;
}

bool DeltaDevice::forwardKinematics(const Eigen::Vector3d& theta_rad,
                                    Eigen::Vector3d& position_m) const noexcept {
  if (!theta_rad.allFinite()) return false;
  std::array<Eigen::Vector3d, 3> knee;
  for (int leg = 0; leg < 3; ++leg) {
    knee[static_cast<std::size_t>(leg)] =
        kneeCentre(leg, std::sin(theta_rad[leg]), std::cos(theta_rad[leg]));
  }
  Eigen::Vector3d tip;
  if (!intersectLegs(knee, tip)) return false;
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

void DeltaDevice::requirePose(const Eigen::Vector3d& position_m, Pose& out,
                              const char* what) const {
  Eigen::Vector3d theta;
  if (!inverseKinematics(position_m, theta) || !solvePose(theta, out)) {
    throw Error(parameters_.specifications.model_name + " " + what +
                ": position is outside the mechanism's reach");
  }
}

Eigen::Matrix3d DeltaDevice::jacobian(const Eigen::Vector3d& theta_rad) const noexcept {
  Pose at{};
  if (!solvePose(theta_rad, at)) {
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
  Pose at{};
  if (!solvePose(theta_rad, at)) {
    return Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return massMatrix(at);
}

Eigen::Vector3d DeltaDevice::gravityTorque(const Pose& at) const noexcept {
  // U = sum_i k_i cos(theta_i) + m_p g z_p: the arms' part per joint, the platform's through J.
  return moving_mass_kg_ * kStandardGravity * at.jacobian.row(2).transpose() -
         arm_gravity_n_m_.cwiseProduct(at.sin_theta);
}

Eigen::Vector3d DeltaDevice::gravityTorque(const Eigen::Vector3d& theta_rad) const noexcept {
  Pose at{};
  if (!solvePose(theta_rad, at)) {
    return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  return gravityTorque(at);
}

double DeltaDevice::potentialEnergy_j(const Eigen::Vector3d& theta_rad) const noexcept {
  Pose at{};
  if (!solvePose(theta_rad, at)) return std::numeric_limits<double>::quiet_NaN();
  return arm_gravity_n_m_.dot(at.cos_theta) + moving_mass_kg_ * kStandardGravity * at.tip_m.z();
}

double DeltaDevice::kineticEnergy_j(const Eigen::Vector3d& theta_rad,
                                    const Eigen::Vector3d& thetad_rad_per_s) const noexcept {
  return 0.5 * thetad_rad_per_s.dot(massMatrix(theta_rad) * thetad_rad_per_s);
}

Eigen::Vector3d DeltaDevice::trueGravity(const Eigen::Vector3d& position_m) const {
  Pose at{};
  requirePose(position_m, at, "trueGravity");
  const Eigen::Matrix3d jacobian_t = at.jacobian.transpose();
  return commandDelivering_n(jacobian_t, loadedGravity_n(jacobian_t.inverse() * gravityTorque(at)));
}

Eigen::Vector3d DeltaDevice::mechanismGravity_n() const noexcept {
  return pose_.jacobian.transpose().inverse() * gravityTorque(pose_);
}

void DeltaDevice::applyPayload_kg(double payload_kg) {
  // A payload at the grip is more moving mass: gravity and inertia both follow m_p.
  const auto& p = parameters_;
  moving_mass_kg_ = p.platform_mass_kg + p.grip_mass_kg + 1.5 * p.forearm_mass_kg + payload_kg;
}

Eigen::Matrix3d DeltaDevice::trueApparentMass(const Eigen::Vector3d& position_m) const {
  Pose at{};
  requirePose(position_m, at, "trueApparentMass");
  const Eigen::Matrix3d inverse = at.jacobian.inverse();
  const Eigen::Matrix3d lambda = inverse.transpose() * massMatrix(at) * inverse;
  return 0.5 * (lambda + lambda.transpose());
}

Eigen::Vector3d DeltaDevice::cartesianToMotor(const Eigen::Vector3d& force_n) const noexcept {
  return pose_.jacobian.transpose() * force_n;
}

Eigen::Vector3d DeltaDevice::motorToCartesian(const Eigen::Vector3d& command) const noexcept {
  // J^-T = (A^-1 B)^-T = A^T B^-1: each motor's torque pushes along its own forearm.
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  for (int leg = 0; leg < 3; ++leg) {
    force_n += (command[leg] / pose_.drive[leg]) * pose_.forearm[static_cast<std::size_t>(leg)];
  }
  return force_n;
}

void DeltaDevice::integrateStep(const Eigen::Vector3d& motor_command,
                                const Eigen::Vector3d& external_force_n, double dt_s) noexcept {
  const auto& p = parameters_;
  const Pose& at = pose_;  // of the current state, kept from the previous step
  const Eigen::Vector3d& theta = theta_rad_;
  const Eigen::Vector3d& thetad = thetad_rad_per_s_;
  const Eigen::Matrix3d jacobian_t = at.jacobian.transpose();

  // The grip's travel stops push back on each face they stand on and drag on the grip's speed.
  Eigen::Vector3d grip_force_n = external_force_n;
  const auto grip_velocity = [&at, &thetad]() -> Eigen::Vector3d { return at.jacobian * thetad; };
  if (pushTravelStops(p, at.tip_m - home_tip_m_ - workspaceCenter_m(), grip_velocity,
                      grip_force_n)) {
    end_stop_hit_ = true;
  }

  // The motors' torques (saturated, quantized and delayed by the driver) and the hand's force on
  // the grip.
  Eigen::Vector3d torque =
      motor_command + jacobian_t * grip_force_n - gravityTorque(at) - friction_.step(thetad, dt_s);

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
        -a * (at.cos_theta[leg] * radial_[i] + at.sin_theta[leg] * kAxis);
    h[leg] = thetad[leg] * thetad[leg] * at.forearm[i].dot(knee_curvature) -
             (velocity_m_per_s_ - at.knee_rate[i] * thetad[leg]).squaredNorm();
  }
  torque -= moving_mass_kg_ * (jacobian_t * (at.constraint_inverse * h));
  const Eigen::Vector3d thetadd = massMatrix(at).inverse() * torque;

  // Semi-implicit Euler: new velocity, then the position with it.
  const Eigen::Vector3d next_thetad = thetad + dt_s * thetadd;
  const Eigen::Vector3d next_theta = theta + dt_s * next_thetad;
  Pose next{};
  if (!solvePose(next_theta, next)) {
    thetad_rad_per_s_.setZero();  // a singular pose: the mechanism locks, as a real one would
    velocity_m_per_s_.setZero();
    return;
  }
  pose_ = next;
  theta_rad_ = next_theta;
  thetad_rad_per_s_ = next_thetad;
  tip_m_ = next.tip_m - home_tip_m_;
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
  if (!inverseKinematics(position_m, theta) || !solvePose(theta, at) ||
      (theta.array() < p.joint_min_rad.array()).any() ||
      (theta.array() > p.joint_max_rad.array()).any()) {
    throw Error(p.specifications.model_name +
                ": resetState position is outside the workspace (beyond the arm stops)");
  }
  theta_rad_ = theta;
  thetad_rad_per_s_.setZero();
  friction_.reset();
  pose_ = at;
  tip_m_ = at.tip_m - home_tip_m_;
  velocity_m_per_s_.setZero();
}

Eigen::Vector3d DeltaDevice::travelStopForce_n(
    const Eigen::Vector3d& position_m, const Eigen::Vector3d& velocity_m_per_s) const noexcept {
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  pushTravelStops(
      parameters_, position_m - workspaceCenter_m(),
      [&velocity_m_per_s]() -> Eigen::Vector3d { return velocity_m_per_s; }, force_n);
  return force_n;
}

bool DeltaDevice::isReachable(const Eigen::Vector3d& position_m) const noexcept {
  Eigen::Vector3d theta_rad;
  const auto& p = parameters_;
  const Eigen::Vector3d offset_m = position_m - workspaceCenter_m();
  const bool inside_stops =
      p.travel_stop_shape == TravelStopShape::kCylinder
          ? std::hypot(offset_m.x(), offset_m.y()) <= p.travel_stop_radius_m &&
                offset_m.z() >= p.travel_stop_floor_m && offset_m.z() <= p.travel_stop_ceiling_m
          // The published cube, whose inscribed sphere the specifications give.
          : offset_m.cwiseAbs().maxCoeff() <= specifications().workspace_radius_m;
  return inside_stops && inverseKinematics(position_m, theta_rad) &&
         (theta_rad.array() >= parameters_.joint_min_rad.array()).all() &&
         (theta_rad.array() <= parameters_.joint_max_rad.array()).all();
}

}  // namespace autograv::sim
