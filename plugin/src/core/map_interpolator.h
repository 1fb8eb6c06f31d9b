#pragma once

// Private: the servo thread's view of a published gravity map. Built once on the publishing
// thread (it allocates), then read by the servo thread without allocating: the vertex estimates
// packed into one contiguous, aligned array, so that a lookup touches eight neighbouring values,
// runs on SIMD packets and inlines into the servo path.

#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/gravity_map.h"
#include "trilinear.h"

namespace autograv::detail {

class MapInterpolator {
 public:
  /// `margin_m`: how far outside the grid a position still counts as inside. Not real-time safe.
  MapInterpolator(std::shared_ptr<const GravityMap> map, double margin_m)
      : map_(std::move(map)),
        grid_(map_->grid()),
        margin_cells_(margin_m / map_->grid().spacing_m()),
        last_cell_(static_cast<double>(map_->grid().resolution() - 1)) {
    values_.reserve(map_->vertices().size());
    for (const VertexEstimate& vertex : map_->vertices()) {
      values_.emplace_back(vertex.gravity_n.x(), vertex.gravity_n.y(), vertex.gravity_n.z(), 0.0);
    }
  }

  /// GravityMap::gravityAt on the packed copy (a point outside is clamped to the boundary).
  /// `inside` tells whether `position_m` lies within the grid grown by the margin; it is false
  /// for a NaN coordinate. Real-time safe. Unit: [N]
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m, bool& inside) const noexcept {
    const Eigen::Vector3d cells = grid_.toCells(position_m);
    inside = (cells.array() >= -margin_cells_).all() &&
             (cells.array() <= last_cell_ + margin_cells_).all();
    return interpolateTrilinear(grid_, cells, [this](int index) -> const Eigen::Vector4d& {
      return values_[static_cast<std::size_t>(index)];
    });
  }

  /// The same without the inside test. Real-time safe. Unit: [N]
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m) const noexcept {
    bool inside = false;
    return gravityAt(position_m, inside);
  }

  /// True when `position_m` lies within the grid grown by the margin. Real-time safe.
  bool contains(const Eigen::Vector3d& position_m) const noexcept {
    bool inside = false;
    gravityAt(position_m, inside);
    return inside;
  }

  const std::shared_ptr<const GravityMap>& map() const noexcept { return map_; }

 private:
  std::shared_ptr<const GravityMap> map_;
  TrilinearGrid grid_;
  double margin_cells_;  ///< The outside margin in grid cells. Unit: [cells]
  double last_cell_;     ///< resolution - 1. Unit: [cells]
  /// Vertex estimates zero-padded to four components: aligned, so the lookup runs on whole SSE
  /// packets. Unit: [N]
  std::vector<Eigen::Vector4d> values_;
};

}  // namespace autograv::detail
