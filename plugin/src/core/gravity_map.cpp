#include "autograv/gravity_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "autograv/error.h"

namespace autograv {

namespace {

struct OutcomeName {
  VertexOutcome outcome;
  const char* name;
};

constexpr std::array<OutcomeName, 6> kOutcomeNames{{
    {VertexOutcome::kPending, "pending"},
    {VertexOutcome::kConverged, "converged"},
    {VertexOutcome::kIterationCap, "iteration_cap"},
    {VertexOutcome::kNoSteadyState, "no_steady_state"},
    {VertexOutcome::kSaturated, "saturated"},
    {VertexOutcome::kDeviceFault, "device_fault"},
}};

}  // namespace

const char* toString(VertexOutcome outcome) noexcept {
  for (const auto& entry : kOutcomeNames) {
    if (entry.outcome == outcome) return entry.name;
  }
  return "unknown";
}

bool parseVertexOutcome(const std::string& name, VertexOutcome& outcome) noexcept {
  for (const auto& entry : kOutcomeNames) {
    if (name == entry.name) {
      outcome = entry.outcome;
      return true;
    }
  }
  return false;
}

GravityMap::GravityMap(WorkspaceGrid grid, std::vector<VertexEstimate> vertices,
                       MapMetadata metadata)
    : grid_(std::move(grid)), vertices_(std::move(vertices)), metadata_(std::move(metadata)) {
  if (static_cast<int>(vertices_.size()) != grid_.vertexCount()) {
    std::ostringstream message;
    message << "gravity map: " << vertices_.size() << " vertex estimates for a grid of "
            << grid_.vertexCount() << " vertices (" << grid_.resolution() << "^3)";
    throw Error(message.str());
  }
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    if (!vertices_[i].gravity_n.allFinite()) {
      std::ostringstream message;
      message << "gravity map: vertex " << i << " has a non-finite gravity estimate";
      throw Error(message.str());
    }
  }
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m) const noexcept {
  const int last = grid_.resolution() - 1;
  const Eigen::Vector3d scaled = (position_m - grid_.minCorner_m()) / grid_.spacing_m();
  std::array<int, 3> cell{};
  std::array<double, 3> fraction{};
  for (int axis = 0; axis < 3; ++axis) {
    // Clamp to the grid so that a point outside gets the boundary value (NaN goes to 0).
    const double clamped = std::isfinite(scaled[axis])
                               ? std::clamp(scaled[axis], 0.0, static_cast<double>(last))
                               : 0.0;
    cell[axis] = std::min(static_cast<int>(clamped), last - 1);
    fraction[axis] = clamped - cell[axis];
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1;
    const int dy = (corner >> 1) & 1;
    const int dz = (corner >> 2) & 1;
    const double weight = (dx ? fraction[0] : 1.0 - fraction[0]) *
                          (dy ? fraction[1] : 1.0 - fraction[1]) *
                          (dz ? fraction[2] : 1.0 - fraction[2]);
    const int index = grid_.vertexIndex(cell[0] + dx, cell[1] + dy, cell[2] + dz);
    sum += weight * vertices_[static_cast<std::size_t>(index)].gravity_n;
  }
  return sum;
}

int GravityMap::convergedCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  }));
}

}  // namespace autograv
