#pragma once

#include <algorithm>

namespace autograv {

// The one law of every fade of the decorator (compensation level, map blend): a weight in [0, 1]
// moves by dt_s / ramp_s per tick, and at once when ramp_s is 0. Real-time safe.

/// `weight` one tick further toward 1. Units: [s] for both durations.
inline double rampUp(double weight, double dt_s, double ramp_s) noexcept {
  return ramp_s > 0.0 ? std::min(1.0, weight + dt_s / ramp_s) : 1.0;
}

/// `weight` one tick further toward 0. Units: [s] for both durations.
inline double rampDown(double weight, double dt_s, double ramp_s) noexcept {
  return ramp_s > 0.0 ? std::max(0.0, weight - dt_s / ramp_s) : 0.0;
}

}  // namespace autograv
