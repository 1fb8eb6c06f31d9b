#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>

namespace autograv::demo {

/// Deadline statistics of a servo loop paced on absolute deadlines (deadline k = start + k T).
/// A tick is "missed" when it starts more than one period late, i.e. after the next tick was
/// already due. A missed-deadline burst runs from the deadline of the first missed tick of a run
/// of missed ticks to the start of the first tick after it that was on time again: how long the
/// device went without being serviced on schedule. Plain arithmetic, no clock: the servo thread
/// feeds it the times it measured. Real-time safe.
class ServoTiming {
 public:
  struct Report {
    std::int64_t ticks = 0;
    double elapsed_s = 0.0;         ///< First deadline to the start of the last tick. [s]
    double rate_hz = 0.0;           ///< Ticks per second over elapsed_s. Unit: [Hz]
    std::int64_t missed_ticks = 0;  ///< Ticks that started more than one period late.
    double worst_burst_ms = 0.0;    ///< Longest missed-deadline burst. Unit: [ms]
    double max_lateness_ms = 0.0;   ///< Latest start after a deadline. Unit: [ms]
    double max_gap_ms = 0.0;        ///< Longest time between the starts of two ticks. [ms]
    double mean_lateness_ms = 0.0;  ///< Unit: [ms]
    double max_tick_ms = 0.0;       ///< Longest tick, start to end of its work. Unit: [ms]
  };

  explicit ServoTiming(std::int64_t period_ns) noexcept : period_ns_(period_ns) {}

  /// Tick k was due at `deadline_ns` and started at `start_ns` (same clock). Real-time safe.
  void record(std::int64_t deadline_ns, std::int64_t start_ns) noexcept;
  /// The work of the latest tick took `duration_ns`. Real-time safe.
  void recordWork(std::int64_t duration_ns) noexcept {
    max_work_ns_ = duration_ns > max_work_ns_ ? duration_ns : max_work_ns_;
  }
  /// Statistics so far; a burst still open counts up to the last tick. Real-time safe.
  Report report() const noexcept;

 private:
  std::int64_t period_ns_;
  std::int64_t ticks_ = 0;
  std::int64_t first_deadline_ns_ = 0;
  std::int64_t last_start_ns_ = 0;
  std::int64_t missed_ = 0;
  std::int64_t worst_burst_ns_ = 0;
  std::int64_t max_lateness_ns_ = 0;
  std::int64_t max_gap_ns_ = 0;
  std::int64_t max_work_ns_ = 0;
  double sum_lateness_ns_ = 0.0;
  bool in_burst_ = false;
  std::int64_t burst_start_ns_ = 0;
};

/// Runs `tick()` on absolute deadlines (start + k period, steady clock) until `stop` is set,
/// recording each tick's start and work in `timing`: a late tick does not push the ones after
/// it. Runs on the calling thread.
template <typename Tick>
void runPaced(std::int64_t period_ns, const std::atomic<bool>& stop, ServoTiming& timing,
              Tick&& tick) {
  using Clock = std::chrono::steady_clock;
  const auto nanoseconds = [](Clock::time_point time) {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(time.time_since_epoch()).count();
  };
  const auto period = std::chrono::nanoseconds(period_ns);
  const auto start = Clock::now() + period;
  for (std::int64_t k = 0; !stop.load(std::memory_order_relaxed); ++k) {
    const auto deadline = start + k * period;
    std::this_thread::sleep_until(deadline);
    const std::int64_t start_ns = nanoseconds(Clock::now());
    timing.record(nanoseconds(deadline), start_ns);
    tick();
    timing.recordWork(nanoseconds(Clock::now()) - start_ns);
  }
}

/// A thread paced like the servo loop and at its priority, with nothing to do: its misses are
/// what this machine imposes on any real-time thread (other load, a virtual machine's CPU
/// scheduling), the baseline against which the servo loop's figures are read. Started by the
/// constructor. Not real-time safe.
class ReferenceLoop {
 public:
  explicit ReferenceLoop(std::int64_t period_ns);
  ~ReferenceLoop();
  ReferenceLoop(const ReferenceLoop&) = delete;
  ReferenceLoop& operator=(const ReferenceLoop&) = delete;

  /// Stops the thread and returns its statistics.
  ServoTiming::Report stop();
  /// True when the thread got SCHED_FIFO (valid after stop()).
  bool realtimePriority() const noexcept { return realtime_; }

 private:
  ServoTiming timing_;
  std::atomic<bool> stop_{false};
  bool realtime_ = false;
  std::thread thread_;
};

}  // namespace autograv::demo
