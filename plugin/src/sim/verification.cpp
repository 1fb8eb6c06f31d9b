#include "autograv/sim/verification.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "autograv/device/forwarding_device.h"
#include "autograv/device/servo_clock.h"
#include "autograv/device/servo_sample.h"
#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

namespace {

// The simulated user carries the stylus between points at 10 cm/s and holds it still for a
// moment before letting go; compensation must be fully in within the timeout.
constexpr double kHandSpeed_m_per_s = 0.1;
constexpr double kHandHold_s = 0.3;
constexpr double kReadyTimeout_s = 5.0;
// A probe whose position moved more than this during its averaging window had not settled.
constexpr double kSettleTolerance_m = 1e-4;
// Force change the probe may make against friction without the decorator calling the position
// stale: the hold at its stiffest times its approach distance, with room. Unit: [N]
constexpr double kProbeFrozenForceFloor_n = 2.0;
// How far outside the map's grid the residual probe may take the end-effector. Unit: [m]
constexpr double kProbeOutsideGrid_m = 0.003;

/// Remembers the largest force that went to the device: the check "never above the device's
/// maximum" is made on what was sent, not on what the decorator meant to send.
class ForceMeter final : public ForwardingDevice {
 public:
  explicit ForceMeter(std::shared_ptr<HapticDevice> inner) : ForwardingDevice(std::move(inner)) {}
  bool setForce(const Eigen::Vector3d& force_n) override {
    max_force_n_ = std::max(max_force_n_, force_n.norm());
    return ForwardingDevice::setForce(force_n);
  }
  /// Unit: [N]
  double maxForce_n() const { return max_force_n_; }

