#include "autograv/estimation/pd_design.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kSettlingBand = 0.02;  // +-2 % of the step
}  // namespace

PdGains designPdGains(const StepResponseSpec& spec) {
  if (!(std::isfinite(spec.settling_time_s) && spec.settling_time_s > 0.0)) {
    throw Error("PD design: settling time must be positive (seconds)");
  }
  if (!(spec.overshoot_percent > 0.0 && spec.overshoot_percent < 100.0)) {
    throw Error("PD design: overshoot must be between 0 and 100 percent (exclusive)");
  }
  const double log_p = std::log(spec.overshoot_percent / 100.0);
  const double zeta = -log_p / std::sqrt(kPi * kPi + log_p * log_p);
  // Envelope exp(-zeta wn t) falls to 2 % after ~4 time constants (-ln 0.02 = 3.91).
  const double zeta_omega = 4.0 / spec.settling_time_s;
  const double omega_n = zeta_omega / zeta;
  return {2.0 * zeta_omega, omega_n * omega_n};
}

StepResponseSpec analyzePdGains(const PdGains& gains) {
  if (!(gains.alpha_per_s > 0.0 && gains.beta_per_s2 > 0.0)) {
    throw Error("PD analysis: alpha and beta must be positive");
  }
  const double omega_n = std::sqrt(gains.beta_per_s2);
  const double zeta = gains.alpha_per_s / (2.0 * omega_n);
  StepResponseSpec spec;
  if (zeta < 1.0) {
    spec.overshoot_percent = 100.0 * std::exp(-zeta * kPi / std::sqrt(1.0 - zeta * zeta));
    spec.settling_time_s = 4.0 / (zeta * omega_n);
  } else {
    const double slow_pole = omega_n * (zeta - std::sqrt(zeta * zeta - 1.0));
    spec.overshoot_percent = 0.0;
    spec.settling_time_s = -std::log(kSettlingBand) / slow_pole;
  }
  return spec;
}

StepResponseSpec simulateStepResponse(const PdGains& gains) {
  if (!(gains.alpha_per_s > 0.0 && gains.beta_per_s2 > 0.0)) {
    throw Error("PD step response: alpha and beta must be positive");
  }
  // Fixed-step RK4 on x'' = beta (1 - x) - alpha x', from rest at 0 toward 1.
  const double dt = 1e-5;
  const double horizon_s = 50.0 / gains.alpha_per_s + 50.0 / std::sqrt(gains.beta_per_s2);
  double x = 0.0;
  double v = 0.0;
  double peak = 0.0;
  double last_outside_s = 0.0;
  auto acceleration = [&](double position, double velocity) {
    return gains.beta_per_s2 * (1.0 - position) - gains.alpha_per_s * velocity;
  };
  for (double t = 0.0; t < horizon_s; t += dt) {
    const double k1x = v, k1v = acceleration(x, v);
    const double k2x = v + 0.5 * dt * k1v,
                 k2v = acceleration(x + 0.5 * dt * k1x, v + 0.5 * dt * k1v);
    const double k3x = v + 0.5 * dt * k2v,
                 k3v = acceleration(x + 0.5 * dt * k2x, v + 0.5 * dt * k2v);
    const double k4x = v + dt * k3v, k4v = acceleration(x + dt * k3x, v + dt * k3v);
    x += dt / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    v += dt / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    peak = std::max(peak, x);
    if (std::abs(x - 1.0) > kSettlingBand) last_outside_s = t + dt;
  }
  return {last_outside_s, std::max(0.0, 100.0 * (peak - 1.0))};
}

FeasibilityCheck checkConvergence(double beta_per_s2, double gravity_norm_n,
                                  double lipschitz_n_per_m) {
  FeasibilityCheck check;
  const double needed = 2.0 * lipschitz_n_per_m * kStandardGravity;
  if (beta_per_s2 * gravity_norm_n >= needed) return check;
  check.ok = false;
  std::ostringstream message;
  message << "convergence check failed (paper Sec. IV): beta*|G| = " << beta_per_s2 << " 1/s^2 * "
          << gravity_norm_n << " N = " << beta_per_s2 * gravity_norm_n
          << " is below 2*c*g = " << needed << " for c = " << lipschitz_n_per_m
          << " N/m; raise beta to at least "
          << (gravity_norm_n > 0.0 ? std::ceil(needed / gravity_norm_n) : INFINITY)
          << " 1/s^2 (EstimationParameters::beta_per_s2), or use a shorter settling time";
  check.message = message.str();
  return check;
}

FeasibilityCheck checkSaturation(double beta_per_s2, double gravity_norm_n, double cell_m,
                                 double max_force_n, double margin) {
  FeasibilityCheck check;
  const double stiffness_n_per_m = beta_per_s2 * gravity_norm_n / kStandardGravity;
  const double worst_n = stiffness_n_per_m * cell_m + gravity_norm_n;
  const double limit_n = margin * max_force_n;
  if (worst_n <= limit_n) return check;
  check.ok = false;
  std::ostringstream message;
  message << "saturation check failed (paper Sec. VI): K_P*cell + |G| = " << stiffness_n_per_m
          << " N/m * " << cell_m * 1e3 << " mm + " << gravity_norm_n << " N = " << worst_n
          << " N exceeds " << margin * 100.0 << " % of the device's " << max_force_n << " N";
  if (limit_n > gravity_norm_n) {
    const double max_cell_m = (limit_n - gravity_norm_n) / stiffness_n_per_m;
    const double max_beta =
        (limit_n - gravity_norm_n) * kStandardGravity / (gravity_norm_n * cell_m);
    message << "; use grid cells of at most " << max_cell_m * 1e3
            << " mm (a larger WizardConfig::grid_resolution or a smaller "
               "WizardConfig::advanced.box_size_m), "
               "or lower EstimationParameters::beta_per_s2 to at most "
            << std::floor(max_beta) << " 1/s^2";
  } else {
    message << "; the device cannot even hold its own weight at this margin";
  }
  check.message = message.str();
  return check;
}

double defaultInitializationStiffness(const DeviceSpecifications& specifications) {
  const double paper_n_per_m = EstimationParameters{}.k0_n_per_m;
  if (!(specifications.max_linear_stiffness_n_per_m > 0.0)) return paper_n_per_m;
  return std::min(paper_n_per_m, 0.1 * specifications.max_linear_stiffness_n_per_m);
}

std::vector<std::string> checkCalibrationPlan(const EstimationParameters& parameters, double cell_m,
                                              double max_force_n,
                                              const Eigen::Vector3d& initial_gravity_n,
                                              double field_margin) {
  std::vector<std::string> problems;
  const double gravity_n = initial_gravity_n.norm();
  // Convergence needs the smallest |G| over the grid, saturation the largest.
  const FeasibilityCheck convergence = checkConvergence(
      parameters.beta_per_s2, gravity_n / field_margin, parameters.lipschitz_prior_n_per_m);
  if (!convergence.ok) problems.push_back(convergence.message);
  const FeasibilityCheck saturation =
      checkSaturation(parameters.beta_per_s2, gravity_n * field_margin, cell_m, max_force_n);
  if (!saturation.ok) problems.push_back(saturation.message);
  return problems;
}

}  // namespace autograv
