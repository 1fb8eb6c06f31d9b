#pragma once

#include <Eigen/Core>

#include "autograv/map/gravity_map.h"
#include "core/compensation/map_handoff.h"

namespace autograv {

/// The maps the servo thread compensates with, and the fade from one to the next. Internal to
/// core; the servo thread's only. Real-time safe throughout.
///
/// A new map is taken only between fades, so at most two maps are ever in use. The first map
/// fades in from none, and a null map fades the last one out, like any other swap. Once a fade
/// is over, the hand-off is told the older maps are no longer read.
class MapFade {
 public:
  /// True while a fade is in progress.
  bool fading() const noexcept { return blend_ < 1.0; }
  /// True when a map is in use (fading in, or the only one).
  bool hasMap() const noexcept { return current_ != nullptr; }

  /// Whether advance() has anything to do this tick: a new publication or a fade in progress.
  bool needsAdvance(const MapHandoff& handoff) const noexcept {
    return blend_ < 1.0 || handoff.hasNewPublication();
  }
  /// Takes a new publication from `handoff` when no fade is in progress, then moves the fade on
  /// by one tick of `dt_s` over a fade of `ramp_s`. Units: [s]
  void advance(MapHandoff& handoff, double dt_s, double ramp_s) noexcept;

  /// The maps' gravity at `position_m`, blended during a fade (from or to no map as well), zero
  /// without a map, each map's scaled for the motors' thermal load `load` by its own drift
  /// (thermalScale); `inside` is false when the position is farther than `margin_m` outside the
  /// grid of a map in use (GravityMap::gravityAt). Units: [m] in, [N] out.
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m, double margin_m, double load,
                            bool& inside) const noexcept {
    inside = true;
    if (blend_ < 1.0) return blended(position_m, margin_m, load, inside);
    // The usual case inline: no fade in progress.
    if (current_ == nullptr) return Eigen::Vector3d::Zero();
    return thermalScale(current_->metadata().thermal_drift, load) *
           current_->gravityAt(position_m, margin_m, inside);
  }

 private:
  Eigen::Vector3d blended(const Eigen::Vector3d& position_m, double margin_m, double load,
                          bool& inside) const noexcept;

  const GravityMap* current_ = nullptr;
  const GravityMap* previous_ = nullptr;
  double blend_ = 1.0;  ///< Weight of current_ against previous_ in a fade, in [0, 1].
};

}  // namespace autograv
