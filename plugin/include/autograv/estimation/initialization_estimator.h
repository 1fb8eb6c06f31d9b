#pragma once

#include <cstdint>
#include <memory>

#include <Eigen/Core>

#include "autograv/device/servo_sample.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv {

/// Paper Section III-A, the manual initialization: a spring field of stiffness k0 centred on the
/// point X0 the user chose holds the released end-effector; at steady state
/// G_hat_0 = k0 (X0 - X_inf) (eq. 7). The field is ramped in so the user feels no jolt.
/// Its state lives in a private Impl that the constructor allocates.
class InitializationEstimator {
 public:
  /// Where the manual initialization stands (WizardStatus::release_status).
  enum class Status : std::uint8_t {
    kRampingIn,    ///< The field is coming on; keep holding.
    kWaiting,      ///< Field on; waiting for the released end-effector to settle.
    kStillHeld,    ///< Settled with almost no sag: the hand is still holding it. Let go.
    kDone,         ///< G_hat_0 is available.
    kDeviceFault,  ///< The device stopped answering or sent non-finite samples.
  };

  /// Uses k0, n_S, eps_S, the minimum step duration and the servo period of `parameters`.
  /// `damping_n_s_per_m` adds light viscous damping to the field: it does not move the steady
  /// state (eq. 7 holds unchanged) but lets a device with little friction settle. `ramp_s` is the
  /// fade-in time of the field. Throws autograv::Error on bad parameters. Not real-time safe.
  InitializationEstimator(const EstimationParameters& parameters, double max_force_n,
                          double ramp_s = 0.3, double damping_n_s_per_m = 5.0);
  ~InitializationEstimator();
  /// Moves the estimator; the moved-from one may only be destroyed or assigned to.
  InitializationEstimator(InitializationEstimator&&) noexcept;
  /// Moves the estimator; the moved-from one may only be destroyed or assigned to.
  InitializationEstimator& operator=(InitializationEstimator&&) noexcept;

  /// Centres the field on `center_m` (X0) and starts ramping it in. Real-time safe.
  void start(const Eigen::Vector3d& center_m) noexcept;
  /// One servo tick: returns the field force to send and the status. Real-time safe.
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;

  /// G_hat_0 (eq. 7), valid once step() returned kDone. Real-time safe. Unit: [N]
  const Eigen::Vector3d& gravityEstimate_n() const noexcept;
  /// Centre X0 of the spring field, as given to start(). Real-time safe. Unit: [m]
  const Eigen::Vector3d& center_m() const noexcept;
  /// Current sag of the end-effector below the field centre. Real-time safe. Unit: [m]
  double sag_m() const noexcept;
  /// Smallest |G_hat_0| accepted (constraint 6 of the paper). Unit: [N]
  static constexpr double kMinGravityN = 0.02;

 private:
  struct Impl;  // the estimator's state (plugin/src/core/estimation/initialization_estimator.cpp)
  std::unique_ptr<Impl> impl_;
};

}  // namespace autograv
