#include "autograv/map/gravity_map.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "autograv/error.h"
#include "autograv/map/vertex_fill.h"
#include "core/map/trilinear.h"

namespace autograv {

GravityMap::GravityMap(WorkspaceGrid grid, std::vector<VertexEstimate> vertices,
                       MapMetadata metadata)
    : grid_(std::move(grid)),
      vertices_(std::move(vertices)),
      metadata_(std::move(metadata)),
      lookup_resolution_(grid_.resolution()),
      min_corner_m_(grid_.minCorner_m()),
      inverse_spacing_per_m_(grid_.spacing_m().cwiseInverse()),
      last_cell_((grid_.resolution().array() - 1).cast<double>()) {
  if (static_cast<int>(vertices_.size()) != grid_.vertexCount()) {
    std::ostringstream message;
    message << "gravity map: " << vertices_.size() << " vertex estimates for a grid of "
            << grid_.vertexCount() << " vertices (" << grid_.describe() << ")";
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
  const int refinement = metadata_.lookup_refinement;
  if (refinement < 1 || refinement > kMaxLookupRefinement) {
    throw Error("gravity map: MapMetadata::lookup_refinement must lie in 1.." +
                std::to_string(kMaxLookupRefinement) + ", got " + std::to_string(refinement));
  }
  if (refinement == 1) return;
  const Eigen::Vector3i fine =
      (grid_.resolution() - Eigen::Vector3i::Ones()) * refinement + Eigen::Vector3i::Ones();
  // The finer grid's values are one sparse solve: bounded so that a map file cannot ask for
  // minutes of it.
  if (fine.cast<long>().prod() > kMaxLookupVertices) {
    throw Error("gravity map: MapMetadata::lookup_refinement " + std::to_string(refinement) +
                " on a grid of " + grid_.describe() + " makes more than " +
                std::to_string(kMaxLookupVertices) +
                " lookup vertices; use a smaller refinement for so fine a grid");
  }
  const std::vector<Eigen::Vector3d> refined = refinedVertexValues(grid_, vertices_, refinement);
  lookup_resolution_ =
      (grid_.resolution() - Eigen::Vector3i::Ones()) * refinement + Eigen::Vector3i::Ones();
  inverse_spacing_per_m_ *= refinement;
  last_cell_ = (lookup_resolution_.array() - 1).cast<double>();
  packed_gravity_n_.clear();
  packed_gravity_n_.reserve(refined.size());
  for (const Eigen::Vector3d& gravity_n : refined) {
    packed_gravity_n_.emplace_back(gravity_n.x(), gravity_n.y(), gravity_n.z(), 0.0);
  }
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m) const noexcept {
  const Eigen::Vector3d cells = (position_m - min_corner_m_).cwiseProduct(inverse_spacing_per_m_);
  return detail::interpolateTrilinear(lookup_resolution_, cells, packed_gravity_n_.data());
}

Eigen::Vector3d GravityMap::gravityAt(const Eigen::Vector3d& position_m, double margin_m,
                                      bool& inside) const noexcept {
  const Eigen::Vector3d cells = (position_m - min_corner_m_).cwiseProduct(inverse_spacing_per_m_);
  const Eigen::Array3d margin_cells = margin_m * inverse_spacing_per_m_.array();
  inside = (cells.array() >= -margin_cells).all() &&
           (cells.array() <= last_cell_.array() + margin_cells).all();
  return detail::interpolateTrilinear(lookup_resolution_, cells, packed_gravity_n_.data());
}

int GravityMap::convergedCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  }));
}

bool GravityMap::isComplete() const noexcept {
  return std::all_of(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged ||
           (v.outcome == VertexOutcome::kUnreachable && v.provenance == VertexProvenance::kFilled);
  });
}

int GravityMap::unreachableCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kUnreachable;
  }));
}

int GravityMap::filledCount() const noexcept {
  return static_cast<int>(std::count_if(vertices_.begin(), vertices_.end(), [](const auto& v) {
    return v.provenance == VertexProvenance::kFilled;
  }));
}

}  // namespace autograv
