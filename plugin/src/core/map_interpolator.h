#pragma once

// Private: the servo thread's view of a published gravity map. Built once on the publishing
// thread (it allocates), then read by the servo thread without allocating: the vertex estimates
// packed into one contiguous array and the grid reduced to the few numbers the lookup needs, so
// that a lookup costs a few nanoseconds and inlines into the servo path.

#include <algorithm>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "autograv/gravity_map.h"

namespace autograv::detail {

class MapInterpolator {
 public:
  /// `margin_m`: how far outside the grid contains() still answers true. Not real-time safe.
  MapInterpolator(std::shared_ptr<const GravityMap> map, double margin_m)
      : map_(std::move(map)),
        min_corner_m_(map_->grid().minCorner_m()),
        low_m_(min_corner_m_ - Eigen::Vector3d::Constant(margin_m)),
        high_m_(map_->grid().maxCorner_m() + Eigen::Vector3d::Constant(margin_m)),
        inverse_spacing_per_m_(1.0 / map_->grid().spacing_m()),
        resolution_(map_->grid().resolution()) {
    values_.reserve(map_->vertices().size());
    for (const VertexEstimate& vertex : map_->vertices()) values_.push_back(vertex.gravity_n);
  }

  /// The same trilinear interpolation as GravityMap::gravityAt (a point outside is clamped to
  /// the boundary first) for a FINITE position. Real-time safe. Unit: [N]
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m) const noexcept {
    const int last = resolution_ - 1;
    int cell[3];
    double t[3];
    for (int axis = 0; axis < 3; ++axis) {
      const double scaled =
          std::clamp((position_m[axis] - min_corner_m_[axis]) * inverse_spacing_per_m_, 0.0,
                     static_cast<double>(last));
      cell[axis] = std::min(static_cast<int>(scaled), last - 1);
      t[axis] = scaled - cell[axis];
    }
    const int n = resolution_;
    const Eigen::Vector3d* v = values_.data() + cell[0] + n * (cell[1] + n * cell[2]);
    const int dy = n;
    const int dz = n * n;
    const Eigen::Vector3d x00 = v[0] + t[0] * (v[1] - v[0]);
    const Eigen::Vector3d x10 = v[dy] + t[0] * (v[dy + 1] - v[dy]);
    const Eigen::Vector3d x01 = v[dz] + t[0] * (v[dz + 1] - v[dz]);
    const Eigen::Vector3d x11 = v[dz + dy] + t[0] * (v[dz + dy + 1] - v[dz + dy]);
    const Eigen::Vector3d y0 = x00 + t[1] * (x10 - x00);
    const Eigen::Vector3d y1 = x01 + t[1] * (x11 - x01);
    return y0 + t[2] * (y1 - y0);
  }

  /// True when `position_m` is inside the grid grown by the margin. Real-time safe.
  bool contains(const Eigen::Vector3d& position_m) const noexcept {
    return (position_m.array() >= low_m_.array()).all() &&
           (position_m.array() <= high_m_.array()).all();
  }

  const std::shared_ptr<const GravityMap>& map() const noexcept { return map_; }

 private:
  std::shared_ptr<const GravityMap> map_;
  Eigen::Vector3d min_corner_m_;
  Eigen::Vector3d low_m_;
  Eigen::Vector3d high_m_;
  double inverse_spacing_per_m_;
  int resolution_;
  std::vector<Eigen::Vector3d> values_;
};

}  // namespace autograv::detail
