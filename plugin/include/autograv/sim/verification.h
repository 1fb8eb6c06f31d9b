#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/gravity_compensated_device.h"
#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

/// How the residual force of a map is probed at a point: a soft PD hold on top of the map's
/// compensation pulls the end-effector toward the point, once from each side along each axis.
///
/// Why it works: at rest the hold's effort F balances what the compensation misses,
/// r = G - G_hat, plus the dry friction f left loaded by the approach: F = r + f. Approached from
/// the opposite side every joint last slid the other way, f changes sign, and the mean of the two
/// efforts is r. Only what a real driver gives is used: positions, estimated velocities, forces.
///
/// Why soft: the effort is read as K (X_target - X), so one encoder count is K times the count of
/// force. At 20 N/m one count of an Omni-class encoder (0.055 mm at the tip) is 1.1 mN; a stiff
/// hold of 1 N/mm would read in steps of 55 mN, blind to the errors that matter.
struct ResidualProbeOptions {
  /// Stiffness of the hold. Unit: [N/m]
  double stiffness_n_per_m = 20.0;
  /// Damping ratio of the hold with the apparent mass the caller gives (over-damped, so that the
  /// end-effector slides into its rest position without overshooting and reversing its friction).
  double damping_ratio = 1.5;
  /// The target first goes this far past the point on the other side, then back to the point.
  /// Unit: [m]
  double approach_distance_m = 0.009;
  /// Time the end-effector gets to reach the far side. Unit: [s]
  double retreat_s = 0.8;
  /// Time from the target's return to the point to the end of the averaging. Unit: [s]
  double approach_s = 1.2;
  /// The effort is averaged over this last part of approach_s. Unit: [s]
  double average_s = 0.25;
  /// An approach that moved the end-effector less than this fraction of approach_distance_m
  /// was held by friction, not by the hold: it is redone with the stiffness doubled, at most
  /// max_stiffness_doublings times.
  double min_slide_fraction = 0.25;
  /// How often a held approach is redone with the stiffness doubled.
  int max_stiffness_doublings = 2;
  /// Approaches from each side along each axis, averaged, toward targets spread evenly over
  /// target_spread_m along the axis around the point. The residual is smooth over millimetres;
  /// what is not averages out: cogging (a period of a few millimetres at the tip of a
  /// capstan-driven device), the encoder counts and the DAC steps at the rest positions.
  int approaches_per_side = 4;
  /// Unit: [m]
  double target_spread_m = 0.004;
  /// The far-side targets stay within this box (shorter approaches near its faces). Unit: [m]
  Eigen::Vector3d keep_within_min_m = Eigen::Vector3d::Constant(-HUGE_VAL);
  /// Upper corner of that box. Unit: [m]
  Eigen::Vector3d keep_within_max_m = Eigen::Vector3d::Constant(HUGE_VAL);
};

/// Outcome of probing one point.
struct ResidualMeasurement {
  /// Every probe slid into its rest position and the readings never failed.
  bool valid = false;
  /// Estimated G - G_hat at the point: the force the map is missing. Unit: [N]
  Eigen::Vector3d residual_force_n = Eigen::Vector3d::Zero();
  /// Mean over the axes of half the difference between the efforts from the two sides along the
  /// approach axis: the dry friction the hold saw. Unit: [N]
  double holding_friction_n = 0.0;
  /// Stiffness of the hold that was used (raised when friction held the end-effector). Unit: [N/m]
  double stiffness_n_per_m = 0.0;
  /// Probes whose position still changed during the averaging window.
  int unsettled_probes = 0;
  /// Simulated or wall time taken. Unit: [s]
  double seconds = 0.0;
};

/// Probes the residual force at `point_m` through `device`, which must add the map's
/// compensation itself (a GravityCompensatedDevice at full compensation). `apparent_mass_kg`
/// sets the damping (|G_hat| / g is good enough). Commands the device on every tick of `ticks`;
/// ends holding the end-effector at the point, still. Allocates nothing, throws nothing
/// (the servo path runs inside). Units: [m], [kg]
ResidualMeasurement measureResidualForce(HapticDevice& device, TickSource& ticks,
                                         const Eigen::Vector3d& point_m, double apparent_mass_kg,
                                         const ResidualProbeOptions& options) noexcept;

/// Outcome of letting go of the end-effector.
struct ReleaseMeasurement {
  bool valid = false;  ///< Every position read succeeded.
  /// Measured distance from the release position at the end. Unit: [m]
  double drift_m = 0.0;
  /// Largest measured distance from the release position. Unit: [m]
  double max_excursion_m = 0.0;
  /// Friction kept the end-effector within stuck_threshold_m the whole time.
  bool stuck = false;
};

/// Sends zero application force through `device` for `duration_s` from where the end-effector is
/// and measures how far it goes, from the driver's positions. Allocates nothing, throws nothing.
/// Units: [s], [m]
ReleaseMeasurement measureRelease(HapticDevice& device, TickSource& ticks, double duration_s,
                                  double stuck_threshold_m) noexcept;

