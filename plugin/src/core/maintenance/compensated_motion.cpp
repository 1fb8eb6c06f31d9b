#include "autograv/maintenance/compensated_motion.h"

#include <algorithm>
#include <cmath>

#include "autograv/device/servo_sample.h"
#include "core/estimation/minimum_jerk_move.h"
#include "core/maintenance/hold_toward.h"

namespace autograv {

namespace {

// A probe whose position moved more than this during its averaging window had not settled.
constexpr double kSettleTolerance_m = 1e-4;
// A carry is stalled when the end-effector closes on its target at under this fraction of the
// path's speed plus this speed (a stop holds it: it does not move at all). Units: [1], [m/s]
constexpr double kStalledSpeedFraction = 0.3;
constexpr double kStalledSpeed_m_per_s = 0.005;
// How far a blocked carry backs off from where the stop held it (a stop gives a millimetre or
// so under the push). Unit: [m]
constexpr double kBlockedBackOff_m = 0.002;

/// The PD hold's effort toward `target_m`, from one servo sample, within `limit`.
/// Units: [N/m], [N s/m]
Eigen::Vector3d holdEffort_n(const ServoSample& sample, const Eigen::Vector3d& target_m,
                             double stiffness_n_per_m, double damping_n_s_per_m,
                             const EffortLimit& limit) noexcept {
  Eigen::Vector3d effort_n = stiffness_n_per_m * (target_m - sample.position_m) -
                             damping_n_s_per_m * sample.velocity_m_per_s;
  limit.apply(effort_n);
  return effort_n;
}

}  // namespace

namespace detail {

/// Holds toward `target_m` for `duration_s`; averages the effort over the last `average_s`.
ProbeOutcome holdToward(HapticDevice& device, TickSource& ticks, const Eigen::Vector3d& target_m,
                        double stiffness_n_per_m, double damping_n_s_per_m,
                        const EffortLimit& limit, double duration_s, double average_s) noexcept {
  ProbeOutcome outcome;
  // Durations in servo time, counted in nominal periods (whole numbers on an exact loop); each
  // effort is weighted by the time it was held, up to the next tick.
  const double period_s = ticks.period_s();
  const long total_ticks = std::max(1L, std::lround(duration_s / period_s));
  const long average_ticks = std::clamp(std::lround(average_s / period_s), 1L, total_ticks);
  const double window_from =
      static_cast<double>(total_ticks - average_ticks) - kServoTimeSlackPeriods;
  Eigen::Vector3d window_start_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d effort_sum_n = Eigen::Vector3d::Zero();
  double weight_sum = 0.0;
  bool window_started = false;
  for (double elapsed = 0.0; elapsed < static_cast<double>(total_ticks) - kServoTimeSlackPeriods;) {
    const ServoSample sample = readServoSample(device, ticks.lastInterval_s());
    Eigen::Vector3d effort_n = Eigen::Vector3d::Zero();
    if (sample.valid) {
      effort_n = holdEffort_n(sample, target_m, stiffness_n_per_m, damping_n_s_per_m, limit);
    } else {
      outcome.read_ok = false;
    }
    device.setForce(effort_n);
    const bool in_window = elapsed >= window_from;
    if (in_window && !window_started) {
      window_start_m = sample.position_m;
      window_started = true;
    }
    if (in_window && (sample.position_m - window_start_m).norm() > kSettleTolerance_m) {
      outcome.settled = false;
    }
    if (!ticks.waitForNextTick()) {
      outcome.read_ok = false;
      break;
    }
    const double periods = ticks.lastInterval_s() / period_s;
    elapsed += periods;
    if (in_window) {
      effort_sum_n += periods * effort_n;
      weight_sum += periods;
    }
  }
  outcome.mean_effort_n =
      weight_sum > 0.0 ? Eigen::Vector3d(effort_sum_n / weight_sum) : Eigen::Vector3d::Zero();
  return outcome;
}

}  // namespace detail

namespace {

using detail::holdToward;
using detail::ProbeOutcome;

/// Measured position now, or NaN when the read fails.
Eigen::Vector3d measuredPosition_m(HapticDevice& device) noexcept {
  Eigen::Vector3d position_m;
  if (!device.getPosition(position_m)) position_m.setConstant(std::nan(""));
  return position_m;
}

/// The far side of an approach: `distance_m` from `target_m` along `direction`, shortened so that
/// it stays in the options' box and inside their workspace (real-time safe: a few halvings).
Eigen::Vector3d farSide(const Eigen::Vector3d& target_m, const Eigen::Vector3d& direction,
                        double distance_m, const ResidualProbeOptions& options) noexcept {
  Eigen::Vector3d far_m = (target_m + distance_m * direction)
                              .cwiseMax(options.keep_within_min_m)
                              .cwiseMin(options.keep_within_max_m);
  if (options.keep_inside.empty()) return far_m;
  double length_m = (far_m - target_m).norm();
  constexpr int kHalvings = 12;
  for (int i = 0;
       i < kHalvings && !options.keep_inside.contains(far_m, options.keep_inside_margin_m); ++i) {
    length_m *= 0.75;
    far_m = target_m + length_m * direction;
  }
  return far_m;
}

/// Both approaches along one axis, `repeats` times each, toward targets spread evenly along the
/// axis around the point: the mean then spans target_spread_m of cogging and encoder counts.
struct AxisProbe {
  double effort_plus_n = 0.0;   ///< Mean effort along the axis, approached moving along +axis.
  double effort_minus_n = 0.0;  ///< Same, approached moving along -axis.
  bool slid = true;
  bool read_ok = true;
  int unsettled = 0;
};

AxisProbe probeAxis(HapticDevice& device, TickSource& ticks, const Eigen::Vector3d& point_m,
                    int axis, double stiffness_n_per_m, double damping_n_s_per_m,
                    const ResidualProbeOptions& options) noexcept {
  AxisProbe probe;
  const Eigen::Vector3d direction = Eigen::Vector3d::Unit(axis);
  const int repeats = std::max(1, options.approaches_per_side);
  for (int repeat = 0; repeat < repeats; ++repeat) {
    const double offset_m = options.target_spread_m * ((repeat + 0.5) / repeats - 0.5);
    const Eigen::Vector3d target_m = point_m + offset_m * direction;
    for (const double sign : {1.0, -1.0}) {
      const Eigen::Vector3d far_side_m =
          farSide(target_m, -sign * direction, options.approach_distance_m, options);
      const double distance_m = (far_side_m - target_m).norm();
      holdToward(device, ticks, far_side_m, stiffness_n_per_m, damping_n_s_per_m, options.limit,
                 options.retreat_s, options.average_s);
      const Eigen::Vector3d before_m = measuredPosition_m(device);
      const ProbeOutcome outcome =
          holdToward(device, ticks, target_m, stiffness_n_per_m, damping_n_s_per_m, options.limit,
                     options.approach_s, options.average_s);
      const Eigen::Vector3d after_m = measuredPosition_m(device);
      probe.read_ok =
          probe.read_ok && outcome.read_ok && after_m.allFinite() && before_m.allFinite();
      probe.slid = probe.slid &&
                   sign * (after_m - before_m)[axis] >= options.min_slide_fraction * distance_m;
      probe.unsettled += !outcome.settled;
      (sign > 0.0 ? probe.effort_plus_n : probe.effort_minus_n) +=
          outcome.mean_effort_n[axis] / repeats;
    }
  }
  return probe;
}

}  // namespace

void EffortLimit::apply(Eigen::Vector3d& effort_n) const noexcept {
  if (max_effort_n > 0.0) clampForce(effort_n, max_effort_n);
  if (max_total_n > 0.0) {
    Eigen::Vector3d total_n = compensation_n + effort_n;
    if (clampForce(total_n, max_total_n)) effort_n = total_n - compensation_n;
  }
}

ResidualMeasurement measureResidualForce(HapticDevice& device, TickSource& ticks,
                                         const Eigen::Vector3d& point_m, double apparent_mass_kg,
                                         const ResidualProbeOptions& options) noexcept {
  ResidualMeasurement result;
  const double start_s = ticks.now_s();
  const double mass_kg = std::max(apparent_mass_kg, 1e-3);
  double stiffness_n_per_m = options.stiffness_n_per_m;
  const double max_stiffness_n_per_m =
      options.stiffness_n_per_m * std::ldexp(1.0, std::max(0, options.max_stiffness_doublings));
  result.valid = true;
  double friction_sum_n = 0.0;
  const auto damping_n_s_per_m = [&] {
    return 2.0 * options.damping_ratio * std::sqrt(stiffness_n_per_m * mass_kg);
  };
  for (int axis = 0; axis < 3 && result.valid; ++axis) {
    for (int attempt = 0;; ++attempt) {
      const AxisProbe probe =
          probeAxis(device, ticks, point_m, axis, stiffness_n_per_m, damping_n_s_per_m(), options);
      // Friction held it: pull harder, for every axis from now on, up to max_stiffness_doublings
      // doublings in all (each count of the encoder reads as K counts of force: a stiffer hold
      // reads coarser).
      if (probe.read_ok && !probe.slid && attempt < options.max_stiffness_doublings &&
          stiffness_n_per_m < max_stiffness_n_per_m) {
        stiffness_n_per_m *= 2.0;
        continue;
      }
      result.valid = probe.read_ok && probe.slid;
      // Only the component along the approach: a joint the approach hardly moves keeps whatever
      // friction it had, but by virtual work its friction has no component along the approach.
      result.residual_force_n[axis] = 0.5 * (probe.effort_plus_n + probe.effort_minus_n);
      friction_sum_n += 0.5 * (probe.effort_plus_n - probe.effort_minus_n);
      result.unsettled_probes += probe.unsettled;
      break;
    }
  }
  // End held at the point itself, as documented (the last target was beside it).
  holdToward(device, ticks, point_m, stiffness_n_per_m, damping_n_s_per_m(), options.limit,
             options.approach_s, options.average_s);
  result.holding_friction_n = friction_sum_n / 3.0;
  result.stiffness_n_per_m = stiffness_n_per_m;
  result.seconds = ticks.now_s() - start_s;
  return result;
}

CarryOutcome carryTo(HapticDevice& device, TickSource& ticks, const Eigen::Vector3d& to_m,
                     double apparent_mass_kg, const CarryOptions& options) noexcept {
  CarryOutcome outcome;
  const double start_s = ticks.now_s();
  const double mass_kg = std::max(apparent_mass_kg, 1e-3);
  const double stiffness = options.stiffness_n_per_m;
  const double damping = 2.0 * options.damping_ratio * std::sqrt(stiffness * mass_kg);
  const ServoSample first = readServoSample(device, ticks.lastInterval_s());
  if (!first.valid) {
    device.setForce(Eigen::Vector3d::Zero());
    ticks.waitForNextTick();
    outcome.read_ok = false;
    outcome.seconds = ticks.now_s() - start_s;
    return outcome;
  }
  MinimumJerkMove move;
  move.start(
      first.position_m, to_m,
      MinimumJerkMove::durationFor((to_m - first.position_m).norm(),
                                   options.max_acceleration_m_per_s2, options.min_duration_s));
  // The path stays inside the workspace where it starts inside: pulling a target inside is
  // continuous along the path, and leaves it as it is where it already lies inside.
  const bool keep_inside = !options.keep_inside.empty() &&
                           options.keep_inside.contains(first.position_m, 0.0) &&
                           options.keep_inside.contains(to_m, options.keep_inside_margin_m);
  Eigen::Vector3d held_at_m = to_m;
  double lagging_s = 0.0;
  double t_s = 0.0;
  bool moving = true;
  bool blocked = false;
  ServoSample sample = first;
  for (double settle_s = 0.0; settle_s < options.settle_s;) {
    Eigen::Vector3d effort_n = Eigen::Vector3d::Zero();
    if (sample.valid) {
      Eigen::Vector3d target_m = held_at_m;
      Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
      Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();
      if (moving) {
        move.sample(t_s, target_m, velocity, acceleration);
        if (keep_inside) target_m = options.keep_inside.pullInside(target_m, 0.0);
      }
      effort_n = stiffness * (target_m - sample.position_m) +
                 damping * (velocity - sample.velocity_m_per_s) + mass_kg * acceleration;
      options.limit.apply(effort_n);
      if (moving) {
        // Blocked: far behind the path and not catching up (moving toward the target at under
        // kStalledSpeedFraction of the path's speed). A lag while it still follows is no stop.
        const Eigen::Vector3d lag_m = target_m - sample.position_m;
        const double lag_norm_m = lag_m.norm();
        const double closing_m_per_s =
            lag_norm_m > 0.0 ? sample.velocity_m_per_s.dot(lag_m) / lag_norm_m : 0.0;
        const bool stalled =
            closing_m_per_s < kStalledSpeedFraction * velocity.norm() + kStalledSpeed_m_per_s;
        lagging_s = lag_norm_m > options.blocked_lag_m && stalled
                        ? lagging_s + servoPeriodsOf(sample, ticks.period_s()) * ticks.period_s()
                        : 0.0;
        if (lagging_s >= options.blocked_s) {
          // A stop holds it: back off from it and stay there, never push on.
          blocked = true;
          moving = false;
          held_at_m = sample.position_m - kBlockedBackOff_m * lag_m / lag_norm_m;
          effort_n = -damping * sample.velocity_m_per_s;
          options.limit.apply(effort_n);
        }
      }
    } else {
      outcome.read_ok = false;
    }
    device.setForce(effort_n);
    if (!ticks.waitForNextTick()) {
      outcome.read_ok = false;
      break;
    }
    const double dt_s = ticks.lastInterval_s();
    if (moving) {
      t_s += dt_s;
      if (t_s >= move.duration_s()) moving = false;
    } else {
      settle_s += dt_s;
    }
    sample = readServoSample(device, dt_s);
  }
  outcome.reached = !blocked && outcome.read_ok;
  outcome.seconds = ticks.now_s() - start_s;
  return outcome;
}

ReleaseMeasurement measureRelease(HapticDevice& device, TickSource& ticks,
                                  const ReleaseOptions& options,
                                  HapticDevice* catch_device) noexcept {
  HapticDevice& catcher = catch_device ? *catch_device : device;
  ReleaseMeasurement result;
  result.valid = true;
  const long total_ticks = std::max(1L, std::lround(options.duration_s / ticks.period_s()));
  Eigen::Vector3d released_at_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double elapsed = 0.0;  // servo time in nominal periods
  for (long k = 0; elapsed < static_cast<double>(total_ticks) - kServoTimeSlackPeriods; ++k) {
    const bool read = device.getPosition(position_m) && position_m.allFinite();
    if (!read) {
      result.valid = false;
    } else if (k == 0) {
      released_at_m = position_m;
    } else {
      result.drift_m = (position_m - released_at_m).norm();
      result.max_excursion_m = std::max(result.max_excursion_m, result.drift_m);
      const bool drifted = options.catch_drift_m > 0.0 &&
                           (result.drift_m > options.catch_drift_m ||
                            (!options.catch_inside.empty() &&
                             !options.catch_inside.contains(position_m, options.catch_margin_m)));
      if (drifted) {
        result.caught = true;
        result.caught_after_s = elapsed * ticks.period_s();
        break;
      }
    }
    device.setForce(Eigen::Vector3d::Zero());
    if (!ticks.waitForNextTick()) break;
    elapsed += ticks.lastInterval_s() / ticks.period_s();
  }
  if (result.caught) {
    // Stop it where it is: the damping takes the speed out, the spring holds it there.
    const Eigen::Vector3d hold_m = position_m;
    for (double t_s = 0.0; t_s < options.catch_hold_s;) {
      const ServoSample sample = readServoSample(catcher, ticks.lastInterval_s());
      Eigen::Vector3d effort_n = Eigen::Vector3d::Zero();
      if (sample.valid) {
        effort_n = holdEffort_n(sample, hold_m, options.catch_stiffness_n_per_m,
                                options.catch_damping_n_s_per_m, options.catch_limit);
      } else {
        result.valid = false;
      }
      catcher.setForce(effort_n);
      if (!ticks.waitForNextTick()) break;
      t_s += ticks.lastInterval_s();
    }
  }
  result.stuck = result.valid && result.max_excursion_m <= options.stuck_threshold_m;
  return result;
}

ReleaseMeasurement measureRelease(HapticDevice& device, TickSource& ticks, double duration_s,
                                  double stuck_threshold_m) noexcept {
  ReleaseOptions options;
  options.duration_s = duration_s;
  options.stuck_threshold_m = stuck_threshold_m;
  return measureRelease(device, ticks, options);
}

}  // namespace autograv
