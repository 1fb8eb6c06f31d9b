// What `autograv session` writes: its JSON report and its curves.
#include "session_report.h"

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
  std::vector<std::string> minutes;
  for (const sim::SessionSample& sample : runs.front().samples) {
    minutes.push_back(std::to_string(static_cast<int>(sample.minute + 0.5)));
  }
  const auto panel = [&](const std::string& title, auto&& value) {
    viz::SweepPanel result{title, {}};
    for (std::size_t r = 0; r < runs.size(); ++r) {
      viz::SweepSeries series{names[r], {}, static_cast<int>(r), r > 0};
      for (const sim::SessionSample& sample : runs[r].samples)
        series.values.push_back(value(sample));
      result.series.push_back(series);
    }
    return result;
  };
  viz::PlotOptions plot;
  plot.title = "A map in use: " + device + ", field error and motor temperature over the session";
  viz::writePng(
      viz::renderSweepPlot(
          minutes, "minute of the session",
          {panel("field p90 [% of |G|]", [](const auto& s) { return 100 * s.field.p90_rel; }),
           panel("field p99 [% of |G|]", [](const auto& s) { return 100 * s.field.p99_rel; }),
           panel("hottest winding [C]", [](const auto& s) { return s.hottest_winding_c; }),
           panel("lowest motor gain factor", [](const auto& s) { return s.lowest_gain_factor; })},
          plot),
      path);
  std::printf("\nwrote %s\n", path.c_str());
#else
  (void)runs, (void)names, (void)device;
  throw Error("--plot " + path + ": autograv was built without AUTOGRAV_BUILD_VIZ=ON");
#endif
}

}  // namespace autograv::cli
