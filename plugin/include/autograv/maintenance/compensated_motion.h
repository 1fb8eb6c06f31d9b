#pragma once

#include <cmath>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/map/explored_workspace.h"

/// \file
/// What a device does by itself, with no hand on it, on top of the map's compensation: carry
/// the end-effector to a point (carryTo), probe the residual force there (measureResidualForce)
/// and let go of it, catching it when it drifts (measureRelease). verifyMap
/// (map_verification.h) is made of these; each is real-time safe on its own.

namespace autograv {

/// What a hold may send on top of the map's compensation: at most max_effort_n of its own, and at
/// most max_total_n together with the compensation it rides on (`compensation_n`, the map's value
/// where the hold works). So a map that is off costs a larger effort, never a larger force on
/// the device. Zero: no limit.
struct EffortLimit {
  /// Unit: [N]
  double max_effort_n = 0.0;
  /// Unit: [N]
  double max_total_n = 0.0;
  /// Unit: [N]
  Eigen::Vector3d compensation_n = Eigen::Vector3d::Zero();

  /// Trims `effort_n` to the limits. Real-time safe. Unit: [N]
  void apply(Eigen::Vector3d& effort_n) const noexcept;
};

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
  /// How often the stiffness may be doubled in all (over the three axes): at most 80 N/m.
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
  /// The far-side targets also stay keep_inside_margin_m inside this workspace (shorter
  /// approaches near its boundary; no limit when empty): a probe never pulls toward a stop.
  ExploredWorkspace keep_inside;
  /// Unit: [m]
  double keep_inside_margin_m = 0.0015;
  /// What the hold may send. At rest the effort is the residual plus the friction, far below
  /// it: the limit only trims the step when the target jumps.
  EffortLimit limit;
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

/// How the device carries itself to a point, with no hand on it: a minimum-jerk path tracked by
/// a soft PD on top of the map's compensation. Soft, so that what the map misses costs a lag of
/// a fraction of a millimetre and not a force, and so that a stop the path runs into is felt as
/// a lag, not rammed.
struct CarryOptions {
  /// Stiffness of the tracking PD. At 150 N/m a residual of 30 mN lags the path by 0.2 mm, and
  /// the effort cap below is reached 1-3 mm off the path. Unit: [N/m]
  double stiffness_n_per_m = 150.0;
  /// Damping ratio of the PD with the apparent mass the caller gives.
  double damping_ratio = 1.0;
  /// Peak acceleration of the path: a 10 cm move takes 1.4 s, the pace of a calm hand.
  /// Unit: [m/s^2]
  double max_acceleration_m_per_s2 = 0.3;
  /// Shortest move. Unit: [s]
  double min_duration_s = 0.3;
  /// Hold at the point after the path ends, for the end-effector to come to rest. Unit: [s]
  double settle_s = 0.3;
  /// What the PD may send (verifyMap sets max_total_n and compensation_n from its force budget,
  /// and max_effort_n to the budget when it is 0).
  EffortLimit limit;
  /// A path the end-effector lags by more than this for blocked_s is blocked (a stop, or a
  /// point outside what the device reaches): the move ends where the end-effector is.
  /// Unit: [m]
  double blocked_lag_m = 0.004;
  /// Unit: [s]
  double blocked_s = 0.1;
  /// The path's targets stay this far inside this workspace (when not empty). Unit: [m]
  ExploredWorkspace keep_inside;
  /// Unit: [m]
  double keep_inside_margin_m = 0.002;
};

/// Outcome of a carry.
struct CarryOutcome {
  /// The end-effector followed the path to its end.
  bool reached = false;
  /// Every read succeeded.
  bool read_ok = true;
  /// Servo time taken. Unit: [s]
  double seconds = 0.0;
};

/// Carries the end-effector from where it is to `to_m` (CarryOptions) through `device`, which
/// adds the map's compensation itself; ends holding it at `to_m`, or where it was when the path
/// was blocked. Allocates nothing, throws nothing. Units: [m], [kg]
CarryOutcome carryTo(HapticDevice& device, TickSource& ticks, const Eigen::Vector3d& to_m,
                     double apparent_mass_kg, const CarryOptions& options) noexcept;

/// How a release is watched, and caught when it drifts.
struct ReleaseOptions {
  /// Time after the release. Unit: [s]
  double duration_s = 1.0;
  /// "Stuck": no measured motion beyond this after a release (a few encoder counts). Unit: [m]
  double stuck_threshold_m = 1.5e-4;
  /// A release that drifts farther than this from where it was let go, or to within
  /// catch_margin_m of the boundary of catch_inside, is caught: a PD hold with damping stops the
  /// end-effector where it is (no hand is there to catch it). 0: never caught. Unit: [m]
  double catch_drift_m = 0.0;
  /// The workspace a drifting release must stay inside (nothing, when empty).
  ExploredWorkspace catch_inside;
  /// Unit: [m]
  double catch_margin_m = 0.001;
  /// Stiffness of the catching hold. Unit: [N/m]
  double catch_stiffness_n_per_m = 150.0;
  /// Damping of the catching hold: 1 N at 0.17 m/s. Unit: [N s/m]
  double catch_damping_n_s_per_m = 6.0;
  /// What the catching hold may send.
  EffortLimit catch_limit{0.3};
  /// How long the catching hold lasts. Unit: [s]
  double catch_hold_s = 0.4;
};

/// Outcome of letting go of the end-effector.
struct ReleaseMeasurement {
  bool valid = false;  ///< Every position read succeeded.
  /// Measured distance from the release position at the end (or when caught). Unit: [m]
  double drift_m = 0.0;
  /// Largest measured distance from the release position. Unit: [m]
  double max_excursion_m = 0.0;
  /// Friction kept the end-effector within stuck_threshold_m the whole time.
  bool stuck = false;
  /// The release drifted beyond catch_drift_m (or toward the boundary) and was caught.
  bool caught = false;
  /// Time from the release to the catch. Unit: [s]
  double caught_after_s = 0.0;
};

/// Sends zero application force through `device` for `duration_s` from where the end-effector is
/// and measures how far it goes, from the driver's positions; a drifting release is caught
/// through `catch_device` (null: `device`), which adds compensation when `device` does not.
/// Allocates nothing, throws nothing.
ReleaseMeasurement measureRelease(HapticDevice& device, TickSource& ticks,
                                  const ReleaseOptions& options,
                                  HapticDevice* catch_device = nullptr) noexcept;

/// The same, never caught. Allocates nothing, throws nothing. Units: [s], [m]
ReleaseMeasurement measureRelease(HapticDevice& device, TickSource& ticks, double duration_s,
                                  double stuck_threshold_m) noexcept;

}  // namespace autograv
