#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv {

/// Step-response specification of the linearized closed loop Xdd = beta (X_D - X) - alpha Xd
/// (paper eq. 5), used to design alpha and beta (paper Section II, Figs. 2-3).
struct StepResponseSpec {
  /// Settling time into the +-2 % band, by the classic 4 / (zeta omega_n) rule (the exact 2 %
  /// time differs by a few percent: simulateStepResponse gives it). Unit: [s]
  double settling_time_s = 0.2;
  /// Percent overshoot of the unit-step response, e.g. 5 for 5 %. Unit: [%]
  double overshoot_percent = 5.0;
};

/// The two gains of the feedback-linearizing PD: K_D = alpha M, K_P = beta M (eq. 4).
struct PdGains {
  double alpha_per_s = 0.0;  ///< Unit: [1/s]
  double beta_per_s2 = 0.0;  ///< Unit: [1/s^2]
};

/// alpha and beta for a spec, by the second-order formulas behind the paper's design plots:
/// zeta = -ln(p) / sqrt(pi^2 + ln^2 p), zeta * omega_n = 4 / T_s (2 % band), so
/// alpha = 2 zeta omega_n = 8 / T_s and beta = omega_n^2.
/// Throws autograv::Error unless 0 < T_s and 0 < p < 100. Not real-time safe.
PdGains designPdGains(const StepResponseSpec& spec);

/// The spec that (alpha, beta) achieve, by the same formulas (an underdamped loop is required:
/// alpha^2 < 4 beta; an overdamped one reports 0 % overshoot and its slow-pole settling time).
/// Throws autograv::Error for non-positive gains. Not real-time safe.
StepResponseSpec analyzePdGains(const PdGains& gains);

/// Exact +-2 % settling time and overshoot of the unit step response of eq. (5), found by
/// integrating it (no approximation), for tests and reports. Not real-time safe.
StepResponseSpec simulateStepResponse(const PdGains& gains);

/// Result of a feasibility check: `ok`, and when not, what to change and to what.
struct FeasibilityCheck {
  /// True when the check passed; `message` then is empty.
  bool ok = true;
  std::string message;  ///< Empty when ok.
};

/// Paper Section IV: the iteration contracts when beta ||G|| >= 2 c g, c being the Lipschitz
/// constant of G(X). `gravity_norm_n` [N], `lipschitz_n_per_m` [N/m]. Not real-time safe.
FeasibilityCheck checkConvergence(double beta_per_s2, double gravity_norm_n,
                                  double lipschitz_n_per_m);

/// Paper Section VI: the PD effort over one grid cell plus ||G|| must stay under the device's
/// force limit (with `margin`, e.g. 0.9 of it). Units: [1/s^2], [N], [m], [N].
/// Not real-time safe.
FeasibilityCheck checkSaturation(double beta_per_s2, double gravity_norm_n, double cell_m,
                                 double max_force_n, double margin = 0.9);

/// Stiffness of the initialization field (eq. 7) for a device: the paper's 0.5 N/mm, but never
/// more than a tenth of the stiffness the device can render. Above that, one encoder count of
/// position error is a force step larger than the device's stiction and the field limit-cycles
/// instead of settling (seen on the Omni-like arm at 0.5 N/mm); a tenth still sags a few
/// millimetres, which eq. (7) needs. Unit: [N/m]. Not real-time safe.
double defaultInitializationStiffness(const DeviceSpecifications& specifications);

/// Both checks for a calibration plan, run after the manual initialization and before the device
/// moves by itself, with G_hat_0 standing in for the unknown field: its norm is divided by
/// `field_margin` for the convergence check (which needs the smallest |G| over the grid) and
/// multiplied by it for the saturation check (the largest). The Lipschitz constant is the
/// parameters' prior. Returns the messages of the failed checks, empty when all pass.
/// Units: cell [m], force [N]. Not real-time safe.
std::vector<std::string> checkCalibrationPlan(const EstimationParameters& parameters, double cell_m,
                                              double max_force_n,
                                              const Eigen::Vector3d& initial_gravity_n,
                                              double field_margin = 1.3);

}  // namespace autograv
