#include "autograv/device/servo_loop_stats.h"

#include <algorithm>
#include <cmath>

namespace autograv {

namespace {
constexpr std::size_t kBins =
    static_cast<std::size_t>(ServoLoopStats::kRange_s / ServoLoopStats::kBin_s) + 1;

std::size_t binOf(double value_s) noexcept {
  if (!(value_s > 0.0)) return 0;
  const double bin = std::floor(value_s / ServoLoopStats::kBin_s);
  return bin >= static_cast<double>(kBins - 1) ? kBins - 1 : static_cast<std::size_t>(bin);
}

/// Upper edge of the bin holding the `fraction` quantile, in ms (capped at the exact maximum; 0
/// for the first bin, so that a loop on time reads 0).
double quantile_ms(const std::vector<std::uint32_t>& histogram, std::int64_t count, double fraction,
                   double max_s) noexcept {
  if (count == 0) return 0.0;
  const auto rank = static_cast<std::int64_t>(std::ceil(fraction * static_cast<double>(count)));
  std::int64_t seen = 0;
  for (std::size_t bin = 0; bin < histogram.size(); ++bin) {
    seen += histogram[bin];
    if (seen >= std::max<std::int64_t>(rank, 1)) {
      if (bin == 0) return 0.0;  // under one bin: on time
      return 1e3 * std::min(static_cast<double>(bin + 1) * ServoLoopStats::kBin_s, max_s);
    }
  }
  return 1e3 * max_s;
}
}  // namespace

ServoLoopStats::ServoLoopStats() : intervals_(kBins, 0), lateness_(kBins, 0) {}

void ServoLoopStats::record(double interval_s, double lateness_s) noexcept {
  if (!std::isfinite(interval_s) || !std::isfinite(lateness_s)) return;
  ++ticks_;
  duration_s_ += std::max(0.0, interval_s);
  ++intervals_[binOf(interval_s)];
  ++lateness_[binOf(lateness_s)];
  longest_gap_s_ = std::max(longest_gap_s_, interval_s);
  max_lateness_s_ = std::max(max_lateness_s_, lateness_s);
  if (interval_s > 0.010) ++gaps_over_10ms_;
}

void ServoLoopStats::clear() noexcept {
  std::fill(intervals_.begin(), intervals_.end(), 0);
  std::fill(lateness_.begin(), lateness_.end(), 0);
  ticks_ = 0;
  duration_s_ = 0.0;
  longest_gap_s_ = 0.0;
  max_lateness_s_ = 0.0;
  gaps_over_10ms_ = 0;
}

ServoLoopStats::Summary ServoLoopStats::summary() const noexcept {
  Summary summary;
  summary.ticks = ticks_;
  summary.duration_s = duration_s_;
  summary.rate_hz = duration_s_ > 0.0 ? static_cast<double>(ticks_) / duration_s_ : 0.0;
  summary.interval_p50_ms = quantile_ms(intervals_, ticks_, 0.5, longest_gap_s_);
  summary.interval_p99_ms = quantile_ms(intervals_, ticks_, 0.99, longest_gap_s_);
  summary.lateness_p50_ms = quantile_ms(lateness_, ticks_, 0.5, max_lateness_s_);
  summary.lateness_p99_ms = quantile_ms(lateness_, ticks_, 0.99, max_lateness_s_);
  summary.max_lateness_ms = 1e3 * max_lateness_s_;
  summary.longest_gap_ms = 1e3 * longest_gap_s_;
  summary.gaps_over_10ms = gaps_over_10ms_;
  return summary;
}

}  // namespace autograv
