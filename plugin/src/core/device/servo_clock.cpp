#include "autograv/device/servo_clock.h"

#include <chrono>
#include <cmath>
#include <string>

#include "autograv/error.h"

namespace autograv {

double SteadyServoClock::now_s() noexcept {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

FixedPeriodServoClock::FixedPeriodServoClock(double period_s) : period_s_(period_s) {
  if (!(std::isfinite(period_s) && period_s > 0.0)) {
    throw Error("FixedPeriodServoClock: the period must be a positive time in seconds, got " +
                std::to_string(period_s));
  }
}

double FixedPeriodServoClock::now_s() noexcept {
  // Multiplied, not summed: no drift from accumulated rounding over long runs.
  return static_cast<double>(ticks_++) * period_s_;
}

}  // namespace autograv
