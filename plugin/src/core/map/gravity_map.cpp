#include "autograv/map/gravity_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "autograv/error.h"
#include "map/trilinear.h"

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
    : grid_(std::move(grid)),
      vertices_(std::move(vertices)),
      metadata_(std::move(metadata)),
      min_corner_m_(grid_.minCorner_m()),
      inverse_spacing_per_m_(1.0 / grid_.spacing_m()),
      last_cell_(grid_.resolution() - 1) {
  if (static_cast<int>(vertices_.size()) != grid_.vertexCount()) {
    std::ostringstream message;
    message << "gravity map: " << vertices_.size() << " vertex estimates for a grid of "
            << grid_.vertexCount() << " vertices (" << grid_.resolution() << "^3)";
    throw Error(message.str());
  }
  packed_gravity_n_.reserve(vertices_.size());
  for (std::size_t i = 0; i < vertices_.size(); ++i) {
    const Eigen::Vector3d& gravity_n = vertices_[i].gravity_n;
    if (!gravity_n.allFinite()) {
      std::ostringstream message;
      message << "gravity map: vertex " << i << " has a non-finite gravity estimate";
      throw Error(message.str());
    }
    if (gravity_n.cwiseAbs().maxCoeff() > kMaxGravityEstimate_n) {
      std::ostringstream message;
      message << "gravity map: vertex " << i << " has a gravity estimate of [" << gravity_n.x()
              << ", " << gravity_n.y() << ", " << gravity_n.z() << "] N, beyond the "
              << kMaxGravityEstimate_n << " N that any device could need";
      throw Error(message.str());
    }
    packed_gravity_n_.emplace_back(gravity_n.x(), gravity_n.y(), gravity_n.z(), 0.0);
  }
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d cells = (position_m - min_corner_m_) * inverse_spacing_per_m_;
  return detail::interpolateTrilinear(grid_.resolution(), cells, packed_gravity_n_.data());
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m, double margin_m,
                                      bool& inside) const noexcept {
  const Eigen::Vector3d cells = (position_m - min_corner_m_) * inverse_spacing_per_m_;
  const double margin_cells = margin_m * inverse_spacing_per_m_;
  inside =
      (cells.array() >= -margin_cells).all() && (cells.array() <= last_cell_ + margin_cells).all();
  return detail::interpolateTrilinear(grid_.resolution(), cells, packed_gravity_n_.data());
}

int GravityMap::convergedCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  }));
}

}  // namespace autograv
