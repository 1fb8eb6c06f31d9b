#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// The inner loop of the paper (eqs. 10-12) at a few vertices of an existing map's grid, started
/// from the map's own values: what the map says against what the device needs today. Shared by
/// retare (a new handle) and the health check (does the map still fit?).
struct SpotMeasurementOptions {
  /// The estimation at each vertex.
  EstimationParameters parameters;
  /// Added to the map's value for the first estimate (0: trust the map). Unit: [N]
  Eigen::Vector3d initial_offset_n = Eigen::Vector3d::Zero();
  /// Gives up when the run takes longer than this (servo time). Unit: [s]
  double timeout_s = 60.0;
  /// Called between servo ticks, every progress_period_s of servo time. Unit: [s]
  std::function<void(const AutoCalibrator&)> on_progress;
  /// Servo time between two calls of on_progress. Unit: [s]
  double progress_period_s = 0.25;
};

/// The estimates measured at a few vertices of a map.
struct SpotMeasurement {
  std::vector<int> vertices;                   ///< Grid indices measured, as asked.
  std::vector<VertexEstimate> estimates;       ///< One per vertices[k].
  std::vector<Eigen::Vector3d> map_gravity_n;  ///< The map's value there. Unit: [N]
  /// How the measurement ended.
  AutoCalibrator::Status status = AutoCalibrator::Status::kIdle;
  double seconds = 0.0;  ///< Servo time of the whole run, moves included. Unit: [s]
  /// True when the run reached timeout_s before every vertex finished.
  bool timed_out = false;
};

/// True when `change_n` lies within about 25 degrees of the line of `up` (either way): a change
/// of weight, such as a new handle, rather than of gravity's direction (a tilted or moved
/// device). Real-time safe.
bool isChangeOfWeight(const Eigen::Vector3d& change_n, const Eigen::Vector3d& up) noexcept;

/// Up to `count` vertices of `grid` nearest its centre, ties broken by index (deterministic):
/// the middle of the workspace, where a device is best behaved. Not real-time safe.
std::vector<int> centralVertices(const WorkspaceGrid& grid, int count);

/// Holds the end-effector where it is with the map's compensation, carries it to each vertex in
/// turn, runs the inner loop there until it converges, and finally sends zero force. The device
/// must be open and homed; `ticks` paces the loop (a simulated device's tick source advances
/// its physics). Throws autograv::Error when the device does not answer at the start or a vertex
/// index is out of range. Not real-time safe (it runs the servo loop itself).
SpotMeasurement measureAtVertices(HapticDevice& device, TickSource& ticks, const GravityMap& map,
                                  const std::vector<int>& vertices,
                                  const SpotMeasurementOptions& options);

}  // namespace autograv
