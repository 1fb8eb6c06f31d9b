#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/maintenance/compensated_motion.h"
#include "autograv/map/explored_workspace.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// Median, 90th percentile and maximum of a set of values (zeros when empty).
struct Percentiles {
  /// The median.
  double median = 0.0;
  /// The 90th percentile.
  double p90 = 0.0;
  /// The largest value.
  double max = 0.0;
};
/// Not real-time safe.
Percentiles percentiles(std::vector<double> values);

/// `count` seeded points drawn uniformly from `workspace` at least `margin_m` inside its
/// boundary, the parts outside `grid`'s box included; from `grid`'s box shrunk by `margin_m` when
/// the workspace is empty. Deterministic on every platform. Throws autograv::Error when the
/// workspace is thinner than twice the margin. Not real-time safe. Unit: [m]
std::vector<Eigen::Vector3d> drawVerificationPoints(const WorkspaceGrid& grid,
                                                    const ExploredWorkspace& workspace, int count,
                                                    std::uint64_t seed, double margin_m);

/// Settings of verifyMap.
struct VerificationOptions {
  int points = 100;        ///< Seeded points drawn uniformly from the map's workspace.
  std::uint64_t seed = 1;  ///< Seed of the points.
  /// The points lie this far inside the explored workspace, next to the stops but clear of them:
  /// a probe records the boundary pressed into a stop's rubber (about 2 mm on sim:falcon). The
  /// calibration measures closer (kBoundaryMargin_m), watching each hold for a stop; verify's
  /// residual probe has no such watch. Unit: [m]
  double point_margin_m = 0.004;
  /// How each release is watched and caught; catch_inside is the map's workspace.
  ReleaseOptions release;
  /// How the residual force is probed at each point.
  ResidualProbeOptions probe;
  /// How the device carries itself between points.
  CarryOptions carry;
  /// Ramp and margins of the compensation under test. Its clock must be the loop's own (null:
  /// wall time); the frozen-driver floor is raised to the probe's pushes.
  CompensationOptions compensation;
  /// Largest force sent on purpose, as a fraction of the device's continuous rating
  /// (continuousForceRating_n): the carry, the probe and the catch send at most this together
  /// with the map's value at the point (EffortLimit::max_total_n), and at most carry.limit's
  /// max_effort_n of their own (0: the budget); where |G_hat| leaves less than min_effort_n
  /// under the budget, |G_hat| + min_effort_n (friction must still be overcome).
  double force_budget_fraction = 0.8;
  /// Unit: [N]
  double min_effort_n = 0.15;
  /// Also release every point with compensation off (the baseline the drift is compared with).
  /// The end-effector falls, and is caught at release.catch_drift_m.
  bool compare_uncompensated = true;
  /// Called after each point with (points done, points in all).
  std::function<void(int done, int total)> on_progress;
};

/// Knowledge of the truth that only a simulation has: used for scoring, never to drive.
struct VerificationTruth {
  /// True where the device can really be.
  std::function<bool(const Eigen::Vector3d&)> is_reachable;
  /// The true gravity force at a point. Unit: [N]
  std::function<Eigen::Vector3d(const Eigen::Vector3d&)> gravity_n;
};

/// Everything verify measured at one point.
struct PointVerification {
  /// The point, drawn from the map's workspace. Unit: [m]
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  /// The device carried itself to the point (its path was not blocked).
  bool reached = false;
  /// False when the end-effector could not be held at the point with full compensation (not
  /// reached, or the decorator kept faulting there); nothing else was measured.
  bool ready = false;
  /// The residual force the compensation leaves at the point.
  ResidualMeasurement residual;
  /// The release test with compensation on.
  ReleaseMeasurement release;
  /// The release test with compensation off (when compare_uncompensated).
  ReleaseMeasurement release_uncompensated;
  /// The map's value at the point. Unit: [N]
  Eigen::Vector3d map_gravity_n = Eigen::Vector3d::Zero();
  /// Simulation only (VerificationTruth): the point is really reachable.
  bool truly_reachable = true;
  /// Simulation only: the true gravity at the point. Unit: [N]
  Eigen::Vector3d true_gravity_n = Eigen::Vector3d::Zero();
  /// Simulation only: |G_hat - G| at the point. Unit: [N]
  double truth_error_n = 0.0;
  double truth_error_rel = 0.0;  ///< Simulation only: truth_error_n / |G|
};

