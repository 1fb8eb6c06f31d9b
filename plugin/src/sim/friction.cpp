#include "autograv/sim/friction.h"

#include <cmath>
#include <string>
#include <vector>

#include "autograv/error.h"

namespace autograv::sim {

namespace {

constexpr FrictionLevel kAllLevels[] = {FrictionLevel::kNone, FrictionLevel::kLow,
                                        FrictionLevel::kTypical, FrictionLevel::kHigh};

void requireNonNegative(const Eigen::Vector3d& value, const std::string& owner, const char* name) {
  if (!value.allFinite() || (value.array() < 0.0).any()) {
    throw Error(owner + ": friction " + name + " must be finite and >= 0 on every joint");
  }
}

}  // namespace

const char* toString(FrictionLevel level) noexcept {
  switch (level) {
    case FrictionLevel::kNone:
      return "none";
    case FrictionLevel::kLow:
      return "low";
    case FrictionLevel::kTypical:
      return "typical";
    case FrictionLevel::kHigh:
      return "high";
  }
  return "typical";
}

std::vector<std::string> frictionLevelNames() {
  std::vector<std::string> names;
  for (const FrictionLevel level : kAllLevels) names.emplace_back(toString(level));
  return names;
}

FrictionLevel parseFrictionLevel(const std::string& name) {
  for (const FrictionLevel level : kAllLevels) {
    if (name == toString(level)) return level;
  }
  std::string valid;
  for (const auto& known : frictionLevelNames()) valid += (valid.empty() ? "" : ", ") + known;
  throw Error("unknown friction level '" + name + "'; valid levels: " + valid);
}

double dryFrictionScale(FrictionLevel level) noexcept {
  switch (level) {
    case FrictionLevel::kNone:
      return 0.0;
    case FrictionLevel::kLow:
      return 1.0 / 3.0;
    case FrictionLevel::kTypical:
      return 1.0;
    case FrictionLevel::kHigh:
      return 2.5;
  }
  return 1.0;
}

void LuGreParameters::validate(const std::string& owner) const {
  requireNonNegative(coulomb, owner, "coulomb");
  requireNonNegative(stiction, owner, "stiction");
  requireNonNegative(bristle_damping, owner, "bristle_damping");
  requireNonNegative(viscous, owner, "viscous");
  requireNonNegative(bristle_stiffness, owner, "bristle_stiffness");
  for (int j = 0; j < 3; ++j) {
    if (stiction[j] < coulomb[j]) {
      throw Error(owner + ": friction stiction must be >= coulomb on every joint");
    }
    if (!std::isfinite(stribeck_velocity[j]) || stribeck_velocity[j] <= 0.0) {
      throw Error(owner + ": friction stribeck_velocity must be finite and > 0 on every joint");
    }
    if (stiction[j] > 0.0 && bristle_stiffness[j] <= 0.0) {
      throw Error(owner + ": friction bristle_stiffness must be > 0 where there is dry friction");
    }
  }
}

LuGreParameters LuGreParameters::scaledDry(double dry_scale) const {
  if (!std::isfinite(dry_scale) || dry_scale < 0.0) {
    throw Error("LuGre friction: the dry-friction scale must be finite and >= 0");
  }
  LuGreParameters scaled = *this;
  scaled.coulomb *= dry_scale;
  scaled.stiction *= dry_scale;
  // The same pre-sliding range (a property of the contact's asperities, not of the load), and the
  // same damping ratio of the bristles: sigma0 scales with the level, sigma1 with its root.
  scaled.bristle_stiffness *= dry_scale;
  scaled.bristle_damping *= std::sqrt(dry_scale);
  return scaled;
}

LuGreParameters makeLuGreParameters(const Eigen::Vector3d& coulomb, const Eigen::Vector3d& stiction,
                                    const Eigen::Vector3d& stribeck_velocity,
                                    const Eigen::Vector3d& presliding_range,
                                    const Eigen::Vector3d& inertia, double damping_ratio,
                                    const Eigen::Vector3d& viscous) {
  if (!presliding_range.allFinite() || (presliding_range.array() <= 0.0).any() ||
      !inertia.allFinite() || (inertia.array() <= 0.0).any() || !std::isfinite(damping_ratio) ||
      damping_ratio < 0.0) {
    throw Error(
        "LuGre friction: presliding_range and inertia must be > 0 and damping_ratio >= 0 on every "
        "joint");
  }
  LuGreParameters parameters;
  parameters.coulomb = coulomb;
  parameters.stiction = stiction;
  parameters.stribeck_velocity = stribeck_velocity;
  parameters.bristle_stiffness = stiction.cwiseQuotient(presliding_range);
  parameters.bristle_damping =
      2.0 * damping_ratio * parameters.bristle_stiffness.cwiseProduct(inertia).cwiseSqrt();
  parameters.viscous = viscous;
  parameters.validate("LuGre friction");
  return parameters;
}

LuGreFriction::LuGreFriction(const LuGreParameters& parameters) : parameters_(parameters) {
  parameters_.validate("LuGre friction");
}

double LuGreFriction::stribeckLevel(int joint, double velocity) const noexcept {
  const double ratio = velocity / parameters_.stribeck_velocity[joint];
  const double ratio2 = ratio * ratio;
  // Beyond 6 vs the Stribeck term is below 3e-16 of (Fs - Fc): skip the exponential.
  if (ratio2 > 36.0) return parameters_.coulomb[joint];
  return parameters_.coulomb[joint] +
         (parameters_.stiction[joint] - parameters_.coulomb[joint]) * std::exp(-ratio2);
}

Eigen::Vector3d LuGreFriction::step(const Eigen::Vector3d& velocity, double dt_s) noexcept {
  Eigen::Vector3d force = parameters_.viscous.cwiseProduct(velocity);
  for (int j = 0; j < 3; ++j) {
    const double sigma0 = parameters_.bristle_stiffness[j];
    const double v = velocity[j];
    if (!(std::abs(v - level_velocity_[j]) <= 1e-4 * parameters_.stribeck_velocity[j])) {
      level_[j] = stribeckLevel(j, v);  // NaN after reset(): always recomputed first
      level_velocity_[j] = v;
    }
    const double level = level_[j];
    if (level <= 0.0 || sigma0 <= 0.0) continue;  // no dry friction on this joint
    const double z = deflection_[j];
    // Exact solution of dz/dt = v - a z over the step, z + (z_ss - z) (1 - exp(-a dt)); for small
    // a dt a short series (error below (a dt)^4 / 24 < 5e-14) spares the exponential.
    const double decay = sigma0 * std::abs(v) / level * dt_s;  // a dt
    const double steady = v > 0.0 ? level / sigma0 : (v < 0.0 ? -level / sigma0 : 0.0);
    const double relaxed =
        decay < 1e-3 ? decay * (1.0 - 0.5 * decay * (1.0 - decay / 3.0)) : -std::expm1(-decay);
    const double next = z + (steady - z) * relaxed;
    deflection_[j] = next;
    force[j] += sigma0 * next + parameters_.bristle_damping[j] * (next - z) / dt_s;
  }
  return force;
}

Eigen::Vector3d CoggingRipple::at(const Eigen::Vector3d& angle_rad) noexcept {
  for (int j = 0; j < 3; ++j) {
    if (amplitude_[j] == 0.0) continue;
    if (!(std::abs(angle_rad[j] - angle_[j]) <= 1e-3)) {  // NaN after reset(): recomputed
      ripple_[j] = amplitude_[j] * std::sin(angle_rad[j]);
      angle_[j] = angle_rad[j];
    }
  }
  return ripple_;
}

}  // namespace autograv::sim
