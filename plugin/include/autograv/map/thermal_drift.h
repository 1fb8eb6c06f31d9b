#pragma once

#include <algorithm>
#include <vector>

#include <Eigen/Core>

#include "autograv/map/workspace_grid.h"
#include "autograv/types/vertex_estimate.h"

/// \file
/// A calibration that sees its own motors warm: the torque a motor gives per command falls as it
/// heats (its magnet weakens; where the amplifier drives a voltage, its winding's resistance
/// rises too), and a calibration holds gravity for minutes, so its last measurements read more
/// command than its first for the same field. The calibration measures a few of its first points
/// again at its end, fits the loss of torque per unit of thermal load (the square of the force
/// sent over the continuous rating, low-passed over the motors' time constant:
/// GravityCompensatedDevice::thermalLoad) to what they read, takes it out of every measurement,
/// and the map keeps it, so that the decorator gives back what the motors lose as they warm in
/// use. From driver data only: the forces sent and the positions read.

namespace autograv {

/// What a calibration saw of its motors warming: MapMetadata::thermal_drift.
struct ThermalDrift {
  /// Torque per command lost per unit of thermal load, in [0, kMaxGainLossPerLoad]: at a load L
  /// the device delivers (1 - gain_loss_per_load * L) of what it delivered cold. The map's values
  /// are those of motors at room temperature (load 0). 0: no correction (none seen, or none
  /// measured).
  double gain_loss_per_load = 0.0;
  /// Its standard error, from the scatter of the points measured again and their repeatability.
  double gain_loss_standard_error = 0.0;
  /// Points measured again at the calibration's end; 0 when it did not look.
  int points = 0;
  /// Mean thermal load when the points were first measured, and when measured again.
  double first_load = 0.0;
  /// See first_load.
  double again_load = 0.0;
  /// How much more command the points needed the second time, relative, on average: what the
  /// warming did during the calibration.
  double drift_rel = 0.0;
};

/// Largest loss of torque per unit of load a map accepts: a device that would lose all of it at
/// its rated temperature rise. Ferrite magnets and copper windings on a voltage drive lose about
/// 0.4 per unit load (0.5 %/K over an 80 K rated rise), NdFeB on a current drive about 0.1.
inline constexpr double kMaxGainLossPerLoad = 1.0;
/// The smallest share of its cold torque the correction assumes a device keeps, so that a wrong
/// load never multiplies the map without bound.
inline constexpr double kMinThermalGain = 0.5;
/// Points measured again to see the drift.
inline constexpr int kThermalDriftPoints = 3;
/// Below this thermal load at the end of the pass over the plan the motors did not warm enough
/// for a drift to be seen, and none is looked for.
inline constexpr double kMinDriftLoad = 0.02;

/// The factor by which a map's gravity is multiplied at thermal load `load`: 1 / (1 - k L), k
/// the drift's gain_loss_per_load, the gain floored at kMinThermalGain. Real-time safe.
inline double thermalScale(const ThermalDrift& drift, double load) noexcept {
  if (!(drift.gain_loss_per_load > 0.0) || !(load > 0.0)) return 1.0;
  return 1.0 / std::max(kMinThermalGain, 1.0 - drift.gain_loss_per_load * load);
}

/// A point measured early in a calibration, to be measured again at its end.
struct DriftReference {
  int vertex = -1;                                          ///< Grid index.
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();        ///< Where. Unit: [m]
  Eigen::Vector3d first_value_n = Eigen::Vector3d::Zero();  ///< What it read first. Unit: [N]
  double first_load = 0.0;  ///< The thermal load then (VertexEstimate::thermal_load).
};

/// After the pass over the plan: the kThermalDriftPoints converged vertices measured at the
/// lowest thermal load (the first ones: a winding warms within a minute or two, so later points
/// miss its share), each where it was measured (a point by the stops is measured just inside
/// them, and its stop watch meets the stop again there), leaving out `exclude` (the measurements
/// the review measures again anyway), any measured above half the highest load and any at load 0
/// (restored from an earlier run: VertexEstimate::thermal_load). Empty when the
/// load never passed kMinDriftLoad. Measure them again (AutoCalibrator::remeasureAt, at point_m)
/// in the pass that redoes the failed vertices, then call concludeThermalDrift. Not real-time
/// safe.
std::vector<DriftReference> planThermalDriftCheck(const WorkspaceGrid& grid,
                                                  const std::vector<VertexEstimate>& vertices,
                                                  const std::vector<int>& exclude = {});

/// Fits the loss of torque per unit load to what `references` read again (their vertices in
/// `vertices` now hold the second measurement), and takes it out of every measured value of
/// `vertices` (gravity_n and measured_gravity_n times 1 - k * thermal_load), so that the map is
/// of motors at room temperature. `eps_g_n`, the calibration's eps_G, is the repeatability of one
/// measurement. A reference whose second hold did not converge is skipped. Throws
/// autograv::Error when `vertices` does not match `grid`. Not real-time safe.
ThermalDrift concludeThermalDrift(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices,
                                  const std::vector<DriftReference>& references, double eps_g_n);

}  // namespace autograv
