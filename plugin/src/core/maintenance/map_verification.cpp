#include "autograv/maintenance/map_verification.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include "autograv/device/device_specifications.h"
#include "autograv/device/forwarding_device.h"
#include "autograv/device/servo_sample.h"
#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/minimum_jerk_move.h"
#include "autograv/map/map_summary.h"

namespace autograv {

namespace {

// A probe whose position moved more than this during its averaging window had not settled.
constexpr double kSettleTolerance_m = 1e-4;
// Force change the probe may make against friction without the decorator calling the position
// stale: the hold at its stiffest times its approach distance, with room. Unit: [N]
constexpr double kProbeFrozenForceFloor_n = 2.0;
// How far outside the map's grid the residual probe may take the end-effector, for a map that
// knows no workspace (the map is extrapolated outside its grid). Unit: [m]
constexpr double kProbeOutsideGrid_m = 0.003;
// Time the end-effector gets, held at a point, for compensation to be fully in. Unit: [s]
constexpr double kReadyTimeout_s = 5.0;
// A carry is stalled when the end-effector closes on its target at under this fraction of the
// path's speed plus this speed (a stop holds it: it does not move at all). Units: [1], [m/s]
constexpr double kStalledSpeedFraction = 0.3;
constexpr double kStalledSpeed_m_per_s = 0.005;
// How far a blocked carry backs off from where the stop held it (a stop gives a millimetre or
// so under the push). Unit: [m]
constexpr double kBlockedBackOff_m = 0.002;
// A tick whose force is within this fraction of the device's maximum sent the force limit.
constexpr double kForceLimitFraction = 0.999;

/// Measures what went to the device: the largest force, the time spent above the continuous
/// rating (and its longest stretch) and the ticks at the force limit. The check "never above the
/// device's maximum" is made on what was sent, not on what the decorator meant to send.
class ForceMeter final : public ForwardingDevice {
 public:
  ForceMeter(std::shared_ptr<HapticDevice> inner, TickSource& ticks, double continuous_n,
             double limit_n)
      : ForwardingDevice(std::move(inner)),
        ticks_(ticks),
        continuous_n_(continuous_n),
        limit_n_(limit_n) {}
  bool setForce(const Eigen::Vector3d& force_n) override {
    const double norm = force_n.norm();
    max_force_n_ = std::max(max_force_n_, norm);
    // The force is held until the next tick: one nominal period (the interval is only known
    // once the tick has come; the loop's mean is the nominal period).
    const double held_s = ticks_.period_s();
    if (norm > continuous_n_) {
      above_s_ += held_s;
      stretch_s_ += held_s;
      longest_s_ = std::max(longest_s_, stretch_s_);
    } else {
      stretch_s_ = 0.0;
    }
    if (norm >= kForceLimitFraction * limit_n_) ++limit_ticks_;
    return ForwardingDevice::setForce(force_n);
  }
  double maxForce_n() const { return max_force_n_; }
  double secondsAbove() const { return above_s_; }
  double longestAbove_s() const { return longest_s_; }
  std::uint64_t limitTicks() const { return limit_ticks_; }

