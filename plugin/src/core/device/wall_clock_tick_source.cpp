#include "autograv/device/wall_clock_tick_source.h"

#include <thread>

#include "autograv/error.h"

namespace autograv {

WallClockTickSource::WallClockTickSource(double period_s)
    : period_s_(period_s),
      start_(std::chrono::steady_clock::now()),
      last_interval_s_(period_s),
      last_wake_(start_) {
  if (!(period_s > 0.0 && period_s <= 0.1)) {
    throw Error("wall-clock tick source: the servo period must be in (0, 0.1] s");
  }
}

bool WallClockTickSource::waitForNextTick() {
  ++ticks_;
  const auto deadline = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                     std::chrono::duration<double>(ticks_ * period_s_));
  std::this_thread::sleep_until(deadline);
  const auto wake = std::chrono::steady_clock::now();
  last_interval_s_ = std::chrono::duration<double>(wake - last_wake_).count();
  last_wake_ = wake;
  return true;
}

double WallClockTickSource::now_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

}  // namespace autograv
