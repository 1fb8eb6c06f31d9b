#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// How the map of another unit of the same model is corrected to this unit. Units of one model
/// share their geometry and masses; what differs (each motor's gain, the handle, a small tilt of
/// the base) changes the field smoothly, so a few measurements fit the difference. Which model
/// fits it is chosen from the measurements, by leave-one-out, as the map's field model is.
enum class CorrectionModel : std::uint8_t {
  kShift,          ///< One constant force everywhere (a changed handle).
  kAffine,         ///< (A - I) G_prior(x) + b: motors' gains seen through a nearly constant
                   ///< Jacobian, a tilt, a load.
  kConservative,   ///< A conservative FieldFit of the differences.
  kComponentwise,  ///< Each component of the differences on its own (FieldFit, curl weight 1).
};

/// Stable lower-case name: "shift", "affine", "conservative", "componentwise".
const char* toString(CorrectionModel model) noexcept;

/// One candidate correction's leave-one-out error over the fit points.
struct CorrectionScore {
  CorrectionModel model = CorrectionModel::kShift;  ///< The candidate.
  double mean_rel = 0.0;  ///< Mean |leave-one-out residual| / |G|: what the choice compares.
  double max_rel = 0.0;   ///< Largest.
};

/// What transferMap is doing, for a progress display.
struct TransferProgress {
  /// The two parts of a run.
  enum class Phase : std::uint8_t {
    kProbing,    ///< Probing the stops along the prior's directions.
    kMeasuring,  ///< Measuring the field at the prior's points.
  };
  Phase phase = Phase::kProbing;  ///< What the run is doing now.
  int done = 0;                   ///< Probes, or points, finished.
  int total = 0;                  ///< Probes, or points, planned.
  double seconds = 0.0;           ///< Servo time so far. Unit: [s]
};

/// How transferMap measures and judges.
struct TransferOptions {
  /// The estimation at each point (the prior's own parameters are a good choice).
  EstimationParameters parameters;
  /// Points measured before the first fit, spread over the prior's measurement points (farthest
  /// point first, from the centre), so that the stops' neighbourhood is measured too.
  int first_points = 12;
  /// Points measured in each further batch, while the correction is not yet good enough.
  int batch_points = 4;
  /// Most points measured in all.
  int max_points = 32;
  /// Every this-many-th point of the spread is kept out of the fit, to check it.
  int check_every = 5;
  /// Enough points once the chosen correction predicts each fit point from the others within
  /// this fraction of |G| on average (leave-one-out): about the measurements' own scatter.
  double enough_rel = 0.004;
  /// No further batch that would end past this much device time, the workspace check included.
  /// Unit: [s]
  double time_budget_s = 90.0;
  /// Directions probed (an even spread from where the end-effector starts) to check that this
  /// unit reaches what the prior's unit reached.
  int probe_directions = 6;
  /// A probe that meets its stop further than this from the prior's boundary refuses the prior:
  /// the units' workspaces differ (another model, a bent link, a tool in the way). Unit: [m]
  double max_workspace_difference_m = 0.006;
  /// The corrected map must meet every check point within this fraction of |G|. Typical units
  /// of every model meet theirs within 1.5 %; a Falcon whose motors stray twice as far missed by
  /// 6.9 %, with a map 1.4 points worse at p90 than a whole calibration.
  double max_check_error_rel = 0.03;
  /// A check point stands out when its error exceeds the median of the other check points' by
  /// more than this many of their robust standard deviations (1.4826 times their median
  /// absolute deviation), and by more than that median itself ...
  double stand_out_mads = 3.0;
  /// ... and by more than this fraction of |G|: about the measurements' own scatter, below which
  /// no point stands out however alike the others are. A check point past max_check_error_rel
  /// that stands out is measured again, where it was, before it can refuse the unit; one past
  /// the line that does not stand out refuses at once.
  double stand_out_min_rel = 0.005;
  /// ... and the chosen correction must predict its own fit points from the others within this
  /// (mean leave-one-out): a correction that does not explain the measurements is no correction.
  double max_fit_error_rel = 0.03;
  /// How the prior was named (a path): kept in the map's MapPrior::source.
  std::string prior_source;
  /// Gives up when the run takes longer than this (servo time). Unit: [s]
  double timeout_s = 180.0;
  /// Called every progress_period_s of servo time and when a probe or point finishes.
  std::function<void(const TransferProgress&)> on_progress;
  double progress_period_s = 0.5;  ///< Unit: [s]
};

