#include "servo_timing.h"

#include <algorithm>

#include "autograv/device/real_time_priority.h"

namespace autograv::demo {

void ServoTiming::record(std::int64_t deadline_ns, std::int64_t start_ns) noexcept {
  const std::int64_t lateness_ns = std::max<std::int64_t>(0, start_ns - deadline_ns);
  if (ticks_ == 0) {
    first_deadline_ns_ = deadline_ns;
  } else {
    max_gap_ns_ = std::max(max_gap_ns_, start_ns - last_start_ns_);
  }
  ++ticks_;
  last_start_ns_ = start_ns;
  sum_lateness_ns_ += static_cast<double>(lateness_ns);
  max_lateness_ns_ = std::max(max_lateness_ns_, lateness_ns);
  if (lateness_ns > period_ns_) {
    ++missed_;
    if (!in_burst_) {
      in_burst_ = true;
      burst_start_ns_ = deadline_ns;
    }
  } else if (in_burst_) {
    in_burst_ = false;
    worst_burst_ns_ = std::max(worst_burst_ns_, start_ns - burst_start_ns_);
  }
}

ServoTiming::Report ServoTiming::report() const noexcept {
  Report report;
  report.ticks = ticks_;
  if (ticks_ == 0) return report;
  const std::int64_t elapsed_ns = std::max<std::int64_t>(last_start_ns_ - first_deadline_ns_, 1);
  report.elapsed_s = static_cast<double>(elapsed_ns) * 1e-9;
  // Ticks after the first one per elapsed second: 1000 ticks paced at 1 ms span 0.999 s.
  report.rate_hz = ticks_ > 1 ? static_cast<double>(ticks_ - 1) / report.elapsed_s : 0.0;
  report.missed_ticks = missed_;
  std::int64_t worst_ns = worst_burst_ns_;
  if (in_burst_) worst_ns = std::max(worst_ns, last_start_ns_ - burst_start_ns_);
  report.worst_burst_ms = static_cast<double>(worst_ns) * 1e-6;
  report.max_lateness_ms = static_cast<double>(max_lateness_ns_) * 1e-6;
  report.max_gap_ms = static_cast<double>(max_gap_ns_) * 1e-6;
  report.max_tick_ms = static_cast<double>(max_work_ns_) * 1e-6;
  report.mean_lateness_ms = sum_lateness_ns_ / static_cast<double>(ticks_) * 1e-6;
  return report;
}

ReferenceLoop::ReferenceLoop(std::int64_t period_ns) : timing_(period_ns) {
  thread_ = std::thread([this, period_ns] {
    realtime_ = enterRealTimePriority(/*lock_memory=*/true).granted;
    runPaced(period_ns, stop_, timing_, [] {});
  });
}

ReferenceLoop::~ReferenceLoop() { stop(); }

ServoTiming::Report ReferenceLoop::stop() {
  if (thread_.joinable()) {
    stop_.store(true);
    thread_.join();
  }
  return timing_.report();
}

}  // namespace autograv::demo
