#include "autograv/map/thermal_drift.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "autograv/error.h"

namespace autograv {

namespace {

bool measuredValue(const VertexEstimate& vertex) noexcept {
  return vertex.outcome == VertexOutcome::kConverged ||
         vertex.outcome == VertexOutcome::kIterationCap ||
         vertex.outcome == VertexOutcome::kLeftOut;
}

}  // namespace

std::vector<DriftReference> planThermalDriftCheck(const WorkspaceGrid& grid,
                                                  const std::vector<VertexEstimate>& vertices,
                                                  const std::vector<int>& exclude) {
  std::vector<DriftReference> references;
  if (static_cast<int>(vertices.size()) != grid.vertexCount()) return references;
  double highest_load = 0.0;
  std::vector<int> candidates;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
    highest_load = std::max(highest_load, vertex.thermal_load);
    // Load 0: restored from an earlier run (or a file), whose motors this run never saw.
    if (vertex.outcome != VertexOutcome::kConverged || !(vertex.thermal_load > 0.0)) continue;
    if (std::find(exclude.begin(), exclude.end(), i) != exclude.end()) continue;
    candidates.push_back(i);
  }
  if (highest_load < kMinDriftLoad) return references;
  std::stable_sort(candidates.begin(), candidates.end(), [&](int a, int b) {
    return vertices[static_cast<std::size_t>(a)].thermal_load <
           vertices[static_cast<std::size_t>(b)].thermal_load;
  });
  for (int index : candidates) {
    if (static_cast<int>(references.size()) == kThermalDriftPoints) break;
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(index)];
    // Only points measured while the motors were still much cooler than now tell the drift.
    if (vertex.thermal_load > 0.5 * highest_load) break;
    DriftReference reference;
    reference.vertex = index;
    reference.point_m = vertex.measuredAt_m(grid.vertexPosition(index));
    reference.first_value_n = vertex.measuredGravity_n();
    reference.first_load = vertex.thermal_load;
    references.push_back(reference);
  }
  return references;
}

ThermalDrift concludeThermalDrift(const WorkspaceGrid& grid, std::vector<VertexEstimate>& vertices,
                                  const std::vector<DriftReference>& references, double eps_g_n) {
  if (static_cast<int>(vertices.size()) != grid.vertexCount()) {
    throw Error("thermal drift: " + std::to_string(vertices.size()) +
                " vertex estimates for a grid of " + std::to_string(grid.vertexCount()));
  }
  ThermalDrift drift;
  // Each point: f1 (1 - k L1) = f2 (1 - k L2), f the command along the first reading, so
  // f2 - f1 = k (f2 L2 - f1 L1): a line through the origin, fitted by least squares.
  double sum_drift = 0.0;
  std::vector<double> a, b;
  for (const DriftReference& reference : references) {
    if (reference.vertex < 0 || reference.vertex >= grid.vertexCount()) continue;
    const VertexEstimate& vertex = vertices[static_cast<std::size_t>(reference.vertex)];
    const double f1 = reference.first_value_n.norm();
    if (vertex.outcome != VertexOutcome::kConverged || !(f1 > 0.0)) continue;
    const double f2 = vertex.measuredGravity_n().dot(reference.first_value_n) / f1;
    a.push_back(f2 - f1);
    b.push_back(f2 * vertex.thermal_load - f1 * reference.first_load);
    sum_drift += (f2 - f1) / f1;
    drift.first_load += reference.first_load;
    drift.again_load += vertex.thermal_load;
    ++drift.points;
  }
  if (drift.points == 0) return drift;
  drift.first_load /= drift.points;
  drift.again_load /= drift.points;
  drift.drift_rel = sum_drift / drift.points;
  double sum_ab = 0.0, sum_bb = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) {
    sum_ab += a[j] * b[j];
    sum_bb += b[j] * b[j];
  }
  if (!(sum_bb > 0.0)) return drift;
  const double k = sum_ab / sum_bb;
  // The scatter about the line, and at least two measurements' repeatability (eps_G each).
  double residual_n2 = 0.0;
  for (std::size_t j = 0; j < a.size(); ++j) residual_n2 += std::pow(a[j] - k * b[j], 2);
  const double scatter_n2 = a.size() > 1 ? residual_n2 / static_cast<double>(a.size() - 1) : 0.0;
  const double noise_n2 = std::max(scatter_n2, 2.0 * eps_g_n * eps_g_n);
  drift.gain_loss_standard_error = std::sqrt(noise_n2 / sum_bb);
  // Warming never raises a motor's torque per command: a negative fit is the measurements'
  // scatter, and no correction is the right one.
  drift.gain_loss_per_load = std::clamp(k, 0.0, kMaxGainLossPerLoad);
  for (VertexEstimate& vertex : vertices) {
    if (!measuredValue(vertex)) continue;
    const double gain =
        std::max(kMinThermalGain, 1.0 - drift.gain_loss_per_load * vertex.thermal_load);
    vertex.gravity_n *= gain;
    if (vertex.measuredOffVertex()) vertex.measured_gravity_n *= gain;
  }
  return drift;
}

}  // namespace autograv
