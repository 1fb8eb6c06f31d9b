#pragma once

#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/device/servo_loop_stats.h"
#include "autograv/sim/servo_timing_model.h"
#include "choice_option.h"

namespace autograv::cli {

/// Adds --servo-timing exact|desktop|realtime|free to `command`: how the simulated servo loop's
/// ticks arrive, written into `timing` (exact, today's figures, when the option is not given).
/// AdvancedOptions declares it once for the commands that take it.
inline CLI::Option* addServoTimingOption(CLI::App& command, sim::ServoTiming& timing) {
  return addChoiceOption(
      command, "--servo-timing", timing, sim::parseServoTiming, sim::servoTimingNames(),
      "How the simulated servo ticks arrive: exact (1 kHz, the published figures), desktop "
      "(1 kHz, late by 0-1 ms, 1 % by 3-5 ms, a 20 ms stall every 10-30 s), realtime (the same "
      "thread at SCHED_FIFO: late by 0-0.2 ms, 0.1 % by 3-5 ms, the same stalls) or free "
      "(free-running at 2-8 kHz)");
}

/// What the servo loop did, for a JSON report (rate, lateness percentiles, longest gap).
inline nlohmann::json servoLoopJson(sim::ServoTiming timing, const ServoLoopStats::Summary& loop) {
  return {{"servo_timing", sim::toString(timing)},
          {"ticks", loop.ticks},
          {"rate_hz", loop.rate_hz},
          {"interval_p50_ms", loop.interval_p50_ms},
          {"interval_p99_ms", loop.interval_p99_ms},
          {"lateness_p50_ms", loop.lateness_p50_ms},
          {"lateness_p99_ms", loop.lateness_p99_ms},
          {"max_lateness_ms", loop.max_lateness_ms},
          {"longest_gap_ms", loop.longest_gap_ms},
          {"gaps_over_10ms", loop.gaps_over_10ms}};
}

/// One line for a command's summary: "servo loop  desktop: 1000 Hz, late p50 0.50 / p99 3.9 ms,
/// longest gap 21 ms".
inline void printServoLoop(sim::ServoTiming timing, const ServoLoopStats::Summary& loop) {
  std::printf("%-34s %s: %.0f Hz, late p50 %.2f ms / p99 %.2f ms, longest gap %.1f ms\n",
              "servo loop", sim::toString(timing), loop.rate_hz, loop.lateness_p50_ms,
              loop.lateness_p99_ms, loop.longest_gap_ms);
}

}  // namespace autograv::cli
