#pragma once

#include <cstdint>
#include <vector>

namespace autograv {

/// What a servo loop did: how often it ticked, how late, and its longest gap. The servo thread
/// records each tick's interval and lateness into histograms sized by the constructor, so that
/// recording allocates nothing; the summary reads percentiles from them (to kBin_s).
class ServoLoopStats {
 public:
  /// The loop's figures so far, for reports and warnings.
  struct Summary {
    std::int64_t ticks = 0;           ///< Ticks recorded.
    double duration_s = 0.0;          ///< Sum of the intervals. Unit: [s]
    double rate_hz = 0.0;             ///< ticks / duration_s. Unit: [Hz]
    double interval_p50_ms = 0.0;     ///< Unit: [ms]
    double interval_p99_ms = 0.0;     ///< Unit: [ms]
    double lateness_p50_ms = 0.0;     ///< Unit: [ms]
    double lateness_p99_ms = 0.0;     ///< Unit: [ms]
    double max_lateness_ms = 0.0;     ///< Unit: [ms]
    double longest_gap_ms = 0.0;      ///< Longest interval between two ticks. Unit: [ms]
    std::int64_t gaps_over_10ms = 0;  ///< Intervals longer than 10 ms (stalls).
  };

  /// Histogram bin width and range (longer intervals are counted in the last bin, and the
  /// longest is kept exactly). Unit: [s]
  static constexpr double kBin_s = 2e-6;
  static constexpr double kRange_s = 0.05;  ///< Unit: [s]

  /// Not real-time safe (allocates the histograms).
  ServoLoopStats();
  /// One tick that came `interval_s` after the previous one, `lateness_s` after it was due.
  /// Real-time safe. Units: [s]
  void record(double interval_s, double lateness_s) noexcept;
  /// Forgets every tick. Real-time safe.
  void clear() noexcept;
  /// Not real-time safe (walks the histograms).
  Summary summary() const noexcept;

 private:
  std::vector<std::uint32_t> intervals_;
  std::vector<std::uint32_t> lateness_;
  std::int64_t ticks_ = 0;
  double duration_s_ = 0.0;
  double longest_gap_s_ = 0.0;
  double max_lateness_s_ = 0.0;
  std::int64_t gaps_over_10ms_ = 0;
};

}  // namespace autograv
