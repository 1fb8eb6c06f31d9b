#pragma once

#include <cstdint>
#include <string>

namespace autograv {

/// Standard gravity used by the paper to turn a force into an apparent mass. Unit: [m/s^2]
inline constexpr double kStandardGravity = 9.81;

/// How each iteration reaches its steady state (README, "Calibrating through friction").
enum class EstimationMethod : std::uint8_t {
  /// Eqs. 7-13 as written: the steady state is n_S consecutive velocity samples under eps_S, and
  /// eq. 12 reads the position there. Dry friction stops the end-effector anywhere in its dead
  /// band, so each update is off by up to the breakaway force.
  kPaper,
  /// The same recursion (eqs. 10-13) with a zero-mean, half-wave-symmetric dither force added to
  /// eq. 10 so that the joints keep sliding and the friction averages out; the steady state is
  /// the mean position over whole dither periods, which eq. 12 uses.
  kDither,
};

/// "paper" or "dither".
const char* toString(EstimationMethod method) noexcept;
/// Inverse of toString; throws autograv::Error listing the valid names.
EstimationMethod parseEstimationMethod(const std::string& name);

/// User-defined parameters of the iterative estimation (paper Sections II-III). The defaults are
/// what every tool uses: the paper's Section V values converted to SI units, with the
/// friction-robust dither method and n_G = 3 (every dithered update is an average over whole
/// periods, so three small updates in a row are as telling as the paper's five noisy ones).
/// paper() gives eqs. 7-13 exactly as published.
struct EstimationParameters {
  /// How each iteration reaches its steady state.
  EstimationMethod method = EstimationMethod::kDither;
  /// Closed-loop damping of Xdd = beta (X_D - X) - alpha Xd; K_D = alpha M. Unit: [1/s]
  double alpha_per_s = 40.0;
  /// Closed-loop stiffness; K_P = beta M. Unit: [1/s^2]
  double beta_per_s2 = 700.0;
  /// Stiffness of the manual-initialization spring field (eq. 7). Unit: [N/m] (paper: 0.5 N/mm)
  double k0_n_per_m = 500.0;
  /// Consecutive velocity samples under eps_s that make a steady state.
  int n_s = 20;
  /// Steady-state speed threshold. Unit: [m/s] (paper: 0.1 mm/s)
  double eps_s_m_per_s = 1.0e-4;
  /// Consecutive estimate updates under eps_g that end the inner loop (paper: 5).
  int n_g = 3;
  /// Estimate-change threshold. Unit: [N] (paper: 0.5 g-force = 4.905 mN)
  double eps_g_n = 0.5e-3 * kStandardGravity;
  /// Lower bound on the duration of one iteration (the paper used 100 ms). Unit: [s]
  double min_step_duration_s = 0.1;
  /// Upper bound on the duration of one iteration before the vertex is given up. Unit: [s]
  double max_step_duration_s = 10.0;
  /// Inner-loop iteration cap; a vertex that reaches it is marked and skipped.
  int max_iterations = 60;
  /// Servo period. Unit: [s]
  double servo_period_s = 1.0e-3;
  /// Prior on the Lipschitz constant c of G(X), used by the convergence check before any data
  /// exists; refined from neighbouring vertices as the grid fills. Unit: [N/m]
  double lipschitz_prior_n_per_m = 10.0;

  // Dither method only (kDither).
  /// Amplitude of the dither force on each axis; 0 lets the inner loop pick it at each vertex:
  /// kAutoDitherFraction of the device's maximum force, above the breakaway force of the devices
  /// we model, lowered to keep G_hat plus the dither within the continuous force rating, but not
  /// below kMinAutoDither_n. Unit: [N]
  double dither_amplitude_n = 0.0;
  /// Base frequency: x and y are driven in quadrature at f, z at 3f (odd harmonics only, so the
  /// force and hence the motion are half-wave symmetric and the friction cancels). Well above the
  /// PD's bandwidth (sqrt(beta)/(2 pi), about 4 Hz with the paper's beta). Unit: [Hz]
  double dither_frequency_hz = 20.0;
  /// Whole dither periods in one averaging window.
  int dither_periods_per_window = 1;
  /// Consecutive window pairs whose means agree within eps_S times the window duration that
  /// make a steady state (the counterpart of n_S).
  int steady_windows = 2;
  /// The same once the last update was under eps_G: the estimate that may end the vertex is read
  /// over more windows, so the dither's period-to-period scatter averages out, while the first,
  /// large updates stay quick.
  int final_steady_windows = 4;

  /// Largest automatic dither amplitude, as a fraction of the device's maximum force.
  static constexpr double kAutoDitherFraction = 0.09;
  /// Smallest automatic dither amplitude when the continuous rating leaves less room: above the
  /// breakaway force of the devices we model at `high` friction (190 mN on sim:omni); a smaller
  /// dither no longer breaks their friction, and an estimate that friction biases is not worth
  /// the budget. Set dither_amplitude_n for a device whose friction is larger. Unit: [N]
  static constexpr double kMinAutoDither_n = 0.23;

  /// The paper's method exactly as published (Section V's values, n_G = 5, no dither): what
  /// `paper-experiment` runs. Dry friction biases each of its updates by up to the breakaway
  /// force, so calibrate real devices with the defaults.
  static EstimationParameters paper() {
    EstimationParameters parameters;
    parameters.method = EstimationMethod::kPaper;
    parameters.n_g = 5;
    return parameters;
  }
  /// The defaults (the dither method). Kept for programs written when the defaults were the
  /// paper's method.
  static EstimationParameters frictionRobust() { return EstimationParameters{}; }
};

}  // namespace autograv
