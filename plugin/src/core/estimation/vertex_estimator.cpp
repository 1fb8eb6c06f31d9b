#include "core/estimation/vertex_estimator.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "autograv/device/device_specifications.h"
#include "autograv/error.h"

namespace autograv {

namespace {
// Holding force at the actuator limit for this long means the device cannot be held at the vertex
// with the force it has, and the estimate is corrupted by saturation (paper Sec. IV: the proofs
// hold only without saturation). Unit: [s]
constexpr double kMaxSaturated_s = 0.05;
// Smoothing of the mean servo interval the dither's payback is spread over.
constexpr double kIntervalSmoothing = 0.05;
// The dither's payback: rate per nominal period (about 3 ms to pay a debt back) and damping.
constexpr double kPaybackRate = 0.3;
constexpr double kPaybackDamping = 0.7;
// Longer intervals (stalls) are not paid back: nominal periods.
constexpr double kMaxDebtIntervalPeriods = 12.0;

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

VertexEstimator::VertexEstimator(const EstimationParameters& parameters, double max_force_n,
                                 double continuous_force_n)
    : parameters_(parameters),
      max_force_n_(max_force_n),
      continuous_force_n_(continuous_force_n > 0.0 ? continuous_force_n
                                                   : kDefaultContinuousForceFraction * max_force_n),
      hold_(ImpedanceHold::from(parameters, kMinGravityN)),
      detector_(SteadyStateDetector::forParameters(parameters)) {
  validate(parameters, max_force_n);
  if (!(continuous_force_n >= 0.0) || !std::isfinite(continuous_force_n)) {
    throw Error("VertexEstimator: the continuous force rating must be finite and >= 0 N, not " +
                std::to_string(continuous_force_n));
  }
  if (parameters.method == EstimationMethod::kDither) {
    dither_amplitude_n_ =
        parameters.dither_amplitude_n > 0.0
            ? parameters.dither_amplitude_n
            : EstimationParameters::kAutoDitherFraction * max_force_n;  // set per vertex
    dither_step_rad_ = 2.0 * kPi * parameters.dither_frequency_hz * parameters.servo_period_s;
  }
  max_invalid_periods_ = maxInvalidPeriods(parameters.servo_period_s);
  max_saturated_periods_ = kMaxSaturated_s / parameters.servo_period_s + kServoTimeSlackPeriods;
  estimate_.history.reserve(static_cast<std::size_t>(parameters.max_iterations));
}

void VertexEstimator::setGains(const Eigen::Vector3d& gravity_n) noexcept {
  // Constraint (6): the gains need |G_hat| > 0; the hold's floor keeps the loop controllable.
  mass_kg_ = hold_.apparentMass_kg(gravity_n);
  stiffness_n_per_m_ = hold_.stiffness_n_per_m(mass_kg_);
  // Eq. 12 turns a mean position into a force through K_P: window means that would move the update
  // by less than a quarter of eps_G already agree, however soft K_P makes that in millimetres.
  detector_.setWindowTolerance_m(kWindowToleranceOfEpsG * parameters_.eps_g_n / stiffness_n_per_m_);
}

double VertexEstimator::automaticDitherAmplitude_n(double max_force_n, double continuous_force_n,
                                                   double gravity_n) noexcept {
  const double largest = EstimationParameters::kAutoDitherFraction * max_force_n;
  const double smallest = std::min(EstimationParameters::kMinAutoDither_n, largest);
  // |d| = A sqrt(1 + sin^2 3wt) peaks at sqrt(2) A (ditherForce_n).
  const double within_rating =
      (kContinuousForceMargin * continuous_force_n - gravity_n) / std::sqrt(2.0);
  return std::clamp(within_rating, smallest, largest);
}

void VertexEstimator::start(const Eigen::Vector3d& vertex_m,
                            const Eigen::Vector3d& initial_gravity_n) noexcept {
  if (parameters_.method == EstimationMethod::kDither && !(parameters_.dither_amplitude_n > 0.0)) {
    dither_amplitude_n_ =
        automaticDitherAmplitude_n(max_force_n_, continuous_force_n_, initial_gravity_n.norm());
  }
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
  elapsed_periods_ = 0.0;
  small_updates_ = 0;
  stalled_updates_ = 0;
  last_update_n_ = 0.0;
  last_raw_update_n_.setZero();
  relaxation_ = 1.0;
  last_settled_m_.setZero();
  last_previous_n_ = initial_gravity_n;
  stop_contact_ = false;
  outward_.setZero();
  push_direction_.setZero();
  push_phase_ = PushPhase::kNone;
  push_outward_moved_m_.setZero();
  push_inward_moved_m_.setZero();
  initial_gravity_n_ = initial_gravity_n;
  creep_count_ = 0;
  creep_probe_ = false;
  creep_probe_offset_m_.setZero();
  stop_second_look_ = false;
  swing_estimates_ = 0;
  contact_position_m_.setZero();
  contact_direction_.setZero();
  gravity_before_contact_n_ = initial_gravity_n;
  saturated_periods_ = 0.0;
  invalid_periods_ = 0.0;
  finished_ = false;
  restartObservation(requiredSteadyCount(false));
  dither_displacement_debt_.setZero();
  last_dither_n_.setZero();
  hold_started_ = false;
  hold_debt_ns_.setZero();
  last_hold_payback_n_.setZero();
}

Eigen::Vector3d VertexEstimator::ditherForce_n(double cell) const noexcept {
  // x and y in quadrature at f, z at 3f: only odd harmonics, so d(t + T/2) = -d(t). Every joint
  // torque J^T d is then half-wave symmetric too, the motion it drives is symmetric and the dry
  // friction averages to zero over whole periods; the force direction sweeps all of space, so no
  // joint is left undithered.
  const double angle_rad = dither_step_rad_ * cell;
  const double sine = std::sin(angle_rad);
  const double triple = sine * (3.0 - 4.0 * sine * sine);  // sin(3 angle)
  return dither_amplitude_n_ * Eigen::Vector3d(sine, std::cos(angle_rad), triple);
}

Eigen::Vector3d VertexEstimator::ditherImpulse_ns(double from, double to) const noexcept {
  // The waveform an exact loop sends, one value per nominal period, integrated over [from, to]
  // (in nominal periods since the iteration's first sample). Unit: [N period]
  Eigen::Vector3d impulse = Eigen::Vector3d::Zero();
  const double first = std::floor(from + kServoTimeSlackPeriods);
  const double last = std::ceil(to - kServoTimeSlackPeriods);
  for (double cell = first; cell < last; cell += 1.0) {
    const double overlap = std::min(to, cell + 1.0) - std::max(from, cell);
    if (overlap > 0.0) impulse += ditherForce_n(cell) * overlap;
  }
  return impulse;
}

Eigen::Vector3d VertexEstimator::ditherWaveform_n(double periods,
                                                  Eigen::Vector3d& payback_n) noexcept {
  // The dither is a function of servo time: the value an exact loop would send in the nominal
  // period the tick falls in. A late, early or stalled tick holds its command longer or shorter
  // than one period, which a loop that ticks irregularly turns into a random impulse on the
  // end-effector (and a dither that no longer averages to zero over a window): each command pays
  // back what its predecessors delivered too much or too little, so the impulse sent follows the
  // waveform's. On an exact loop the debt is exactly zero, always.
  if (dither_started_) {
    const double from = dither_periods_;
    dither_periods_ += periods;
    mean_interval_periods_ += kIntervalSmoothing * (periods - mean_interval_periods_);
    if (periods <= kMaxDebtIntervalPeriods) {
      const Eigen::Vector3d before = dither_debt_ns_;
      dither_debt_ns_ += last_dither_n_ * periods - ditherImpulse_ns(from, dither_periods_);
      dither_displacement_debt_ += 0.5 * (before + dither_debt_ns_) * periods;
    } else {
      dither_debt_ns_.setZero();  // a stall: the detector does not trust its windows anyway
      dither_displacement_debt_.setZero();
    }
  }
  dither_started_ = true;
  const Eigen::Vector3d waveform_n =
      ditherForce_n(std::floor(dither_periods_ + kServoTimeSlackPeriods));
  // Both the impulse debt and its integral (what it did to the position, times the mass) are
  // paid back, critically damped at kPaybackRate per nominal period: the end-effector ends up
  // where the exact waveform would have put it, not merely at its velocity.
  payback_n = 2.0 * kPaybackDamping * kPaybackRate * dither_debt_ns_ +
              kPaybackRate * kPaybackRate * dither_displacement_debt_;
  payback_n = payback_n.cwiseMax(-dither_amplitude_n_).cwiseMin(dither_amplitude_n_);
  return waveform_n;
}

Eigen::Vector3d VertexEstimator::holdPayback_n(const Eigen::Vector3d& feedback_n,
                                               double periods) noexcept {
  // The feedback force moves quickly under the dither (the damping term follows the dithered
  // velocity): held for an interval longer or shorter than one period it delivers more or less of
  // its old value than an exact loop would, a random impulse on a jittery loop. With the force
  // taken as linear between two ticks, the excess is half its change times the hold's deviation
  // from one period; it is paid back as the dither's is (zero on an exact loop).
  if (hold_started_ && periods <= kMaxDebtIntervalPeriods) {
    hold_debt_ns_ +=
        -last_hold_payback_n_ * periods + 0.5 * (last_feedback_n_ - feedback_n) * (periods - 1.0);
  } else {
    hold_debt_ns_.setZero();
  }
  hold_started_ = true;
  last_feedback_n_ = feedback_n;
  Eigen::Vector3d payback_n = (0.5 / mean_interval_periods_) * hold_debt_ns_;
  payback_n = payback_n.cwiseMax(-dither_amplitude_n_).cwiseMin(dither_amplitude_n_);
  last_hold_payback_n_ = payback_n;
  return payback_n;
}

Eigen::Vector3d VertexEstimator::ditheredHoldForce_n(const Eigen::Vector3d& feedback_n,
                                                     double periods) noexcept {
  const Eigen::Vector3d hold_payback_n = holdPayback_n(feedback_n, periods);
  Eigen::Vector3d dither_payback_n;
  const Eigen::Vector3d waveform_n = ditherWaveform_n(periods, dither_payback_n);
  const Eigen::Vector3d planned_n = feedback_n + waveform_n;
  // Each payback may reach one dither amplitude, on a command whose peaks the automatic dither
  // already plans near the continuous rating: on a jittery loop the paybacks alone would keep
  // the device above its rating (sim:omni on a desktop loop: 6-7 % of a calibration). Send the
  // share of them that keeps the command within the rating; an exact loop owes nothing, and its
  // command is the hold plus the waveform, bit for bit.
  const Eigen::Vector3d payback_n = -hold_payback_n - dither_payback_n;
  double share = 1.0;
  const double limit_n = continuous_force_n_;
  if ((planned_n + payback_n).norm() > limit_n) {
    const double a = payback_n.squaredNorm();
    const double b = planned_n.dot(payback_n);
    const double c = planned_n.squaredNorm() - limit_n * limit_n;
    // |planned + s payback| = limit for s in [0, 1]; none when planned is beyond it already.
    share =
        c >= 0.0 || !(a > 0.0) ? 0.0 : std::clamp((-b + std::sqrt(b * b - a * c)) / a, 0.0, 1.0);
  }
  last_hold_payback_n_ = share * hold_payback_n;
  last_dither_n_ = waveform_n - share * dither_payback_n;
  return planned_n + share * payback_n;
}

int VertexEstimator::requiredSteadyCount(bool last_update_small) const noexcept {
  if (parameters_.method == EstimationMethod::kPaper) return parameters_.n_s;
  return last_update_small ? parameters_.final_steady_windows : parameters_.steady_windows;
}

void VertexEstimator::restartObservation(int required_steady) noexcept {
  detector_.reset();
  detector_.setRequired(required_steady);
  dither_periods_ = 0.0;  // the next window starts at phase 0 again
  dither_started_ = false;
  dither_debt_ns_.setZero();
}

void VertexEstimator::finish(VertexOutcome outcome) noexcept {
  estimate_.outcome = outcome;
  estimate_.gravity_n = gravity_n_;
  finished_ = true;
}

VertexEstimator::Status VertexEstimator::endAgainstStop(
    const Eigen::Vector3d& contact_m, const Eigen::Vector3d& direction,
    const Eigen::Vector3d& gravity_before_n) noexcept {
  stop_contact_ = true;
  contact_position_m_ = contact_m;
  contact_direction_ = direction;
  gravity_before_contact_n_ = gravity_before_n;
  gravity_n_ = gravity_before_n;  // the stop's reaction is no part of G
  finish(VertexOutcome::kUnreachable);
  return Status::kUnreachable;
}

VertexEstimator::Status VertexEstimator::step(const ServoSample& sample,
                                              Eigen::Vector3d& force_n) noexcept {
  if (finished_) {
    // Keep holding the vertex with the final estimate until the caller moves on.
    force_n = last_force_n_;
    return Status::kSettling;
  }
  const double periods = servoPeriodsOf(sample, parameters_.servo_period_s);
  elapsed_periods_ += periods;
  estimate_.seconds = elapsed_periods_ * parameters_.servo_period_s;
  if (!sample.valid) {
    force_n = last_force_n_;
    invalid_periods_ += periods;
    if (invalid_periods_ > max_invalid_periods_) {
      force_n.setZero();
      finish(VertexOutcome::kDeviceFault);
      return Status::kDeviceFault;
    }
    return Status::kSettling;
  }
  invalid_periods_ = 0.0;

  // eq. (10), plus the zero-mean dither of the dither method
  force_n = hold_.holdForce_n(vertex_m_ + creep_probe_offset_m_, sample, mass_kg_, gravity_n_);
  if (dither_amplitude_n_ > 0.0) force_n = ditheredHoldForce_n(force_n, periods);
  saturated_periods_ = clampForce(force_n, max_force_n_) ? saturated_periods_ + periods : 0.0;
  last_force_n_ = force_n;
  if (saturated_periods_ > max_saturated_periods_) {
    finish(VertexOutcome::kUnreachable);
    return Status::kUnreachable;
  }

  if (!detector_.update(sample.position_m, sample.velocity_m_per_s, sample.interval_s)) {
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

  if (stop_second_look_ &&
      (elapsed_periods_ - second_look_start_periods_) * parameters_.servo_period_s <
          kStopSecondLook_s) {
    // Too early for the second look: a creeping end-effector needs time to show it moves.
    restartObservation(requiredSteadyCount(true));
    return Status::kSettling;
  }
  // Steady state of iteration j: eq. (12), then gains for j+1 from G_hat_j (eq. 11).
  const Eigen::Vector3d settled_m = detector_.settledPosition_m();
  if (push_phase_ != PushPhase::kNone) return pushSettled(settled_m);
  if (creep_probe_) {
    // The push test's steady state (kCreepProbe_m): a stop hardly lets the end-effector follow.
    const Eigen::Vector3d direction = creep_probe_offset_m_.normalized();
    const double moved_m = (settled_m - creep_probe_base_m_).dot(direction);
    creep_probe_ = false;
    creep_probe_offset_m_.setZero();
    if (moved_m < kCreepFollow * kCreepProbe_m) {
      return endAgainstStop(creep_probe_base_m_, direction, creep_start_gravity_n_);
    }
    creep_count_ = 0;  // free space (friction): iterate on from here
    restartObservation(requiredSteadyCount(false));
    return Status::kSettling;
  }
  const Eigen::Vector3d previous_n = gravity_n_;
  const Eigen::Vector3d raw_update_n = stiffness_n_per_m_ * (vertex_m_ - settled_m);
  const double update_n = raw_update_n.norm();
  const double stall_floor_n = std::max(kStallUpdateFloor_n, 4.0 * parameters_.eps_g_n);
  // A step that reverses the last one and stays large: eq. (12) overshoots (kOvershootRatio).
  // With relaxation w the observed ratio of raw steps is 1 + w (r - 1), r the unrelaxed one, so
  // w / (1 - ratio) is the relaxation that cancels it.
  const bool both_large =
      estimate_.iterations > 0 && update_n > stall_floor_n && last_update_n_ > stall_floor_n;
  const double step_ratio =
      both_large ? raw_update_n.dot(last_raw_update_n_) / (last_update_n_ * last_update_n_) : 0.0;
  const bool overshoot = both_large && step_ratio < -kOvershootRatio;
  double relaxation = relaxation_;
  if (overshoot) {
    relaxation = std::clamp(relaxation_ / (1.0 - step_ratio), kMinRelaxation, 1.0);
  } else if (both_large && step_ratio > 0.0 && relaxation_ < 1.0) {
    // Steps that keep their direction: the relaxation was too strong (or the field changed
    // under the hold); let it back toward 1 by the same rule, at most doubling it.
    relaxation = std::min(1.0, relaxation_ / (1.0 - std::min(step_ratio, 0.5)));
  }
  // A stop: this step pushes the way the last one did, no shorter, and the last one moved the
  // steady state by far less than the hold's spring would have (kStopFollowFraction).
  // Only with the dither: without it, dry friction holds the end-effector as a stop does until
  // the force breaks it away, and the paper's method keeps its slower stall rule.
  const double expected_move_m = relaxation * last_update_n_ / stiffness_n_per_m_;
  const bool pushed_again =
      parameters_.method == EstimationMethod::kDither && both_large && step_ratio >= kStallRatio;
  const bool held_still =
      pushed_again && (settled_m - last_settled_m_).norm() < kStopFollowFraction * expected_move_m;
  if (held_still && !stop_second_look_) {
    // A steady state taken early (a jittery loop's windows) looks the same while the
    // end-effector still creeps toward X_i: look again under the same force, for at least
    // kStopSecondLook_s and over the longer final windows, before calling it a stop. The step
    // is not counted.
    stop_second_look_ = true;
    second_look_start_periods_ = elapsed_periods_;
    restartObservation(requiredSteadyCount(true));
    return Status::kSettling;
  }
  stop_second_look_ = false;
  // The creep rule (kCreepUpdates), along the outward direction only: the steps' sideways parts
  // are the hold's noise.
  if (parameters_.method == EstimationMethod::kDither && estimate_.iterations > 0 &&
      outward_.squaredNorm() > 0.0) {
    const Eigen::Vector3d outward = outward_.normalized();
    const double along_n = raw_update_n.dot(outward);
    const bool large = along_n >= kCreepFloor * parameters_.eps_g_n;
    bool suspected = false;
    if (creep_count_ > 0 && large) {
      const double moved_m = (settled_m - creep_start_settled_m_).dot(outward);
      ++creep_count_;
      suspected = creep_count_ >= kCreepUpdates && creep_expected_m_ >= kCreepMinExpected_m &&
                  moved_m < kCreepSuspectFollow * creep_expected_m_;
    } else if (large) {
      creep_count_ = 1;
      creep_expected_m_ = 0.0;
      creep_start_settled_m_ = settled_m;
      creep_start_gravity_n_ = previous_n;
    } else {
      creep_count_ = 0;
    }
    if (creep_count_ > 0) creep_expected_m_ += relaxation * along_n / stiffness_n_per_m_;
    if (suspected) {
      // The push test, along the outward direction (a jittery loop's steps scatter sideways by
      // more than they push outward); this step is not counted.
      creep_probe_ = true;
      creep_probe_offset_m_ = kCreepProbe_m * outward;
      creep_probe_base_m_ = settled_m;
      restartObservation(requiredSteadyCount(false));
      return Status::kSettling;
    }
  }
  relaxation_ = relaxation;
  const Eigen::Vector3d updated_n = previous_n + relaxation_ * raw_update_n;
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
  const bool small_update = update_n <= parameters_.eps_g_n;
  restartObservation(requiredSteadyCount(small_update));

  small_updates_ = small_update ? small_updates_ + 1 : 0;
  // Against a stop every step points the same way and keeps its length; an overshoot is
  // relaxed instead, unless the relaxation is already at its floor.
  const bool stalled = estimate_.iterations > 1 && update_n > stall_floor_n &&
                       update_n >= kStallRatio * last_update_n_ &&
                       (!overshoot || relaxation_ <= kMinRelaxation);
  stalled_updates_ = stalled ? stalled_updates_ + 1 : 0;
  if (held_still) {
    return endAgainstStop(settled_m, raw_update_n / update_n, last_previous_n_);
  }
  last_update_n_ = update_n;
  last_raw_update_n_ = raw_update_n;
  last_settled_m_ = settled_m;
  last_previous_n_ = previous_n;
  if (stalled_updates_ >= kStalledUpdates) {
    finish(VertexOutcome::kUnreachable);
    return Status::kUnreachable;
  }
  // The swing rules (the paper's method keeps eqs. 7-13 as published): a vertex that has
  // iterated 2 kSwingHalf times has circled its fixed point, and the mean over that circle is
  // nearer to it than any one estimate. The n_G rule meets such a swing where its steps are
  // smallest, at an end (high friction: sim:omni's vertex 60 ends 31 mN off in y with the last
  // estimate, 6 mN with the mean).
  // The circle starts at the estimate after the last approach step (kApproachSteps eps_G or
  // more): the approach to the fixed point is no part of it (sim:falcon desktop, vertex 80:
  // 0.50 N in x on the way in, 0.35 N around the fixed point; a mean with it is 12 mN off).
  swing_estimates_ = update_n >= kApproachSteps * parameters_.eps_g_n ? 1 : swing_estimates_ + 1;
  recent_n_[static_cast<std::size_t>(swing_estimates_ % (2 * kSwingHalf))] = updated_n;
  const bool swung =
      parameters_.method == EstimationMethod::kDither && swing_estimates_ >= 2 * kSwingHalf;
  Eigen::Vector3d older_n = Eigen::Vector3d::Zero(), newer_n = Eigen::Vector3d::Zero();
  if (swung) {
    for (int k = 0; k < kSwingHalf; ++k) {
      newer_n += recent_n_[static_cast<std::size_t>((swing_estimates_ - k) % (2 * kSwingHalf))];
      older_n += recent_n_[static_cast<std::size_t>((swing_estimates_ - kSwingHalf - k) %
                                                    (2 * kSwingHalf))];
    }
  }
  const bool halves_agree = swung && (newer_n - older_n).norm() <= kSwingHalf * parameters_.eps_g_n;
  if (small_updates_ >= parameters_.n_g || halves_agree) {
    if (swung) gravity_n_ = (older_n + newer_n) / (2.0 * kSwingHalf);
    if (parameters_.method == EstimationMethod::kDither && push_direction_.squaredNorm() > 0.0 &&
        (gravity_n_ - initial_gravity_n_).dot(push_direction_.normalized()) >
            kPushTrigger * parameters_.eps_g_n) {
      beginPush(settled_m);  // the stop watch: shown free before its value is taken
      return Status::kUpdated;
    }
    finish(VertexOutcome::kConverged);
    return Status::kConverged;
  }
  if (estimate_.iterations >= parameters_.max_iterations) {
    finish(VertexOutcome::kIterationCap);
    return Status::kIterationCap;
  }
  return Status::kUpdated;
}

void VertexEstimator::beginPush(const Eigen::Vector3d& settled_m) noexcept {
  ++push_tests_;
  push_phase_ = PushPhase::kOutward;
  push_base_m_ = settled_m;
  creep_probe_offset_m_ = kPushProbe_m * push_direction_.normalized();
  // One window pair (kPushSteadyWindows), agreeing within kPushWindowTolerance of the probe:
  // each push costs device time at a watched point, and the test reads tenths of a millimetre.
  detector_.setWindowTolerance_m(kPushWindowTolerance * kPushProbe_m);
  restartObservation(kPushSteadyWindows);
}

VertexEstimator::Status VertexEstimator::pushSettled(const Eigen::Vector3d& settled_m) noexcept {
  const Eigen::Vector3d push_m = creep_probe_offset_m_;
  const Eigen::Vector3d direction = push_direction_.normalized();
  const Eigen::Vector3d moved_m = settled_m - push_base_m_;
  bool stop = false;
  if (push_phase_ == PushPhase::kOutward) {
    push_outward_moved_m_ = moved_m;
    const double follow = moved_m.dot(direction) / kPushProbe_m;
    if (follow < kPushBlockedFollow) {
      stop = true;
    } else if (follow < kPushFreeFollow) {
      // Ambiguous: friction that held part of the push, or a stop that did. The reference.
      push_phase_ = PushPhase::kInward;
      creep_probe_offset_m_ = -push_m;
      restartObservation(kPushSteadyWindows);
      return Status::kSettling;
    }
  } else {
    push_inward_moved_m_ = moved_m;
    // Free space mirrors the two pushes; a stop took part of the outward one. A push that
    // followed partly and went sideways met a stop across part of it (an edge), whatever the
    // inward push did: a stop deep enough blocks that one too.
    const Eigen::Vector3d& outward_m = push_outward_moved_m_;
    const double sideways_m = (outward_m - outward_m.dot(direction) * direction).norm();
    const double scale_m = std::max(moved_m.norm(), outward_m.norm());
    stop = (outward_m + moved_m).norm() > kPushAsymmetry * scale_m ||
           sideways_m > kPushSideways * kPushProbe_m;
  }
  push_phase_ = PushPhase::kNone;
  creep_probe_offset_m_.setZero();
  if (!stop) {
    finish(VertexOutcome::kConverged);
    return Status::kConverged;
  }
  // The stop's reaction may have been in G_hat from the first iteration on: restart from the
  // estimate the vertex began with (the calibrator's, from converged neighbours).
  return endAgainstStop(push_base_m_, direction, initial_gravity_n_);
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
