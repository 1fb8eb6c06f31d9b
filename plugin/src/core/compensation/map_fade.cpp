#include "core/compensation/map_fade.h"

#include "core/compensation/ramp.h"

namespace autograv {

void MapFade::advance(MapHandoff& handoff, double dt_s, double ramp_s) noexcept {
  const GravityMap* map = nullptr;
  if (blend_ >= 1.0 && handoff.take(map) && map != current_) {
    previous_ = current_;
    current_ = map;
    blend_ = 0.0;
    previous_scale_ = current_scale_;
    scaled_load_ = -1.0;  // the new map's scale at the next setThermalLoad
    current_scale_ = 1.0;
  }
  if (blend_ < 1.0) blend_ = rampUp(blend_, dt_s, ramp_s);
  if (blend_ >= 1.0) {
    previous_ = nullptr;
    handoff.acknowledgeTaken();
  }
}

Eigen::Vector3d MapFade::blended(const Eigen::Vector3d& position_m, double margin_m,
                                 bool& inside) const noexcept {
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();
  if (previous_ != nullptr) {
    gravity_n =
        (1.0 - blend_) * previous_scale_ * previous_->gravityAt(position_m, margin_m, inside);
  }
  if (current_ != nullptr) {
    bool inside_current = true;
    gravity_n +=
        blend_ * current_scale_ * current_->gravityAt(position_m, margin_m, inside_current);
    inside = inside && inside_current;
  }
  return gravity_n;
}

}  // namespace autograv