/// Everything verifyMap measured, point by point and in summary.
struct VerificationReport {
  /// One entry per point.
  std::vector<PointVerification> points;
  /// True when the points were drawn from an explored workspace (else from the grid's box).
  bool points_from_workspace = false;
  /// True when the truth fields were filled (a simulation).
  bool has_truth = false;
  /// Servo period of the run (the map's). Unit: [s]
  double servo_period_s = 0.0;
  /// Servo time of the whole run. Unit: [s]
  double seconds = 0.0;
  /// Largest force sent to the device. Unit: [N]
  double max_force_sent_n = 0.0;
  /// The device's continuous rating (continuousForceRating_n). Unit: [N]
  double continuous_force_rating_n = 0.0;
  /// Servo time spent with a force above the continuous rating, and its longest stretch.
  /// Unit: [s]
  double seconds_above_continuous_force = 0.0;
  /// Unit: [s]
  double longest_above_continuous_force_s = 0.0;
  /// Ticks that sent the device's force limit (within 0.1 %).
  std::uint64_t force_limit_ticks = 0;
  /// Ticks whose force the decorator clamped.
  std::uint64_t clamp_count = 0;
  /// Ticks that ended in each ServoFault, by its value.
  std::array<std::uint64_t, kServoFaultKinds> fault_counts{};

  // Summaries over the points that were ready (residual: over the valid probes).
  /// Residual force over the valid probes. Unit: [N]
  Percentiles residual_force_n;
  /// Residual force over |G_hat| at each point, over the valid probes.
  Percentiles residual_force_rel;
  /// The friction the probes saw (ResidualMeasurement::holding_friction_n). Unit: [N]
  Percentiles holding_friction_n;
  /// Drift after each release, compensated. Unit: [m]
  Percentiles drift_m;
  /// Drift after each release, uncompensated. Unit: [m]
  Percentiles drift_uncompensated_m;
  /// Simulation only: |G_hat - G| at the points. Unit: [N]
  Percentiles truth_error_n;
  /// Simulation only: |G_hat - G| / |G| at the points.
  Percentiles truth_error_rel;
  /// Fraction of compensated releases that did not move beyond stuck_threshold_m.
  double stuck_fraction = 0.0;
  /// Compensated releases that drifted and were caught.
  int caught_releases = 0;
  double median_gravity_n = 0.0;  ///< Median |G_hat| at the points. Unit: [N]
  /// Points the device carried itself to.
  int reached_points = 0;
  /// Points where the end-effector could be held (PointVerification::ready).
  int ready_points = 0;
  /// Points whose residual probe was valid.
  int valid_residuals = 0;
  /// Simulation only: points the simulator says are out of reach.
  int unreachable_points = 0;
};

/// autograv verify, on any device and with no hand on it: at seeded points drawn uniformly from
/// the map's explored workspace (drawVerificationPoints), the device carries itself to the point
/// under its own soft PD on top of the map's compensation (carryTo) and holds it there until the
/// decorator has compensation fully in; the residual force is probed (measureResidualForce); the
/// end-effector is released under compensation alone and its drift measured, caught when it
/// drifts (measureRelease); optionally again with compensation off. Every force sent stays
/// within the budget (VerificationOptions::force_budget_fraction) but for transients, and the
/// force sent, the time above the continuous rating and the decorator's clamps are reported.
/// Only driver data drives the run; `truth` (simulations) only scores. `device` must be open and
/// homed; `ticks` paces the loop. Throws autograv::Error when the device does not accept the map
/// or gives no position. Not real-time safe (runs the servo loop itself).
VerificationReport verifyMap(const std::shared_ptr<HapticDevice>& device, TickSource& ticks,
                             std::shared_ptr<const GravityMap> map,
                             const VerificationOptions& options, bool allow_model_mismatch = false,
                             const VerificationTruth* truth = nullptr);

}  // namespace autograv
