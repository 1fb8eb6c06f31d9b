#include "autograv/gravity_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "autograv/error.h"
#include "trilinear.h"

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
  const detail::TrilinearGrid grid(grid_);
  return detail::interpolateTrilinear(grid, grid.toCells(position_m),
                                      [this](int index) -> const Eigen::Vector3d& {
                                        return vertices_[static_cast<std::size_t>(index)].gravity_n;
                                      });
}

int GravityMap::convergedCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  }));
}

}  // namespace autograv
