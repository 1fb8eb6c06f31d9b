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
#include "autograv/map/map_summary.h"
#include "core/maintenance/hold_toward.h"

namespace autograv {

namespace {

// Force change the probe may make against friction without the decorator calling the position
// stale: the hold at its stiffest times its approach distance, with room. Unit: [N]
constexpr double kProbeFrozenForceFloor_n = 2.0;
// How far outside the map's grid the residual probe may take the end-effector, for a map that
// knows no workspace (the map is extrapolated outside its grid). Unit: [m]
constexpr double kProbeOutsideGrid_m = 0.003;
// Time the end-effector gets, held at a point, for compensation to be fully in. Unit: [s]
constexpr double kReadyTimeout_s = 5.0;

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
    if (norm >= kLimitFraction * limit_n_) ++limit_ticks_;
    return ForwardingDevice::setForce(force_n);
  }
  double maxForce_n() const { return max_force_n_; }
  double secondsAbove() const { return above_s_; }
  double longestAbove_s() const { return longest_s_; }
  std::uint64_t limitTicks() const { return limit_ticks_; }

 private:
  // A tick whose force is within this fraction of the device's maximum sent the force limit.
  static constexpr double kLimitFraction = 0.999;
  TickSource& ticks_;
  double continuous_n_;
  double limit_n_;
  double max_force_n_ = 0.0;
  double above_s_ = 0.0;
  double stretch_s_ = 0.0;
  double longest_s_ = 0.0;
  std::uint64_t limit_ticks_ = 0;
};

using detail::holdToward;

}  // namespace

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
