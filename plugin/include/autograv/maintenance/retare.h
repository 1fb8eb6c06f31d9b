#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/maintenance/spot_measurement.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// Re-taring a map after a handle change. A point load m on the end-effector of a 3-DoF device
/// adds the same force m g (along "up") at every position, so measuring the change at one to three
/// vertices and shifting every vertex by it gives the map a full calibration with the load would
/// give, in seconds instead of minutes.
struct RetareOptions {
  /// How each vertex is measured.
  SpotMeasurementOptions measurement;
  /// How many vertices near the grid centre to measure at (1 to 3); their mean shift is used.
  int vertex_count = 3;
  /// The shift measured at different vertices may differ by at most this fraction of |G|: more
  /// means the change is not a point load (the device moved or was tilted), and the map must be
  /// calibrated again.
  double max_disagreement_rel = 0.03;
};

/// What retareMap measured and the map it made.
struct RetareResult {
  GravityMap map;  ///< The re-tared map (same grid and metadata, every vertex shifted).
  /// The mean change of G_hat over the measured vertices. Unit: [N]
  Eigen::Vector3d shift_n = Eigen::Vector3d::Zero();
  /// The added mass: the shift along the map's mean up direction over g (negative for a lighter
  /// handle). Unit: [kg]
  double payload_kg = 0.0;
  /// Largest difference between one vertex's shift and the mean, over |G|.
  double disagreement_rel = 0.0;
  /// The measurements behind the shift.
  SpotMeasurement measurement;
};

/// Measures and shifts (see RetareOptions). `map` must fit the device otherwise (same unit, same
/// place). Throws autograv::Error when a vertex does not converge, the vertices disagree, or the
/// change is not vertical (a tilted or moved device), with what to do instead; a change within a
/// converged vertex's own scatter (2 eps_G, or 2 % of |G|) is taken as it is, whatever its
/// direction. Not real-time safe (runs the servo loop itself).
RetareResult retareMap(HapticDevice& device, TickSource& ticks, const GravityMap& map,
                       const RetareOptions& options);

/// `map` with every vertex's estimate, and every measurement made off a vertex, moved by
/// `shift_n` (histories kept as measured): a constant shift is the gradient of a linear
/// potential, so the conservative lookup moves by exactly `shift_n` everywhere too.
/// Not real-time safe. Unit: [N]
GravityMap shiftedMap(const GravityMap& map, const Eigen::Vector3d& shift_n);

/// `map` with every vertex's estimate, and every measurement made off a vertex, times `factor`
/// (histories kept as measured): what motors that all deliver 1 / factor of their torque per
/// command need. Not real-time safe.
GravityMap scaledMap(const GravityMap& map, double factor);

}  // namespace autograv