 private:
  double max_force_n_ = 0.0;
};

/// The PD hold's effort toward `target_m`, from one servo sample. Units: [N/m], [N s/m]
Eigen::Vector3d holdEffort_n(const ServoSample& sample, const Eigen::Vector3d& target_m,
                             double stiffness_n_per_m, double damping_n_s_per_m) noexcept {
  return stiffness_n_per_m * (target_m - sample.position_m) -
         damping_n_s_per_m * sample.velocity_m_per_s;
}

/// What one approach saw at rest.
struct ProbeOutcome {
  Eigen::Vector3d mean_effort_n = Eigen::Vector3d::Zero();
  bool read_ok = true;
  bool settled = true;
};

/// Holds toward `target_m` for `duration_s`; averages the effort over the last `average_s`.
ProbeOutcome holdToward(HapticDevice& device, TickSource& ticks, const Eigen::Vector3d& target_m,
                        double stiffness_n_per_m, double damping_n_s_per_m, double duration_s,
                        double average_s) noexcept {
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
      effort_n = holdEffort_n(sample, target_m, stiffness_n_per_m, damping_n_s_per_m);
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
      const Eigen::Vector3d far_side_m = (target_m - sign * options.approach_distance_m * direction)
                                             .cwiseMax(options.keep_within_min_m)
                                             .cwiseMin(options.keep_within_max_m);
      const double distance_m = (far_side_m - target_m).norm();
      holdToward(device, ticks, far_side_m, stiffness_n_per_m, damping_n_s_per_m, options.retreat_s,
                 options.average_s);
      const Eigen::Vector3d before_m = measuredPosition_m(device);
      const ProbeOutcome outcome =
          holdToward(device, ticks, target_m, stiffness_n_per_m, damping_n_s_per_m,
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

ResidualMeasurement measureResidualForce(HapticDevice& device, TickSource& ticks,
                                         const Eigen::Vector3d& point_m, double apparent_mass_kg,
                                         const ResidualProbeOptions& options) noexcept {
  ResidualMeasurement result;
  const double start_s = ticks.now_s();
  const double mass_kg = std::max(apparent_mass_kg, 1e-3);
  double stiffness_n_per_m = options.stiffness_n_per_m;
  result.valid = true;
  double friction_sum_n = 0.0;
  const auto damping_n_s_per_m = [&] {
    return 2.0 * options.damping_ratio * std::sqrt(stiffness_n_per_m * mass_kg);
  };
  for (int axis = 0; axis < 3 && result.valid; ++axis) {
    for (int attempt = 0;; ++attempt) {
      const AxisProbe probe =
          probeAxis(device, ticks, point_m, axis, stiffness_n_per_m, damping_n_s_per_m(), options);
      if (probe.read_ok && !probe.slid && attempt < options.max_stiffness_doublings) {
        stiffness_n_per_m *= 2.0;  // friction held it: pull harder, for every axis from now on
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
  holdToward(device, ticks, point_m, stiffness_n_per_m, damping_n_s_per_m(), options.approach_s,
             options.average_s);
  result.holding_friction_n = friction_sum_n / 3.0;
  result.stiffness_n_per_m = stiffness_n_per_m;
  result.seconds = ticks.now_s() - start_s;
  return result;
}

ReleaseMeasurement measureRelease(HapticDevice& device, TickSource& ticks, double duration_s,
                                  double stuck_threshold_m) noexcept {
  ReleaseMeasurement result;
  result.valid = true;
  const long total_ticks = std::max(1L, std::lround(duration_s / ticks.period_s()));
  Eigen::Vector3d released_at_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  double elapsed = 0.0;  // servo time in nominal periods
  for (long k = 0; elapsed < static_cast<double>(total_ticks) - kServoTimeSlackPeriods; ++k) {
    const bool read = device.getPosition(position_m) && position_m.allFinite();
    device.setForce(Eigen::Vector3d::Zero());
    if (!read) {
      result.valid = false;
    } else if (k == 0) {
      released_at_m = position_m;
    } else {
      result.drift_m = (position_m - released_at_m).norm();
      result.max_excursion_m = std::max(result.max_excursion_m, result.drift_m);
    }
    if (!ticks.waitForNextTick()) break;
    elapsed += ticks.lastInterval_s() / ticks.period_s();
  }
  result.stuck = result.valid && result.max_excursion_m <= stuck_threshold_m;
  return result;
}

Percentiles percentiles(std::vector<double> values) {
  Percentiles result;
  if (values.empty()) return result;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  result.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  result.p90 = values[std::min(n - 1, static_cast<std::size_t>(std::ceil(0.9 * n)) - 1)];
  result.max = values.back();
  return result;
}

namespace {

/// The simulated user takes the end-effector wherever it is, carries it to `point_m`, and holds
/// it there while `device` is commanded zero application force; returns once it has been held
/// still for kHandHold_s and `ready()` says so, or false after kReadyTimeout_s more.
template <typename Ready>
bool carryAndHold(SimulatedDevice& simulated, HapticDevice& device, TickSource& ticks,
                  const Eigen::Vector3d& point_m, Ready&& ready) {
  SimulatedHand& hand = simulated.hand();
  hand.grab(simulated.truePosition_m());  // the user's hand, not a measurement
  hand.moveTo(point_m, kHandSpeed_m_per_s);
  const auto tick = [&] {
    Eigen::Vector3d position_m;
    device.getPosition(position_m);
    device.setForce(Eigen::Vector3d::Zero());
    ticks.waitForNextTick();
  };
  while (!hand.atGoal()) tick();
  for (double t = 0.0; t < kHandHold_s; t += ticks.lastInterval_s()) tick();
  for (double t = 0.0; !ready(); t += ticks.lastInterval_s()) {
    if (t > kReadyTimeout_s) return false;
    tick();
  }
  return true;
}

}  // namespace

VerificationReport verifyMapOnSimulatedDevice(const std::shared_ptr<SimulatedDevice>& simulated,
                                              std::shared_ptr<const GravityMap> map,
                                              const VerificationOptions& options,
                                              bool allow_model_mismatch) {
  if (!simulated || !map) throw Error("verify: no device or no map");
  SimulatedDevice& device = *simulated;
  if (options.points < 1) throw Error("verify: the number of points must be at least 1");
  const WorkspaceGrid& grid = map->grid();
  VerificationReport report;
  report.servo_period_s = map->metadata().parameters.servo_period_s;
  const double start_s = device.time_s();

  auto meter = std::make_shared<ForceMeter>(simulated);
  CompensationOptions compensation = options.compensation;
  SimulatedTickSource ticks(device, report.servo_period_s,
                            SimulatedTickSource::Mode::kAsFastAsPossible, options.servo_timing,
                            options.servo_timing_seed);
  // The decorator reads the loop's own clock; an exact loop is exactly its fixed period.
  if (options.servo_timing == ServoTiming::kExact) {
    compensation.clock = std::make_shared<FixedPeriodServoClock>(report.servo_period_s);
  } else {
    compensation.clock = std::make_shared<ServoTimingClock>(ticks.timingModel());
  }
  // The probe pushes both ways on purpose while friction may hold the end-effector still: the
  // frozen-driver check must not take that for a frozen driver (its own tests cover it).
  compensation.frozen_force_floor_n =
      std::max(compensation.frozen_force_floor_n, kProbeFrozenForceFloor_n);
  GravityCompensatedDevice decorated(meter, compensation);
  decorated.publishMap(map, allow_model_mismatch);

  // Seeded points inside the grid that the device can reach: a fitted box pokes out of the
  // workspace (sim::Random: the same points on every platform).
  Random random(options.seed);
  report.points.resize(static_cast<std::size_t>(options.points));
  constexpr int kMaxDrawsPerPoint = 1000;
  for (PointVerification& point : report.points) {
    int draws = 0;
    do {
      if (++draws > kMaxDrawsPerPoint) {
        throw Error("verify: the map's grid hardly overlaps the reachable workspace of " +
                    device.specifications().model_name);
      }
      for (int axis = 0; axis < 3; ++axis) {
        point.point_m[axis] = grid.minCorner_m()[axis] + random.uniform() * grid.size_m()[axis];
      }
    } while (!device.isReachable(point.point_m));
  }

  const int total = options.points * (options.compare_uncompensated ? 2 : 1);
  int done = 0;
  const auto fully_compensated = [&] {
    return decorated.latestMapInUse() && decorated.compensationLevel() == 1.0 &&
           decorated.activeFault() == ServoFault::kNone;
  };
  for (PointVerification& point : report.points) {
    point.map_gravity_n = map->gravityAt(point.point_m);
    point.true_gravity_n = device.trueGravity(point.point_m);
    point.truth_error_n = (point.map_gravity_n - point.true_gravity_n).norm();
    point.truth_error_rel = point.truth_error_n / point.true_gravity_n.norm();

    // Every point starts afresh: held by hand at the point until compensation is fully in,
    // whatever the previous release did.
    point.ready = carryAndHold(device, decorated, ticks, point.point_m, fully_compensated);
    // Outside the grid the map is extrapolated, then held, so G - G_hat grows with the distance,
    // a negative spring against the soft hold: the probe keeps close to the grid.
    ResidualProbeOptions probe = options.probe;
    probe.keep_within_min_m = grid.minCorner_m().array() - kProbeOutsideGrid_m;
    probe.keep_within_max_m =
        grid.minCorner_m() + grid.size_m() + Eigen::Vector3d::Constant(kProbeOutsideGrid_m);
    device.hand().release();
    if (point.ready) {
      point.residual = measureResidualForce(decorated, ticks, point.point_m,
                                            point.map_gravity_n.norm() / kStandardGravity, probe);
      point.ready = fully_compensated();
    }
    if (point.ready) {
      point.release =
          measureRelease(decorated, ticks, options.release_s, options.stuck_threshold_m);
    }
    if (options.on_progress) options.on_progress(++done, total, true);
  }
  report.max_force_sent_n = meter->maxForce_n();
  report.clamp_count = decorated.clampCount();
  for (int kind = 1; kind < kServoFaultKinds; ++kind) {
    report.fault_counts[static_cast<std::size_t>(kind)] =
        decorated.faultCount(static_cast<ServoFault>(kind));
  }

  if (options.compare_uncompensated) {
    for (PointVerification& point : report.points) {
      carryAndHold(device, device, ticks, point.point_m, [] { return true; });
      device.hand().release();
      point.release_uncompensated =
          measureRelease(device, ticks, options.release_s, options.stuck_threshold_m);
      if (options.on_progress) options.on_progress(++done, total, false);
    }
  }

  std::vector<double> residuals, drifts, drifts_off, errors, errors_rel, norms;
  int stuck = 0;
  for (const PointVerification& point : report.points) {
    errors.push_back(point.truth_error_n);
    errors_rel.push_back(point.truth_error_rel);
    norms.push_back(point.map_gravity_n.norm());
    if (options.compare_uncompensated) drifts_off.push_back(point.release_uncompensated.drift_m);
    if (!point.ready) continue;
    ++report.ready_points;
    drifts.push_back(point.release.drift_m);
    stuck += point.release.stuck;
    if (point.residual.valid) residuals.push_back(point.residual.residual_force_n.norm());
  }
  report.valid_residuals = static_cast<int>(residuals.size());
  report.residual_force_n = percentiles(residuals);
  report.drift_m = percentiles(drifts);
  report.drift_uncompensated_m = percentiles(drifts_off);
  report.truth_error_n = percentiles(errors);
  report.truth_error_rel = percentiles(errors_rel);
  report.median_gravity_n = percentiles(norms).median;
  report.stuck_fraction =
      report.ready_points > 0 ? static_cast<double>(stuck) / report.ready_points : 0.0;
  report.simulated_seconds = device.time_s() - start_s;
  report.servo_loop = ticks.loopSummary();
  return report;
}

}  // namespace autograv::sim
