#pragma once

#include <cmath>

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

  /// Sets the motors' thermal load the maps are scaled for, each by its own drift
  /// (thermalScale). The scales are worked out again only when the load has moved by
  /// kThermalLoadStep or the maps changed: the load moves by about 1e-6 a tick, and a division
  /// per map every tick would cost more than the rest of the correction.
  void setThermalLoad(double load) noexcept {
    if (std::abs(load - scaled_load_) < kThermalLoadStep) return;
    scaled_load_ = load;
    current_scale_ = current_ ? thermalScale(current_->metadata().thermal_drift, load) : 1.0;
    previous_scale_ = previous_ ? thermalScale(previous_->metadata().thermal_drift, load) : 1.0;
  }
  /// The load change after which setThermalLoad works the scales out again: 1e-4 of load is at
  /// most 1e-5 of a map's value at the largest loss per load (kMaxGainLossPerLoad).
  static constexpr double kThermalLoadStep = 1e-4;
  /// The maps' gravity at `position_m`, blended during a fade (from or to no map as well), zero
  /// without a map, each map's scaled for the thermal load last set (setThermalLoad); `inside` is
  /// false when the position is farther than `margin_m` outside the grid of a map in use
  /// (GravityMap::gravityAt). Units: [m] in, [N] out.
  Eigen::Vector3d gravityAt(const Eigen::Vector3d& position_m, double margin_m,
                            bool& inside) const noexcept {
    inside = true;
    if (blend_ < 1.0) return blended(position_m, margin_m, inside);
    // The usual case inline: no fade in progress.
    if (current_ == nullptr) return Eigen::Vector3d::Zero();
    return current_scale_ * current_->gravityAt(position_m, margin_m, inside);
  }

 private:
  Eigen::Vector3d blended(const Eigen::Vector3d& position_m, double margin_m,
                          bool& inside) const noexcept;

  const GravityMap* current_ = nullptr;
  const GravityMap* previous_ = nullptr;
  double blend_ = 1.0;           ///< Weight of current_ against previous_ in a fade, in [0, 1].
  double scaled_load_ = -1.0;    ///< The load the scales are for (-1: to be worked out).
  double current_scale_ = 1.0;   ///< current_'s thermal scale at scaled_load_.
  double previous_scale_ = 1.0;  ///< previous_'s thermal scale at scaled_load_.
};

}  // namespace autograv
