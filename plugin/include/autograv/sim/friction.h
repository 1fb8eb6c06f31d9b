#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace autograv::sim {

/// How much friction a simulated device has. kTypical is what the published figures of the real
/// device say; kLow and kHigh bracket it (a well run-in unit, a stiff or cold one); kNone removes
/// the dry friction entirely but keeps the viscous damping (motor back-EMF, amplifier).
enum class FrictionLevel : std::uint8_t { kNone, kLow, kTypical, kHigh };

/// "none", "low", "typical" or "high". Real-time safe.
const char* toString(FrictionLevel level) noexcept;
/// Every level's name, in increasing order of friction.
std::vector<std::string> frictionLevelNames();
/// Inverse of toString. Throws autograv::Error listing the valid names for any other text.
FrictionLevel parseFrictionLevel(const std::string& name);
/// Factor on a device's typical dry friction (Coulomb and static levels) at `level`: 0, 1/3, 1
/// and 2.5. The same ratios on every device so that a level means the same thing everywhere.
double dryFrictionScale(FrictionLevel level) noexcept;

/// LuGre friction (Canudas de Wit, Olsson, Astrom, Lischinsky, "A new model for control of systems
/// with friction", IEEE TAC 40(3), 1995), one independent model per joint or axis:
///   dz/dt = v - sigma0 |v| z / g(v),   g(v) = Fc + (Fs - Fc) exp(-(v / vs)^2)
///   f     = sigma0 z + sigma1 dz/dt + sigma2 v
/// z is the mean deflection of the contact's bristles: below the breakaway force a joint only
/// deflects them (pre-sliding, a stiff spring sigma0), above it the joint slides with the Stribeck
/// curve g(v) falling from the static level Fs to the Coulomb level Fc.
///
/// Units follow the joint: for a revolute joint forces are torques [N m], velocities [rad/s],
/// bristle deflections [rad]; for a Cartesian axis [N], [m/s], [m]. f opposes the motion: the
/// mechanism subtracts it from its generalized force.
struct LuGreParameters {
  /// Fc, dry friction while sliding fast. Unit: [N] or [N m]
  Eigen::Vector3d coulomb = Eigen::Vector3d::Zero();
  /// Fs >= Fc, dry friction at the onset of sliding (stiction). Unit: [N] or [N m]
  Eigen::Vector3d stiction = Eigen::Vector3d::Zero();
  /// vs > 0, speed over which g(v) falls from Fs to Fc. Unit: [m/s] or [rad/s]
  Eigen::Vector3d stribeck_velocity = Eigen::Vector3d::Constant(1e-3);
  /// sigma0 > 0 (when Fs > 0): bristle stiffness. Unit: [N/m] or [N m/rad]
  Eigen::Vector3d bristle_stiffness = Eigen::Vector3d::Zero();
  /// sigma1 >= 0: bristle damping. Unit: [N s/m] or [N m s/rad]
  Eigen::Vector3d bristle_damping = Eigen::Vector3d::Zero();
  /// sigma2 >= 0: viscous friction. Unit: [N s/m] or [N m s/rad]
  Eigen::Vector3d viscous = Eigen::Vector3d::Zero();

  /// Throws autograv::Error naming the first unusable value (`owner` prefixes the message).
  void validate(const std::string& owner) const;
  /// The same model with Fc, Fs and sigma0 multiplied by `dry_scale` (>= 0) and sigma1 by its
  /// square root: the same pre-sliding range and bristle damping ratio at another friction level.
  /// The viscous term is unchanged.
  LuGreParameters scaledDry(double dry_scale) const;
};

/// Bristle parameters from physical quantities: sigma0 so that the static level is reached after
/// `presliding_range` of deflection, sigma1 so that the joint's `inertia` ringing on the bristles
/// is damped with ratio `damping_ratio` (sigma1 = 2 zeta sqrt(sigma0 m)).
/// Units as LuGreParameters; inertia [kg] or [kg m^2].
LuGreParameters makeLuGreParameters(const Eigen::Vector3d& coulomb, const Eigen::Vector3d& stiction,
                                    const Eigen::Vector3d& stribeck_velocity,
                                    const Eigen::Vector3d& presliding_range,
                                    const Eigen::Vector3d& inertia, double damping_ratio,
                                    const Eigen::Vector3d& viscous);

/// The state and integration of three LuGre models.
///
/// Integration: over one step the velocity is held (the mechanism integrates it semi-implicitly),
/// so dz/dt = v - a z with a = sigma0 |v| / g(v) is linear in z and is solved exactly,
///   z(t + dt) = z_ss + (z - z_ss) exp(-a dt),   z_ss = sign(v) g(v) / sigma0,
/// stable for any stiffness and step (the explicit Euler step diverges once a dt > 2, i.e. at a
/// few cm/s with stiff bristles at 10 kHz). dz/dt in f is the step's mean, (z(t + dt) - z) / dt.
/// At v = 0 the bristles hold their deflection, so a body at rest under a force below breakaway
/// stays put after a pre-sliding of about F / sigma0.
class LuGreFriction {
 public:
  LuGreFriction() = default;
  /// Throws autograv::Error when `parameters` are unusable. Not real-time safe.
  explicit LuGreFriction(const LuGreParameters& parameters);

  /// Relaxes the bristles (z = 0). Real-time safe.
  void reset() noexcept {
    deflection_.setZero();
    level_velocity_.setConstant(std::numeric_limits<double>::quiet_NaN());
  }
  /// Advances the bristles over `dt_s` at joint velocity `velocity` and returns the friction
  /// force f (opposing the motion). Real-time safe.
  Eigen::Vector3d step(const Eigen::Vector3d& velocity, double dt_s) noexcept;

  /// z. Unit: [m] or [rad]
  const Eigen::Vector3d& deflection() const noexcept { return deflection_; }
  /// The parameters the model was made with.
  const LuGreParameters& parameters() const noexcept { return parameters_; }
  /// g(v) for joint `joint`: the steady sliding dry friction at speed |v|. Real-time safe.
  double stribeckLevel(int joint, double velocity) const noexcept;

 private:
  LuGreParameters parameters_;
  Eigen::Vector3d deflection_ = Eigen::Vector3d::Zero();
  // g(v) is reused while v stays within 1e-4 vs of the velocity it was computed at (an error
  // below 1e-4 (Fs - Fc)): at rest and in pre-sliding the step then needs no exponential.
  Eigen::Vector3d level_velocity_ =
      Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d level_ = Eigen::Vector3d::Zero();
};

/// Cogging and torque ripple of three motors: A_j sin(angle_j), the angle set by the mechanism
/// (e.g. N q + phase). The sine is reused while an angle moves less than 1e-3 rad from where it
/// was taken (an error below 1e-3 A), so that a mechanism at rest needs no sine per step.
class CoggingRipple {
 public:
  /// Unit: [N] or [N m]
  explicit CoggingRipple(const Eigen::Vector3d& amplitude = Eigen::Vector3d::Zero()) noexcept
      : amplitude_(amplitude) {}
  /// Forgets the cached sines. Real-time safe.
  void reset() noexcept { angle_.setConstant(std::numeric_limits<double>::quiet_NaN()); }
  /// The three ripple forces or torques at `angle_rad`. Real-time safe.
  Eigen::Vector3d at(const Eigen::Vector3d& angle_rad) noexcept;

 private:
  Eigen::Vector3d amplitude_;
  Eigen::Vector3d angle_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d ripple_ = Eigen::Vector3d::Zero();
};

}  // namespace autograv::sim
