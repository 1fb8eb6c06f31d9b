#pragma once

#include <chrono>

#include "autograv/device/tick_source.h"

namespace autograv {

/// Paces a servo loop on a real device: each tick waits for the next multiple of the period on
/// the steady clock (absolute deadlines, so that late wake-ups do not accumulate).
class WallClockTickSource final : public TickSource {
 public:
  /// Throws autograv::Error for a period outside (0, 0.1] s. Not real-time safe. Unit: [s]
  explicit WallClockTickSource(double period_s);
  /// Sleeps until the next deadline; a late caller is not made later still. Real-time safe.
  bool waitForNextTick() override;
  double period_s() const override { return period_s_; }
  double now_s() const override;
  /// Measured on the steady clock between the two latest wake-ups. Unit: [s]
  double lastInterval_s() const override { return last_interval_s_; }

 private:
  double period_s_;
  std::chrono::steady_clock::time_point start_;
  long long ticks_ = 0;
  double last_interval_s_;
  std::chrono::steady_clock::time_point last_wake_;
};

}  // namespace autograv