 private:
  TickSource& ticks_;
  double continuous_n_;
  double limit_n_;
  double max_force_n_ = 0.0;
  double above_s_ = 0.0;
  double stretch_s_ = 0.0;
  double longest_s_ = 0.0;
  std::uint64_t limit_ticks_ = 0;
};

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

/// What one approach saw at rest.
struct ProbeOutcome {
  Eigen::Vector3d mean_effort_n = Eigen::Vector3d::Zero();
  bool read_ok = true;
  bool settled = true;
};

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

Percentiles percentiles(std::vector<double> values) {
  Percentiles result;
  if (values.empty()) return result;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  result.median = median(values);
  result.p90 = values[std::min(n - 1, static_cast<std::size_t>(std::ceil(0.9 * n)) - 1)];
  result.max = values.back();
  return result;
}

std::vector<Eigen::Vector3d> drawVerificationPoints(const WorkspaceGrid& grid,
                                                    const ExploredWorkspace& workspace, int count,
                                                    std::uint64_t seed, double margin_m) {
  if (count < 1) throw Error("verify: the number of points must be at least 1");
  if (!(margin_m >= 0.0)) throw Error("verify: the points' margin must be zero or more");
  // A box that holds every point that may be drawn, and the test a point must pass.
  Eigen::Vector3d min_m, max_m;
  if (workspace.empty()) {
    min_m = grid.minCorner_m().array() + margin_m;
    max_m = grid.minCorner_m() + grid.size_m() - Eigen::Vector3d::Constant(margin_m);
    if ((max_m - min_m).minCoeff() <= 0.0) {
      throw Error("verify: the map's grid is thinner than twice the points' margin");
    }
  } else {
    min_m = workspace.center_m().array() - workspace.maxRadius_m();
    max_m = workspace.center_m().array() + workspace.maxRadius_m();
  }
  // std::mt19937_64 gives the same bits on every platform (its distributions would not): the
  // uniform draw is made from the top 53 bits by hand.
  std::mt19937_64 bits(seed);
  const auto uniform = [&bits] { return static_cast<double>(bits() >> 11) * 0x1.0p-53; };
  constexpr int kMaxDrawsPerPoint = 1000;
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(count));
  for (int draws = 0; static_cast<int>(points.size()) < count; ++draws) {
    if (draws > kMaxDrawsPerPoint * count) {
      throw Error(
          "verify: the map's explored workspace is thinner than twice the points' margin (" +
          std::to_string(margin_m * 1e3) + " mm); calibrate again with its exploration");
    }
    Eigen::Vector3d point_m;
    for (int axis = 0; axis < 3; ++axis) {
      point_m[axis] = min_m[axis] + uniform() * (max_m[axis] - min_m[axis]);
    }
    if (workspace.empty() || workspace.contains(point_m, margin_m)) points.push_back(point_m);
  }
  return points;
}

VerificationReport verifyMap(const std::shared_ptr<HapticDevice>& device, TickSource& ticks,
                             std::shared_ptr<const GravityMap> map,
                             const VerificationOptions& options, bool allow_model_mismatch,
                             const VerificationTruth* truth) {
  if (!device || !map) throw Error("verify: no device or no map");
  const DeviceSpecifications& specs = device->specifications();
  const WorkspaceGrid& grid = map->grid();
  const ExploredWorkspace& workspace = map->metadata().workspace;
  VerificationReport report;
  report.servo_period_s = map->metadata().parameters.servo_period_s;
  report.points_from_workspace = !workspace.empty();
  report.has_truth = truth != nullptr;
  report.continuous_force_rating_n = continuousForceRating_n(specs);
  const double start_s = ticks.now_s();

  const std::vector<Eigen::Vector3d> points =
      drawVerificationPoints(grid, workspace, options.points, options.seed, options.point_margin_m);

  auto meter = std::make_shared<ForceMeter>(device, ticks, report.continuous_force_rating_n,
                                            specs.max_linear_force_n);
  CompensationOptions compensation = options.compensation;
  // The probe pushes both ways on purpose while friction may hold the end-effector still: the
  // frozen-driver check must not take that for a frozen driver (its own tests cover it).
  compensation.frozen_force_floor_n =
      std::max(compensation.frozen_force_floor_n, kProbeFrozenForceFloor_n);
  GravityCompensatedDevice decorated(meter, compensation);
  decorated.publishMap(map, allow_model_mismatch);

  const ServoSample first = readServoSample(decorated);
  if (!first.valid) {
    throw Error("verify: the device '" + specs.model_name +
                "' gives no valid position (is it open and homed?)");
  }
  const auto fully_compensated = [&] {
    return decorated.latestMapInUse() && decorated.compensationLevel() == 1.0 &&
           decorated.activeFault() == ServoFault::kNone;
  };
  // What is sent on purpose stays within the budget, together with the map's gravity there.
  const double budget_n = options.force_budget_fraction * report.continuous_force_rating_n;
  const auto limit_at = [&](const Eigen::Vector3d& gravity_n) {
    EffortLimit limit = options.carry.limit;
    limit.compensation_n = gravity_n;
    limit.max_total_n = std::max(budget_n, gravity_n.norm() + options.min_effort_n);
    // Where the map is far off, its own compensation pushes the end-effector away: the hold may
    // answer with up to the whole budget (the total stays within it).
    if (!(limit.max_effort_n > 0.0)) limit.max_effort_n = limit.max_total_n;
    return limit;
  };
  // Holds the end-effector still at `at_m` until compensation is fully in, at most the timeout.
  const auto hold_until_ready = [&](const Eigen::Vector3d& at_m, double mass_kg,
                                    const EffortLimit& limit) {
    const double stiffness = options.carry.stiffness_n_per_m;
    const double damping = 2.0 * options.carry.damping_ratio * std::sqrt(stiffness * mass_kg);
    for (double t_s = 0.0; !fully_compensated();) {
      if (t_s > kReadyTimeout_s) return false;
      holdToward(decorated, ticks, at_m, stiffness, damping, limit, 0.05, 0.05);
      t_s += 0.05;
    }
    return true;
  };

  // Compensation ramps in while the end-effector is held where it is.
  {
    const Eigen::Vector3d gravity_n = map->gravityAt(first.position_m);
    hold_until_ready(first.position_m, gravity_n.norm() / kStandardGravity, limit_at(gravity_n));
  }

  CarryOptions carry = options.carry;
  carry.keep_inside = workspace;
  ResidualProbeOptions probe = options.probe;
  probe.keep_inside = workspace;
  if (workspace.empty()) {
    // Outside the grid the map is extrapolated, then held, so G - G_hat grows with the distance,
    // a negative spring against the soft hold: the probe keeps close to the grid.
    probe.keep_within_min_m = grid.minCorner_m().array() - kProbeOutsideGrid_m;
    probe.keep_within_max_m =
        grid.minCorner_m() + grid.size_m() + Eigen::Vector3d::Constant(kProbeOutsideGrid_m);
  }
  ReleaseOptions release = options.release;
  release.catch_inside = workspace;

  report.points.resize(points.size());
  const int total = static_cast<int>(points.size());
  int done = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    PointVerification& point = report.points[i];
    point.point_m = points[i];
    point.map_gravity_n = map->gravityAt(point.point_m);
    if (truth) {
      if (truth->is_reachable) point.truly_reachable = truth->is_reachable(point.point_m);
      if (truth->gravity_n) {
        point.true_gravity_n = truth->gravity_n(point.point_m);
        point.truth_error_n = (point.map_gravity_n - point.true_gravity_n).norm();
        point.truth_error_rel = point.truth_error_n / point.true_gravity_n.norm();
      }
    }
    const double mass_kg = point.map_gravity_n.norm() / kStandardGravity;
    const EffortLimit limit = limit_at(point.map_gravity_n);
    carry.limit = limit;
    probe.limit = limit;
    release.catch_limit = limit;

    point.reached = carryTo(decorated, ticks, point.point_m, mass_kg, carry).reached;
    point.ready = point.reached && hold_until_ready(point.point_m, mass_kg, limit);
    if (point.ready) {
      point.residual = measureResidualForce(decorated, ticks, point.point_m, mass_kg, probe);
      point.ready = fully_compensated();
    }
    if (point.ready) point.release = measureRelease(decorated, ticks, release);
    if (point.ready && options.compare_uncompensated) {
      // Back to the point, still, then let go with compensation off: the decorator is bypassed,
      // and catches the fall.
      carryTo(decorated, ticks, point.point_m, mass_kg, carry);
      point.release_uncompensated = measureRelease(*meter, ticks, release, &decorated);
    }
    if (options.on_progress) options.on_progress(++done, total);
  }
  // Let go where the last point left it, held still.
  decorated.setForce(Eigen::Vector3d::Zero());

