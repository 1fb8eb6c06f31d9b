#include "autograv/sim/servo_timing_model.h"

#include <algorithm>
#include <cmath>

#include "autograv/error.h"

namespace autograv::sim {

namespace {
// A stream of its own: the timing does not share draws with the device's noise of the same seed.
constexpr std::uint64_t kTimingStream = 0x7f4a7c159e3779b9ULL;
// Free-running: the log-rate relaxes to the band's middle in kFreeTimeConstant_s and wanders over
// the band (standard deviation a quarter of it); each interval is jittered by +-kFreeJitter.
constexpr double kFreeTimeConstant_s = 2.0;
constexpr double kFreeJitter = 0.15;
}  // namespace

const char* toString(ServoTiming timing) noexcept {
  switch (timing) {
    case ServoTiming::kExact:
      return "exact";
    case ServoTiming::kDesktop:
      return "desktop";
    case ServoTiming::kRealTime:
      return "realtime";
    case ServoTiming::kFree:
      return "free";
  }
  return "unknown";
}

namespace {
// Every kind of loop, in the order the names are listed: one list for the names and the parser.
constexpr ServoTiming kTimings[] = {ServoTiming::kExact, ServoTiming::kDesktop,
                                    ServoTiming::kRealTime, ServoTiming::kFree};
}  // namespace

std::vector<std::string> servoTimingNames() {
  std::vector<std::string> names;
  for (const ServoTiming timing : kTimings) names.emplace_back(toString(timing));
  return names;
}

ServoTiming parseServoTiming(const std::string& name) {
  std::string valid;
  for (const ServoTiming timing : kTimings) {
    if (name == toString(timing)) return timing;
    valid += (valid.empty() ? "" : ", ") + std::string(toString(timing));
  }
  throw Error("unknown servo timing '" + name + "'; valid: " + valid);
}

ServoTimingModel::ServoTimingModel(ServoTiming timing, std::uint64_t seed, double nominal_period_s)
    : timing_(timing),
      nominal_period_s_(nominal_period_s),
      random_(seed ^ kTimingStream),
      last_interval_s_(nominal_period_s) {
  if (!(nominal_period_s > 0.0 && nominal_period_s <= 0.1)) {
    throw Error("servo timing: the nominal period must be in (0, 0.1] s");
  }
  next_stall_s_ = kStallSpacingMin_s + uniform() * (kStallSpacingMax_s - kStallSpacingMin_s);
  const double low = std::log(kFreeMinRate_hz);
  const double high = std::log(kFreeMaxRate_hz);
  log_rate_ = low + uniform() * (high - low);
}

double ServoTimingModel::uniform() noexcept {
  return static_cast<double>(random_() >> 11) * 0x1.0p-53;
}

double ServoTimingModel::nextInterval_s() noexcept {
  ++ticks_;
  double tick_s = 0.0;
  switch (timing_) {
    case ServoTiming::kExact:
      last_interval_s_ = nominal_period_s_;
      last_lateness_s_ = 0.0;
      now_s_ = static_cast<double>(ticks_) * nominal_period_s_;
      return last_interval_s_;
    case ServoTiming::kDesktop:
    case ServoTiming::kRealTime: {
      const bool real_time = timing_ == ServoTiming::kRealTime;
      const double deadline_s = static_cast<double>(ticks_) * nominal_period_s_;
      const double draw = uniform();
      double lateness_s = 0.0;
      if (deadline_s >= next_stall_s_) {
        lateness_s = kStall_s;
        next_stall_s_ += kStallSpacingMin_s + draw * (kStallSpacingMax_s - kStallSpacingMin_s);
      } else if (draw < (real_time ? kRealTimeRareLateFraction : kRareLateFraction)) {
        lateness_s = 3e-3 + 2e-3 * uniform();
      } else {
        lateness_s = (real_time ? kRealTimeLateness_s : kLateness_s) * uniform();
      }
      // Absolute deadlines: a tick after a late one is due at its own deadline, which may have
      // passed already (then it runs at once).
      tick_s = std::max(deadline_s + lateness_s, now_s_ + kMinInterval_s);
      last_lateness_s_ = tick_s - deadline_s;
      break;
    }
    case ServoTiming::kFree: {
      const double low = std::log(kFreeMinRate_hz);
      const double high = std::log(kFreeMaxRate_hz);
      const double middle = 0.5 * (low + high);
      const double period_s = std::exp(-log_rate_);
      // Ornstein-Uhlenbeck step (uniform noise of the right variance), reflected into the band.
      const double sigma = 0.25 * (high - low) * std::sqrt(2.0 / kFreeTimeConstant_s);
      log_rate_ += -(log_rate_ - middle) * period_s / kFreeTimeConstant_s +
                   sigma * std::sqrt(3.0 * period_s) * (2.0 * uniform() - 1.0);
      if (log_rate_ < low) log_rate_ = 2.0 * low - log_rate_;
      if (log_rate_ > high) log_rate_ = 2.0 * high - log_rate_;
      const double interval_s = period_s * (1.0 + kFreeJitter * (2.0 * uniform() - 1.0));
      tick_s = now_s_ + interval_s;
      last_lateness_s_ = std::max(0.0, interval_s - period_s);
      break;
    }
  }
  last_interval_s_ = tick_s - now_s_;
  now_s_ = tick_s;
  return last_interval_s_;
}

}  // namespace autograv::sim
