// What `autograv session` writes: its JSON report and its curves.
#include "session_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "autograv/error.h"
#include "cli_support.h"

#ifdef AUTOGRAV_HAVE_VIZ
#include "autograv/viz/image.h"
#include "autograv/viz/plots.h"
#endif

namespace autograv::cli {

nlohmann::json sessionJson(const sim::SessionWorkloadResult& result,
                           const sim::SimulatedUnit& unit) {
  nlohmann::json samples = nlohmann::json::array();
  for (const sim::SessionSample& sample : result.samples) {
    nlohmann::json row = {
        {"minute", sample.minute},
        {"path_p90_rel", sample.path_p90_rel},
        {"thermal_scale", sample.thermal_scale},
        {"best_scale", sample.best_scale},
        {"rescaled_field_error_p90_rel", sample.rescaled_field.p90_rel},
        {"rescaled_field_error_p99_rel", sample.rescaled_field.p99_rel},
        {"thermal_load", sample.thermal_load},
        {"hottest_winding_c", sample.hottest_winding_c},
        {"hottest_housing_c", sample.hottest_housing_c},
        {"lowest_gain_factor", sample.lowest_gain_factor},
        {"highest_gain_factor", sample.highest_gain_factor},
        {"seconds_above_continuous_force", sample.seconds_above_continuous_force}};
    addFieldErrorJson(row, sample.field);
    samples.push_back(row);
  }
  return {{"thermal", unit.thermal.enabled},
          {"ambient_c", unit.thermal.ambient_c},
          {"motor_start_c", unit.thermal.start_c},
          {"session", unit.session},
          {"force_limit_ticks", result.force_limit_ticks},
          {"seconds_above_continuous_force", result.seconds_above_continuous_force},
          {"peak_force_n", result.peak_force_n},
          {"releases", result.releases},
          {"contacts", result.contacts},
          {"samples", samples}};
}

void plotSessions(const std::string& path, const std::vector<sim::SessionWorkloadResult>& runs,
                  const std::vector<std::string>& names, const std::string& device) {
#ifdef AUTOGRAV_HAVE_VIZ
  // At most 13 points along the session: sixty-one categorical labels would overlap.
  const std::size_t count = runs.front().samples.size();
  const std::size_t every = std::max<std::size_t>(1, (count + 10) / 12);
  std::vector<std::size_t> shown;
  std::vector<std::string> minutes;
  for (std::size_t i = 0; i < count; i += every) {
    shown.push_back(i);
    minutes.push_back(std::to_string(static_cast<int>(runs.front().samples[i].minute + 0.5)));
  }
  // One colour per session; dashed, the same session's map scaled by the one gain that fits it
  // best (what a correction of the motors' common gain, known exactly, would leave).
  const auto panel = [&](const std::string& title, auto&& value, auto&& rescaled) {
    viz::SweepPanel result{title, {}};
    for (std::size_t r = 0; r < runs.size(); ++r) {
      viz::SweepSeries series{names[r], {}, static_cast<int>(r), false};
      viz::SweepSeries corrected{names[r] + ", one gain fitted", {}, static_cast<int>(r), true};
      for (const std::size_t i : shown) {
        const sim::SessionSample& sample = runs[r].samples[std::min(i, runs[r].samples.size() - 1)];
        series.values.push_back(value(sample));
        corrected.values.push_back(rescaled(sample));
      }
      result.series.push_back(series);
      if (!std::isnan(corrected.values.back())) result.series.push_back(corrected);
    }
    return result;
  };
  const auto none = [](const sim::SessionSample&) { return std::nan(""); };
  viz::PlotOptions plot;
  plot.title = "A map in use: " + device + ", field error and motors over the session";
  viz::writePng(
      viz::renderSweepPlot(
          minutes, "minute of the session",
          {panel(
               "field p90 [% of |G|]", [](const auto& s) { return 100 * s.field.p90_rel; },
               [](const auto& s) { return 100 * s.rescaled_field.p90_rel; }),
           panel(
               "field p99 [% of |G|]", [](const auto& s) { return 100 * s.field.p99_rel; },
               [](const auto& s) { return 100 * s.rescaled_field.p99_rel; }),
           panel(
               "hottest winding [C]", [](const auto& s) { return s.hottest_winding_c; }, none),
           panel(
               "thermal load the decorator reports", [](const auto& s) { return s.thermal_load; },
               none)},
          plot),
      path);
  std::printf("\nwrote %s\n", path.c_str());
#else
  (void)runs, (void)names, (void)device;
  throw Error("--plot " + path + ": autograv was built without AUTOGRAV_BUILD_VIZ=ON");
#endif
}

}  // namespace autograv::cli
