#include "autograv/estimation/vertex_estimator.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "autograv/error.h"

namespace autograv {

namespace {
// Consecutive bad samples tolerated (holding the last force) before the vertex is given up.
constexpr int kMaxInvalidSamples = 20;
// Holding force at the actuator limit for this long (at 1 kHz: 50 ms) means the device cannot be
// held at the vertex with the force it has, and the estimate is corrupted by saturation (paper
// Sec. IV: the proofs hold only without saturation).
constexpr int kMaxSaturatedTicks = 50;

void validate(const EstimationParameters& p, double max_force_n) {
  std::ostringstream problem;
  if (!(p.alpha_per_s > 0.0))
    problem << "EstimationParameters::alpha_per_s must be positive (1/s), e.g. 60; ";
  if (!(p.beta_per_s2 > 0.0))
    problem << "EstimationParameters::beta_per_s2 must be positive (1/s^2), e.g. 900; ";
  if (p.n_g < 1) problem << "EstimationParameters::n_g must be at least 1; ";
  if (!(p.eps_g_n > 0.0)) problem << "EstimationParameters::eps_g_n must be a positive force (N); ";
  if (p.max_iterations < p.n_g)
    problem << "EstimationParameters::max_iterations must be at least EstimationParameters::n_g; ";
  if (!(p.max_step_duration_s > p.min_step_duration_s)) {
    problem << "EstimationParameters::max_step_duration_s must exceed "
               "EstimationParameters::min_step_duration_s; ";
  }
  if (!(max_force_n > 0.0)) problem << "the device's max force must be positive (N); ";
  if (p.method == EstimationMethod::kDither) {
    if (!(p.dither_amplitude_n >= 0.0))
      problem << "EstimationParameters::dither_amplitude_n must be >= 0 (N); ";
    if (!(p.dither_amplitude_n < 0.5 * max_force_n)) {
      problem << "EstimationParameters::dither_amplitude_n must stay below half the device's max "
                 "force, "
              << 0.5 * max_force_n << " N; ";
    }
    if (p.steady_windows < 1)
      problem << "EstimationParameters::steady_windows must be at least 1; ";
    if (p.final_steady_windows < 1)
      problem << "EstimationParameters::final_steady_windows must be at least 1; ";
  }
  if (!problem.str().empty()) throw Error("vertex estimator: " + problem.str());
}

constexpr double kPi = 3.14159265358979323846;
constexpr double kWindowToleranceOfEpsG = 0.25;
}  // namespace

VertexEstimator::VertexEstimator(const EstimationParameters& parameters, double max_force_n)
    : parameters_(parameters),
      max_force_n_(max_force_n),
      detector_(SteadyStateDetector::forParameters(parameters)) {
  validate(parameters, max_force_n);
  if (parameters.method == EstimationMethod::kDither) {
    dither_amplitude_n_ = parameters.dither_amplitude_n > 0.0
                              ? parameters.dither_amplitude_n
                              : EstimationParameters::kAutoDitherFraction * max_force_n;
    dither_step_rad_ = 2.0 * kPi * parameters.dither_frequency_hz * parameters.servo_period_s;
  }
  estimate_.history.reserve(static_cast<std::size_t>(parameters.max_iterations));
}

void VertexEstimator::setGains(const Eigen::Vector3d& gravity_n) noexcept {
  // Constraint (6): the gains need |G_hat| > 0; a floor keeps the loop controllable.
  const double mass_kg = std::max(gravity_n.norm(), kMinGravityN) / kStandardGravity;
  stiffness_n_per_m_ = parameters_.beta_per_s2 * mass_kg;
  damping_n_s_per_m_ = parameters_.alpha_per_s * mass_kg;
  // Eq. 12 turns a mean position into a force through K_P: window means that would move the update
  // by less than a quarter of eps_G already agree, however soft K_P makes that in millimetres.
  detector_.setWindowTolerance_m(kWindowToleranceOfEpsG * parameters_.eps_g_n / stiffness_n_per_m_);
}

void VertexEstimator::start(const Eigen::Vector3d& vertex_m,
                            const Eigen::Vector3d& initial_gravity_n) noexcept {
  vertex_m_ = vertex_m;
  gravity_n_ = initial_gravity_n;
  setGains(initial_gravity_n);  // eqs. (8) and (13)
  estimate_.gravity_n = initial_gravity_n;
  estimate_.iterations = 0;
  estimate_.seconds = 0.0;
  estimate_.outcome = VertexOutcome::kPending;
  estimate_.history.clear();  // keeps the reserved capacity
  last_error_m_ = NAN;
  last_force_n_.setZero();
  ticks_ = 0;
  small_updates_ = 0;
  stalled_updates_ = 0;
  last_update_n_ = 0.0;
  saturated_ticks_ = 0;
  invalid_samples_ = 0;
  finished_ = false;
  detector_.reset();
  detector_.setRequired(requiredSteadyCount(false));
  dither_ticks_ = 0;
}

Eigen::Vector3d VertexEstimator::ditherForce_n() const noexcept {
  // x and y in quadrature at f, z at 3f: only odd harmonics, so d(t + T/2) = -d(t). Every joint
  // torque J^T d is then half-wave symmetric too, the motion it drives is symmetric and the dry
  // friction averages to zero over whole periods; the force direction sweeps all of space, so no
  // joint is left undithered.
  const double angle_rad = dither_step_rad_ * static_cast<double>(dither_ticks_);
  const double sine = std::sin(angle_rad);
  const double triple = sine * (3.0 - 4.0 * sine * sine);  // sin(3 angle)
  return dither_amplitude_n_ * Eigen::Vector3d(sine, std::cos(angle_rad), triple);
}

int VertexEstimator::requiredSteadyCount(bool last_update_small) const noexcept {
  if (parameters_.method == EstimationMethod::kPaper) return parameters_.n_s;
  return last_update_small ? parameters_.final_steady_windows : parameters_.steady_windows;
}

void VertexEstimator::finish(VertexOutcome outcome) noexcept {
  estimate_.outcome = outcome;
  estimate_.gravity_n = gravity_n_;
  finished_ = true;
}

VertexEstimator::Status VertexEstimator::step(const ServoSample& sample,
                                              Eigen::Vector3d& force_n) noexcept {
  if (finished_) {
    // Keep holding the vertex with the final estimate until the caller moves on.
    force_n = last_force_n_;
    return Status::kSettling;
  }
  ++ticks_;
  estimate_.seconds = ticks_ * parameters_.servo_period_s;
  if (!sample.valid) {
    force_n = last_force_n_;
    if (++invalid_samples_ > kMaxInvalidSamples) {
      force_n.setZero();
      finish(VertexOutcome::kDeviceFault);
      return Status::kDeviceFault;
    }
    return Status::kSettling;
  }
  invalid_samples_ = 0;

  // eq. (10), plus the zero-mean dither of the dither method
  force_n = stiffness_n_per_m_ * (vertex_m_ - sample.position_m) -
            damping_n_s_per_m_ * sample.velocity_m_per_s + gravity_n_;
  if (dither_amplitude_n_ > 0.0) {
    force_n += ditherForce_n();
    ++dither_ticks_;
  }
  saturated_ticks_ = clampForce(force_n, max_force_n_) ? saturated_ticks_ + 1 : 0;
  last_force_n_ = force_n;
  if (saturated_ticks_ > kMaxSaturatedTicks) {
    finish(VertexOutcome::kUnreachable);
    return Status::kUnreachable;
  }

  if (!detector_.update(sample.position_m, sample.velocity_m_per_s)) {
    if (detector_.elapsed_s() > parameters_.max_step_duration_s) {
      // Far from X_i the hold failed because the device cannot get there (bouncing on a rubber
      // end stop, buzzing at a joint limit); close to it, the estimator merely missed its steady
      // state (encoder dither) and a second visit may settle.
      if ((sample.position_m - vertex_m_).norm() > kUnreachableGap_m) {
        finish(VertexOutcome::kUnreachable);
        return Status::kUnreachable;
      }
      finish(VertexOutcome::kNoSteadyState);
      return Status::kNoSteadyState;
    }
    return Status::kSettling;
  }

  // Steady state of iteration j: eq. (12), then gains for j+1 from G_hat_j (eq. 11).
  const Eigen::Vector3d settled_m = detector_.settledPosition_m();
  const Eigen::Vector3d previous_n = gravity_n_;
  const Eigen::Vector3d updated_n = stiffness_n_per_m_ * (vertex_m_ - settled_m) + previous_n;
  last_error_m_ = (vertex_m_ - settled_m).norm();
  IterationRecord record;
  record.position_error_m = last_error_m_;
  record.mass_estimate_kg = updated_n.norm() / kStandardGravity;
  record.gravity_estimate_n = updated_n;
  record.duration_s = detector_.elapsed_s();
  if (estimate_.history.size() < estimate_.history.capacity()) estimate_.history.push_back(record);
  ++estimate_.iterations;
  setGains(previous_n);
  gravity_n_ = updated_n;
  estimate_.gravity_n = updated_n;
  const double update_n = (updated_n - previous_n).norm();
  const bool small_update = update_n <= parameters_.eps_g_n;
  detector_.reset();
  detector_.setRequired(requiredSteadyCount(small_update));
  dither_ticks_ = 0;  // the next window starts at phase 0 again

  small_updates_ = small_update ? small_updates_ + 1 : 0;
  const double stall_floor_n = std::max(kStallUpdateFloor_n, 4.0 * parameters_.eps_g_n);
  const bool stalled = estimate_.iterations > 1 && update_n > stall_floor_n &&
                       update_n >= kStallRatio * last_update_n_;
  stalled_updates_ = stalled ? stalled_updates_ + 1 : 0;
  last_update_n_ = update_n;
  if (stalled_updates_ >= kStalledUpdates) {
    finish(VertexOutcome::kUnreachable);
    return Status::kUnreachable;
  }
  if (small_updates_ >= parameters_.n_g) {
    finish(VertexOutcome::kConverged);
    return Status::kConverged;
  }
  if (estimate_.iterations >= parameters_.max_iterations) {
    finish(VertexOutcome::kIterationCap);
    return Status::kIterationCap;
  }
  return Status::kUpdated;
}

const char* toString(EstimationMethod method) noexcept {
  switch (method) {
    case EstimationMethod::kPaper:
      return "paper";
    case EstimationMethod::kDither:
      return "dither";
  }
  return "unknown";
}

EstimationMethod parseEstimationMethod(const std::string& name) {
  for (const EstimationMethod method : {EstimationMethod::kPaper, EstimationMethod::kDither}) {
    if (name == toString(method)) return method;
  }
  throw Error("unknown estimation method '" + name + "'; valid: paper, dither");
}

const char* toString(VertexEstimator::Status status) noexcept {
  switch (status) {
    case VertexEstimator::Status::kSettling:
      return "settling";
    case VertexEstimator::Status::kUpdated:
      return "updated";
    case VertexEstimator::Status::kConverged:
      return "converged";
    case VertexEstimator::Status::kIterationCap:
      return "iteration_cap";
    case VertexEstimator::Status::kNoSteadyState:
      return "no_steady_state";
    case VertexEstimator::Status::kUnreachable:
      return "unreachable";
    case VertexEstimator::Status::kDeviceFault:
      return "device_fault";
  }
  return "unknown";
}

}  // namespace autograv
