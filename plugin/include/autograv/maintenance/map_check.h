#pragma once

#include <string>

#include "autograv/maintenance/spot_measurement.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// Does a saved map still fit its device? The inner loop runs at a few vertices from the map's
/// values; where the device needs a G_hat that differs from the map's by more than the tolerance,
/// the map no longer fits, and the shape of the difference says why: the same vertical change
/// everywhere is a new handle (re-tare), a rotation of G is a tilted or moved device (calibrate
/// again).
struct MapCheckOptions {
  /// How each vertex is measured.
  SpotMeasurementOptions measurement;
  /// Vertices measured: the ones nearest the centre of the map's grid.
  int vertex_count = 3;
  /// Largest |G_measured - G_map| / |G_map| at a vertex that still fits. A converged vertex of a
  /// healthy device differs by well under 1 % (eps_G over |G|, plus noise): 3 % never fires on
  /// one, and is still 2 g on an Omni's handle.
  double tolerance_rel = 0.03;
};

enum class MapFit { kFits, kRetare, kRecalibrate, kMeasurementFailed };
/// "fits", "retare", "recalibrate", "measurement_failed".
const char* toString(MapFit fit) noexcept;

/// The verdict of checkMap, with the measurements behind it.
struct MapCheckResult {
  /// The verdict.
  MapFit fit = MapFit::kFits;
  std::string reason;          ///< One or two sentences a user can act on.
  double max_error_rel = 0.0;  ///< Worst |G_measured - G_map| / |G_map| over the vertices.
  double payload_kg = 0.0;     ///< Mean change along the map's up direction over g. Unit: [kg]
  double tilt_rad = 0.0;       ///< Mean angle between measured and mapped G. Unit: [rad]
  /// The measurements the verdict rests on.
  SpotMeasurement measurement;
};

/// Runs the check (see MapCheckOptions). Does not throw on a map that does not fit: that is the
/// result. Throws autograv::Error only when the device cannot be driven at all. Not real-time
/// safe (runs the servo loop itself).
MapCheckResult checkMap(HapticDevice& device, TickSource& ticks, const GravityMap& map,
                        const MapCheckOptions& options);

}  // namespace autograv
