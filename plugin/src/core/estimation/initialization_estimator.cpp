#include "autograv/estimation/initialization_estimator.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "autograv/device/servo_sample.h"
#include "autograv/error.h"
#include "autograv/estimation/impedance_hold.h"
#include "core/estimation/steady_state_detector.h"

namespace autograv {

/// Everything an InitializationEstimator keeps.
struct InitializationEstimator::Impl {
  Impl(const EstimationParameters& parameters, double max_force_n, double ramp_s,
       double damping_n_s_per_m);
  void start(const Eigen::Vector3d& center_m) noexcept;
  Status step(const ServoSample& sample, Eigen::Vector3d& force_n) noexcept;

  EstimationParameters parameters_;
  double max_force_n_;
  double damping_n_s_per_m_;
  double ramp_periods_;           // fade-in time, in nominal servo periods
  double max_invalid_periods_;    // bad samples tolerated, in nominal servo periods
  double elapsed_periods_ = 0.0;  // servo time since start(), valid samples only
  SteadyStateDetector detector_;
  Eigen::Vector3d center_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d estimate_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_force_n_ = Eigen::Vector3d::Zero();
  double sag_m_ = 0.0;
  double invalid_periods_ = 0.0;
  bool done_ = false;
};

InitializationEstimator::Impl::Impl(const EstimationParameters& parameters, double max_force_n,
                                    double ramp_s, double damping_n_s_per_m)
    : parameters_(parameters),
      max_force_n_(max_force_n),
      damping_n_s_per_m_(damping_n_s_per_m),
      ramp_periods_(
          static_cast<double>(std::max(1L, std::lround(ramp_s / parameters.servo_period_s)))),
      max_invalid_periods_(maxInvalidPeriods(parameters.servo_period_s)),
      detector_(SteadyStateDetector::forParameters(parameters)) {
  if (!(parameters.k0_n_per_m > 0.0))
    throw Error(
        "initialization: EstimationParameters::k0_n_per_m must be positive (N/m), e.g. 300");
  if (!(max_force_n > 0.0)) throw Error("initialization: the device's max force must be positive");
  if (!(damping_n_s_per_m >= 0.0)) throw Error("initialization: damping must be >= 0 (N s/m)");
  // Eq. 7 turns the settled position into a force through k0 (see VertexEstimator::setGains).
  detector_.setWindowTolerance_m(0.25 * parameters.eps_g_n / parameters.k0_n_per_m);
}

void InitializationEstimator::Impl::start(const Eigen::Vector3d& center_m) noexcept {
  center_m_ = center_m;
  elapsed_periods_ = 0.0;
  done_ = false;
  invalid_periods_ = 0.0;
  sag_m_ = 0.0;
  estimate_n_.setZero();
  last_force_n_.setZero();
  detector_.reset();
}

InitializationEstimator::Status InitializationEstimator::Impl::step(
    const ServoSample& sample, Eigen::Vector3d& force_n) noexcept {
  const double periods = servoPeriodsOf(sample, parameters_.servo_period_s);
  if (!sample.valid) {
    force_n = last_force_n_;
    invalid_periods_ += periods;
    if (invalid_periods_ > max_invalid_periods_) {
      force_n.setZero();
      return Status::kDeviceFault;
    }
    return done_ ? Status::kDone : Status::kWaiting;
  }
  invalid_periods_ = 0.0;
  elapsed_periods_ += periods;
  const double ramp = std::min(1.0, elapsed_periods_ / ramp_periods_);
  const Eigen::Vector3d offset_m = center_m_ - sample.position_m;
  sag_m_ = offset_m.norm();
  force_n =
      ramp * (parameters_.k0_n_per_m * offset_m - damping_n_s_per_m_ * sample.velocity_m_per_s);
  clampForce(force_n, max_force_n_);
  last_force_n_ = force_n;
  if (done_) return Status::kDone;
  if (ramp < 1.0) return Status::kRampingIn;
  if (!detector_.update(sample.position_m, sample.velocity_m_per_s, sample.interval_s)) {
    return Status::kWaiting;
  }
  const Eigen::Vector3d estimate_n =
      parameters_.k0_n_per_m * (center_m_ - detector_.settledPosition_m());  // eq. (7)
  if (estimate_n.norm() < kMinGravityN) {
    // Settled right on the centre: something (the hand) is carrying the weight. Keep watching.
    detector_.reset();
    return Status::kStillHeld;
  }
  estimate_n_ = estimate_n;
  done_ = true;
  return Status::kDone;
}

// --- The public class: each call goes to the Impl ---------------------------------------------

InitializationEstimator::InitializationEstimator(const EstimationParameters& parameters,
                                                 double max_force_n, double ramp_s,
                                                 double damping_n_s_per_m)
    : impl_(std::make_unique<Impl>(parameters, max_force_n, ramp_s, damping_n_s_per_m)) {}

InitializationEstimator::~InitializationEstimator() = default;
InitializationEstimator::InitializationEstimator(InitializationEstimator&&) noexcept = default;
InitializationEstimator& InitializationEstimator::operator=(InitializationEstimator&&) noexcept =
    default;

void InitializationEstimator::start(const Eigen::Vector3d& center_m) noexcept {
  impl_->start(center_m);
}

InitializationEstimator::Status InitializationEstimator::step(const ServoSample& sample,
                                                              Eigen::Vector3d& force_n) noexcept {
  return impl_->step(sample, force_n);
}

const Eigen::Vector3d& InitializationEstimator::gravityEstimate_n() const noexcept {
  return impl_->estimate_n_;
}

const Eigen::Vector3d& InitializationEstimator::center_m() const noexcept {
  return impl_->center_m_;
}

double InitializationEstimator::sag_m() const noexcept { return impl_->sag_m_; }

}  // namespace autograv
