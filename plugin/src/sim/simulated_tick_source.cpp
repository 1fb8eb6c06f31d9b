#include <chrono>
#include <thread>

#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

namespace {
long long steadyNanoseconds() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}
}  // namespace

SimulatedTickSource::SimulatedTickSource(SimulatedDevice& device, double period_s, Mode mode,
                                         ServoTiming timing, std::uint64_t timing_seed)
    : device_(device),
      period_s_(period_s),
      mode_(mode),
      model_(timing, timing_seed, period_s > 0.0 && period_s <= 0.1 ? period_s : 1e-3),
      start_time_s_(device.time_s()) {
  if (!(period_s > 0.0 && period_s <= 0.1)) {
    throw Error("simulated tick source: period must be in (0, 0.1] s");
  }
  wall_start_ns_ = steadyNanoseconds();
}

bool SimulatedTickSource::waitForNextTick() {
  const double interval_s = model_.nextInterval_s();
  device_.advance(interval_s);
  stats_.record(interval_s, model_.lastLateness_s());
  if (mode_ == Mode::kRealTime) {
    // Sleep until the absolute time of the tick so that rounding errors do not accumulate.
    const auto deadline = std::chrono::steady_clock::time_point(
        std::chrono::nanoseconds(wall_start_ns_ + static_cast<long long>(model_.now_s() * 1e9)));
    std::this_thread::sleep_until(deadline);
  }
  return true;
}

double SimulatedTickSource::now_s() const { return device_.time_s() - start_time_s_; }

}  // namespace autograv::sim
