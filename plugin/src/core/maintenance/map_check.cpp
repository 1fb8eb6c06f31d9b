#include "autograv/maintenance/map_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include <Eigen/Geometry>

namespace autograv {

namespace {

std::string format(const char* pattern, double a, double b = 0.0) {
  char text[320];
  std::snprintf(text, sizeof text, pattern, a, b);
  return text;
}

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

}  // namespace

const char* toString(MapFit fit) noexcept {
  switch (fit) {
    case MapFit::kFits:
      return "fits";
    case MapFit::kRetare:
      return "retare";
    case MapFit::kRecalibrate:
      return "recalibrate";
    case MapFit::kMeasurementFailed:
      return "measurement_failed";
  }
  return "unknown";
}

MapCheckResult checkMap(HapticDevice& device, TickSource& ticks, const GravityMap& map,
                        const MapCheckOptions& options) {
  MapCheckResult result;
  result.measurement = measureAtVertices(
      device, ticks, map, centralVertices(map.grid(), options.vertex_count), options.measurement);
  const SpotMeasurement& measurement = result.measurement;
  Eigen::Vector3d change_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  const std::size_t count = measurement.vertices.size();
  for (std::size_t k = 0; k < count; ++k) {
    const VertexEstimate& estimate = measurement.estimates[k];
    const Eigen::Vector3d& mapped_n = measurement.map_gravity_n[k];
    if (estimate.outcome != VertexOutcome::kConverged) {
      result.fit = MapFit::kMeasurementFailed;
      result.reason = "the measurement at vertex " + std::to_string(measurement.vertices[k]) +
                      " did not converge (" + toString(estimate.outcome) +
                      "): keep the end-effector free and run the check again; if it fails "
                      "again, calibrate the device again";
      return result;
    }
    result.max_error_rel =
        std::max(result.max_error_rel, (estimate.gravity_n - mapped_n).norm() / mapped_n.norm());
    result.tilt_rad += angleBetween(estimate.gravity_n, mapped_n) / static_cast<double>(count);
    change_n += (estimate.gravity_n - mapped_n) / static_cast<double>(count);
    up += mapped_n;
  }
  up.normalize();
  result.payload_kg = change_n.dot(up) / kStandardGravity;
  if (result.max_error_rel <= options.tolerance_rel) {
    result.fit = MapFit::kFits;
    result.reason =
        format("the map fits: the largest difference is %.2f %% of |G| (tolerance %.1f %%)",
               100.0 * result.max_error_rel, 100.0 * options.tolerance_rel);
    return result;
  }
  if (isChangeOfWeight(change_n, up)) {
    result.fit = MapFit::kRetare;
    result.reason = format(
        "the map does not fit: the end-effector's weight changed by %+.1f g since it was "
        "calibrated (%.1f %% of |G|), as after a handle change; re-tare it (retareMap)",
        result.payload_kg * 1e3, 100.0 * result.max_error_rel);
  } else {
    result.fit = MapFit::kRecalibrate;
    result.reason = format(
        "the map does not fit: gravity is turned by %.1f degrees against the map (%.1f %% of |G|), "
        "as when the device is tilted or moved; calibrate it again (CalibrationWizard)",
        result.tilt_rad * 180.0 / 3.14159265358979323846, 100.0 * result.max_error_rel);
  }
  return result;
}

}  // namespace autograv