  report.max_force_sent_n = meter->maxForce_n();
  report.seconds_above_continuous_force = meter->secondsAbove();
  report.longest_above_continuous_force_s = meter->longestAbove_s();
  report.force_limit_ticks = meter->limitTicks();
  report.clamp_count = decorated.clampCount();
  for (int kind = 1; kind < kServoFaultKinds; ++kind) {
    report.fault_counts[static_cast<std::size_t>(kind)] =
        decorated.faultCount(static_cast<ServoFault>(kind));
  }

  std::vector<double> residuals, residuals_rel, friction, drifts, drifts_off, errors, errors_rel,
      norms;
  int stuck = 0;
  for (const PointVerification& point : report.points) {
    norms.push_back(point.map_gravity_n.norm());
    if (truth) {
      errors.push_back(point.truth_error_n);
      errors_rel.push_back(point.truth_error_rel);
      report.unreachable_points += !point.truly_reachable;
    }
    report.reached_points += point.reached;
    if (!point.ready) continue;
    ++report.ready_points;
    drifts.push_back(point.release.drift_m);
    stuck += point.release.stuck;
    report.caught_releases += point.release.caught;
    if (options.compare_uncompensated) drifts_off.push_back(point.release_uncompensated.drift_m);
    if (point.residual.valid) {
      residuals.push_back(point.residual.residual_force_n.norm());
      residuals_rel.push_back(point.residual.residual_force_n.norm() /
                              std::max(point.map_gravity_n.norm(), 1e-9));
      friction.push_back(point.residual.holding_friction_n);
    }
  }
  report.valid_residuals = static_cast<int>(residuals.size());
  report.residual_force_n = percentiles(residuals);
  report.residual_force_rel = percentiles(residuals_rel);
  report.holding_friction_n = percentiles(friction);
  report.drift_m = percentiles(drifts);
  report.drift_uncompensated_m = percentiles(drifts_off);
  report.truth_error_n = percentiles(errors);
  report.truth_error_rel = percentiles(errors_rel);
  report.median_gravity_n = percentiles(norms).median;
  report.stuck_fraction =
      report.ready_points > 0 ? static_cast<double>(stuck) / report.ready_points : 0.0;
  report.seconds = ticks.now_s() - start_s;
  return report;
}

}  // namespace autograv
