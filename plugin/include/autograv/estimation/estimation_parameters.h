#pragma once

namespace autograv {

/// Standard gravity used by the paper to turn a force into an apparent mass. Unit: [m/s^2]
inline constexpr double kStandardGravity = 9.81;

/// User-defined parameters of the iterative estimation (paper Sections II-III). Defaults are the
/// paper's Section V values converted to SI units.
struct EstimationParameters {
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
  /// Consecutive estimate updates under eps_g that end the inner loop.
  int n_g = 5;
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
};

}  // namespace autograv
