#include "core/compensation/servo_tick_timer.h"

#include <algorithm>

namespace autograv {

double ServoTickTimer::tick() noexcept {
  const double now_s = clock_->now_s();
  // The first tick has nothing to measure from; a clock going backwards (or NaN) counts as 0.
  double dt_s = has_last_time_ ? now_s - last_time_s_ : 0.0;
  last_time_s_ = now_s;
  has_last_time_ = true;
  if (!(dt_s >= 0.0)) dt_s = 0.0;
  return std::min(dt_s, max_interval_s_);
}

}  // namespace autograv
