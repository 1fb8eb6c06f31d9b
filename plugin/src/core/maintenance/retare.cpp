#include "autograv/maintenance/retare.h"

#include <algorithm>
#include <cstdio>
#include <utility>

#include "autograv/error.h"

namespace autograv {

namespace {

/// `map` with every value the lookup is made from (a map's off-vertex measurements feed its fit
/// too) taken to factor * value + shift_n.
GravityMap affineMap(const GravityMap& map, double factor, const Eigen::Vector3d& shift_n) {
  std::vector<VertexEstimate> vertices = map.vertices();
  for (VertexEstimate& vertex : vertices) {
    vertex.gravity_n = factor * vertex.gravity_n + shift_n;
    if (vertex.measuredOffVertex()) {
      vertex.measured_gravity_n = factor * vertex.measured_gravity_n + shift_n;
    }
  }
  return GravityMap(map.grid(), std::move(vertices), map.metadata());
}

}  // namespace

GravityMap shiftedMap(const GravityMap& map, const Eigen::Vector3d& shift_n) {
  return affineMap(map, 1.0, shift_n);
}

GravityMap scaledMap(const GravityMap& map, double factor) {
  return affineMap(map, factor, Eigen::Vector3d::Zero());
}

RetareResult retareMap(HapticDevice& device, TickSource& ticks, const GravityMap& map,
                       const RetareOptions& options) {
  if (options.vertex_count < 1 || options.vertex_count > 3) {
    throw Error("retare: measure at 1 to 3 vertices");
  }
  SpotMeasurement measurement = measureAtVertices(
      device, ticks, map, centralVertices(map.grid(), options.vertex_count), options.measurement);
  Eigen::Vector3d shift_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  double gravity_norm_n = 0.0;
  const std::size_t count = measurement.vertices.size();
  for (std::size_t k = 0; k < count; ++k) {
    const VertexEstimate& estimate = measurement.estimates[k];
    if (estimate.outcome != VertexOutcome::kConverged) {
      throw Error("retare: vertex " + std::to_string(measurement.vertices[k]) +
                  " did not converge (" + toString(estimate.outcome) +
                  (measurement.timed_out ? ", time limit reached" : "") +
                  "); keep the end-effector free and try again, or calibrate again");
    }
    shift_n += estimate.gravity_n - measurement.map_gravity_n[k];
    up += measurement.map_gravity_n[k];
    gravity_norm_n += measurement.map_gravity_n[k].norm();
  }
  shift_n /= static_cast<double>(count);
  gravity_norm_n /= static_cast<double>(count);
  double disagreement_n = 0.0;
  for (std::size_t k = 0; k < count; ++k) {
    const Eigen::Vector3d shift_k =
        measurement.estimates[k].gravity_n - measurement.map_gravity_n[k];
    disagreement_n = std::max(disagreement_n, (shift_k - shift_n).norm());
  }
  RetareResult result{shiftedMap(map, shift_n), shift_n,
                      shift_n.dot(up.normalized()) / kStandardGravity,
                      disagreement_n / gravity_norm_n, std::move(measurement)};
  // A change within what one converged vertex scatters by (twice eps_G, or 2 % of |G|: a gram
  // or so) has no direction to judge: the handle did not change, and the map keeps its weight.
  const double noise_n =
      std::max(2.0 * options.measurement.parameters.eps_g_n, 0.02 * gravity_norm_n);
  if (shift_n.norm() > noise_n && !isChangeOfWeight(shift_n, up)) {
    throw Error(
        "retare: the change is not vertical, so it is not a new handle (a point load "
        "only adds weight): the device was probably moved or tilted; calibrate it again");
  }
  if (result.disagreement_rel > options.max_disagreement_rel) {
    char text[64];
    std::snprintf(text, sizeof text, "%.1f %%", 100.0 * result.disagreement_rel);
    throw Error("retare: the change differs from vertex to vertex by " + std::string(text) +
                " of |G|, so it is not a new handle (a point load changes G the same everywhere): "
                "the device was probably moved or tilted; calibrate it again");
  }
  return result;
}

}  // namespace autograv