/// Median, 90th percentile and maximum of a set of values (zeros when empty).
struct Percentiles {
  /// The median.
  double median = 0.0;
  /// The 90th percentile.
  double p90 = 0.0;
  /// The largest value.
  double max = 0.0;
};
Percentiles percentiles(std::vector<double> values);

/// Settings of verifyMap.
struct VerificationOptions {
  int points = 100;        ///< Seeded points drawn uniformly inside the map's grid.
  std::uint64_t seed = 1;  ///< Seed of the points.
  /// Time after each release. Unit: [s]
  double release_s = 1.0;
  /// "Stuck": no measured motion beyond this after a release (a few encoder counts). Unit: [m]
  double stuck_threshold_m = 1.5e-4;
  /// How the residual force is probed at each point.
  ResidualProbeOptions probe;
  /// Ramp and margins of the compensation under test; the servo period is the map's.
  CompensationOptions compensation;
  /// How the servo ticks arrive, drawn from servo_timing_seed (README, "Servo timing").
  ServoTiming servo_timing = ServoTiming::kExact;
  std::uint64_t servo_timing_seed = 1;  ///< Seed of the timing model's draws.
  /// Also release every point with compensation off (the baseline the drift is compared with).
  bool compare_uncompensated = true;
  /// Called after each point of each pass with (points done, points in all passes).
  std::function<void(int done, int total, bool compensated)> on_progress;
};

/// Everything verify measured at one point.
struct PointVerification {
  /// The point, drawn inside the map's grid. Unit: [m]
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  /// False when the end-effector could not be held at the point with full compensation (the
  /// decorator kept faulting there); nothing else was measured.
  bool ready = false;
  /// The residual force the compensation leaves at the point.
  ResidualMeasurement residual;
  /// The release test with compensation on.
  ReleaseMeasurement release;
  /// The release test with compensation off (when compare_uncompensated).
  ReleaseMeasurement release_uncompensated;
  /// Simulation only: the map's value, the truth and |G_hat - G| at the point. Unit: [N]
  Eigen::Vector3d map_gravity_n = Eigen::Vector3d::Zero();
  /// The simulator's true gravity at the point. Unit: [N]
  Eigen::Vector3d true_gravity_n = Eigen::Vector3d::Zero();
  /// |G_hat - G| at the point. Unit: [N]
  double truth_error_n = 0.0;
  double truth_error_rel = 0.0;  ///< truth_error_n / |G|
};

/// Everything verifyMap measured, point by point and in summary.
struct VerificationReport {
  /// One entry per point.
  std::vector<PointVerification> points;
  /// Servo period of the run (the map's). Unit: [s]
  double servo_period_s = 0.0;
  /// Simulated time of the whole run. Unit: [s]
  double simulated_seconds = 0.0;
  /// Largest force the decorator sent to the device. Unit: [N]
  double max_force_sent_n = 0.0;
  /// Ticks whose force the decorator clamped.
  std::uint64_t clamp_count = 0;
  /// Ticks that ended in each ServoFault, by its value.
  std::array<std::uint64_t, kServoFaultKinds> fault_counts{};

  // Summaries over the points that were ready (residual: over the valid probes).
  /// Residual force over the valid probes. Unit: [N]
  Percentiles residual_force_n;
  /// Drift after each release, compensated. Unit: [m]
  Percentiles drift_m;
  /// Drift after each release, uncompensated. Unit: [m]
  Percentiles drift_uncompensated_m;
  /// |G_hat - G| at the points. Unit: [N]
  Percentiles truth_error_n;
  /// |G_hat - G| / |G| at the points.
  Percentiles truth_error_rel;
  /// Fraction of compensated releases that did not move beyond stuck_threshold_m.
  double stuck_fraction = 0.0;
  double median_gravity_n = 0.0;  ///< Median |G_hat| at the points. Unit: [N]
  /// Points where the end-effector could be held (PointVerification::ready).
  int ready_points = 0;
  /// Points whose residual probe was valid.
  int valid_residuals = 0;
  ServoLoopStats::Summary servo_loop;  ///< What the servo loop did.
};

/// autograv verify on a simulated device: at seeded points inside the map's grid, the simulated
/// hand carries the end-effector to the point and holds it until the decorator has compensation
/// fully ramped in (so nothing carries over from a release that faulted or left the grid), then
/// the residual force is probed (measureResidualForce), then the end-effector is released from
/// the hold (measureRelease). Optionally the same releases with compensation off. The truth is
/// used only for the simulation-only error fields. Throws autograv::Error when the device does
/// not accept the map. The device must be open. Not real-time safe.
VerificationReport verifyMapOnSimulatedDevice(const std::shared_ptr<SimulatedDevice>& device,
                                              std::shared_ptr<const GravityMap> map,
                                              const VerificationOptions& options,
                                              bool allow_model_mismatch = false);

}  // namespace autograv::sim