/// What transferMap measured, the correction it chose and, when that passed its check, the map.
struct TransferResult {
  /// True when the correction passed its check: `map` is this unit's map. False: `refusal`
  /// says why, with the figures, and no map may be saved.
  bool accepted = false;
  std::string refusal;            ///< Empty when accepted.
  std::optional<GravityMap> map;  ///< The corrected map; empty when refused.
  MapPrior prior;  ///< The provenance and the correction, as the map's metadata keeps it.
  std::vector<CorrectionScore> scores;  ///< Every candidate's, in CorrectionModel's order.
  int converged_points = 0;             ///< Points whose estimate converged.
  int failed_points = 0;                ///< Points left out (no convergence, a stop on the way).
  double seconds = 0.0;                 ///< Servo time of the whole run. Unit: [s]
  double probe_seconds = 0.0;           ///< Of that, the workspace check. Unit: [s]
  double peak_force_n = 0.0;            ///< Largest force sent. Unit: [N]
  /// Servo time with a force above the device's continuous rating. Unit: [s]
  double seconds_above_continuous_force = 0.0;
  /// Every point measured (fit and check points alike). Unit: [m]
  std::vector<Eigen::Vector3d> points_m;
  /// The prior's value at each of points_m. Unit: [N]
  std::vector<Eigen::Vector3d> prior_n;
  /// This unit's measurement at each of points_m. Unit: [N]
  std::vector<Eigen::Vector3d> measured_n;
  std::vector<bool> is_check;  ///< Per point: a check point.
  /// Per check point, in the order of points_m: |corrected map - measurement| / |G|, after any
  /// point measured again.
  std::vector<double> check_errors_rel;
  /// The largest check error before any point was measured again: prior.check_max_rel when
  /// none was.
  double first_check_max_rel = 0.0;
  /// Check points measured again because they stood out past the line (points_m, measured_n
  /// and estimates hold the new measurement).
  int remeasured_points = 0;
  /// Servo time spent measuring check points again, included in `seconds`. Unit: [s]
  double remeasure_seconds = 0.0;
  /// Per point: the inner loop's record there (iterations, seconds held, history).
  std::vector<VertexEstimate> estimates;
};

/// Throws autograv::Error, before the device moves, when `prior` cannot be this device's prior:
/// another model (DeviceSpecifications::model_name), no explored workspace, or too few measured
/// points for `options`. Not real-time safe.
void checkTransferPrior(const GravityMap& prior, const std::string& device_model,
                        const TransferOptions& options);

/// The prior's measured points, farthest point first from the one nearest its workspace's centre:
/// the grid indices of the vertices measured there. Not real-time safe.
std::vector<int> spreadMeasuredVertices(const GravityMap& prior, int count);

/// Per value of `errors_rel`, whether it stands out from the others: it exceeds their median by
/// more than `mads` times their robust standard deviation (1.4826 times their median absolute
/// deviation), by more than `min_rel`, and by more than that median itself (at least twice what
/// the others show). With fewer than three values there is nothing to judge
/// one against, and every value stands out. Not real-time safe.
std::vector<bool> standingOut(const std::vector<double>& errors_rel, double mads, double min_rel);

/// Makes this unit's map from `prior`, the map of another unit of the same model: probes the
/// stops along a few of the prior's own directions (refused when they lie elsewhere), measures
/// the field at the prior's own measurement points, spread farthest first, in batches
/// (TransferOptions::first_points, then batch_points at a time, each point started from the
/// prior's value plus the correction so far), fits each CorrectionModel to the differences after
/// each batch and keeps the one with the smallest leave-one-out error (a simpler one unless
/// beaten by 5 %), stops once that error is within enough_rel or another batch would pass
/// time_budget_s, corrects every value of the prior, and judges the corrected map on the check
/// points (every check_every-th point, never fitted); a check point past max_check_error_rel
/// that stands out from the others (standingOut) is measured again before it can refuse the
/// unit. The device must be open and homed, its end-effector at rest inside the workspace (the
/// prior's compensation holds it); `ticks` paces the loop. Throws autograv::Error as
/// checkTransferPrior does, and when the device stops answering; returns a refused result, with no
/// map, when the workspace, the fit or the check disagree. Not real-time safe (runs the servo loop
/// itself).
TransferResult transferMap(HapticDevice& device, TickSource& ticks, const GravityMap& prior,
                           const TransferOptions& options);

/// `prior` with `correction` added to every value (as MapPrior describes it) and `metadata` as
/// the new map's. Not real-time safe.
GravityMap correctedMap(const GravityMap& prior, const MapPrior& correction, MapMetadata metadata);

}  // namespace autograv
