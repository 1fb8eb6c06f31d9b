#include "sweep_report.h"

#include <cmath>
#include <cstdio>

#include "autograv/error.h"
#include "servo_timing_option.h"

#ifdef AUTOGRAV_HAVE_VIZ
#include "autograv/viz/image.h"
#include "autograv/viz/plots.h"
#endif

namespace autograv::cli {

using sim::CalibrationFigures;
using sim::SweepRow;

nlohmann::json calibrationFiguresJson(const CalibrationFigures& f) {
  return {{"converged", f.converged},
          {"vertices", f.vertices},
          {"iterations_median", f.iterations_median},
          {"iterations_max", f.iterations_max},
          {"seconds_per_vertex", f.seconds_per_vertex},
          {"max_error_n", f.accuracy.max_error_n},
          {"max_error_rel", f.accuracy.max_error_rel}};
}

void printFrictionSweep(const std::vector<SweepRow>& rows, const sim::FrictionSweepOptions& sweep,
                        nlohmann::json& report) {
  const int seeds = sweep.seeds;
  std::printf(
      "\n%s: calibration on a %d^3 grid, then verify at %d points (seeds 1-%d)\n"
      "  error: |G_hat - G| against the simulation's ground truth, worst vertex and RMS over\n"
      "  the grid; residual: verify's measured residual force (median / max)%s\n",
      comparesMethods(sweep) ? "Methods, side by side" : "Friction sweep", sweep.grid, sweep.points,
      seeds,
      seeds > 1 ? ";\n  seeds folded: converged summed, medians of medians, worst of worsts" : "");
  std::printf("  %-10s %-8s %-6s %9s %11s %9s %18s %18s %15s\n", "device", "friction", "method",
              "converged", "iter med/max", "s/vertex", "worst [mN] [%]", "RMS [mN] [%]",
              "residual [mN]");
  nlohmann::json list = nlohmann::json::array();
  for (const SweepRow& row : rows) {
    if (!row.failure.empty()) {
      std::printf("  %-10s %-8s %-6s FAILED: %s\n", row.device.c_str(), sim::toString(row.friction),
                  toString(row.method), row.failure.c_str());
      list.push_back({{"device", row.device},
                      {"friction", sim::toString(row.friction)},
                      {"method", toString(row.method)},
                      {"failure", row.failure}});
      continue;
    }
    const CalibrationFigures& f = row.calibration;
    const sim::AccuracyReport& a = f.accuracy;
    std::printf(
        "  %-10s %-8s %-6s %5d/%-3d %6.1f/%-4d %9.2f %10.2f %6.2f%% %10.2f %6.2f%% %7.2f/%-7.2f\n",
        row.device.c_str(), sim::toString(row.friction), toString(row.method), f.converged,
        f.vertices, f.iterations_median, f.iterations_max, f.seconds_per_vertex,
        a.max_error_n * 1e3, 100.0 * a.max_error_rel, a.rms_residual_n * 1e3,
        100.0 * a.rms_residual_rel, row.residual_n.median * 1e3, row.residual_n.max * 1e3);
    nlohmann::json entry = calibrationFiguresJson(f);
    entry["device"] = row.device;
    entry["friction"] = sim::toString(row.friction);
    entry["method"] = toString(row.method);
    entry["rms_error_n"] = a.rms_residual_n;
    entry["rms_error_rel"] = a.rms_residual_rel;
    entry["residual_force_median_n"] = row.residual_n.median;
    entry["residual_force_max_n"] = row.residual_n.max;
    list.push_back(entry);
  }
  if (sweep.servo_timing != sim::ServoTiming::kExact && !rows.empty() &&
      rows.front().failure.empty()) {
    printServoLoop(sweep.servo_timing, rows.front().calibration.servo_loop);
  }
  report[comparesMethods(sweep) ? "methods" : "friction_sweep"] = {
      {"grid", sweep.grid},
      {"servo_timing", sim::toString(sweep.servo_timing)},
      {"verify_points", sweep.points},
      {"seeds", seeds},
      {"rows", list}};
}

void plotFrictionSweep(const std::vector<SweepRow>& rows, const sim::FrictionSweepOptions& sweep,
                       const std::string& path) {
#ifdef AUTOGRAV_HAVE_VIZ
  const std::vector<EstimationMethod>& methods = sweep.methods;
  const std::vector<std::string> levels = sim::frictionLevelNames();
  const auto panel = [&](const std::string& y_title, auto&& value) {
    viz::SweepPanel result{y_title, {}};
    const std::vector<std::string> devices = sim::simulatedDeviceNames();
    for (std::size_t d = 0; d < devices.size(); ++d) {
      const std::string& device = devices[d];
      for (const EstimationMethod method : methods) {
        const std::string name = methods.size() > 1 ? device + " " + toString(method) : device;
        // One colour per device; the paper's method dashed beside the dither method.
        viz::SweepSeries series{name, std::vector<double>(levels.size(), std::nan("")),
                                static_cast<int>(d),
                                methods.size() > 1 && method == EstimationMethod::kPaper};
        for (const SweepRow& row : rows) {
          if (row.device != device || row.method != method || !row.failure.empty()) continue;
          series.values[static_cast<std::size_t>(row.friction)] = value(row);
        }
        result.series.push_back(series);
      }
    }
    return result;
  };
  const std::vector<viz::SweepPanel> panels = {
      panel("iterations per vertex (median)",
            [](const SweepRow& row) { return row.calibration.iterations_median; }),
      panel("vertices converged [%]",
            [](const SweepRow& row) {
              return 100.0 * row.calibration.converged / row.calibration.vertices;
            }),
      panel("worst vertex |G_hat - G| [% of |G|]",
            [](const SweepRow& row) { return 100.0 * row.calibration.accuracy.max_error_rel; }),
      panel("verify residual force, median [mN]",
            [](const SweepRow& row) { return row.residual_n.median * 1e3; })};
  viz::PlotOptions plot;
  plot.title = comparesMethods(sweep) ? "Paper's method against the dither method"
                                      : "Friction sweep, simulated devices";
  viz::writePng(viz::renderSweepPlot(levels, "friction level", panels, plot), path);
  std::printf("\nwrote %s\n", path.c_str());
#else
  (void)rows;
  (void)sweep;
  throw Error("--plot " + path + ": autograv was built without AUTOGRAV_BUILD_VIZ=ON");
#endif
}

}  // namespace autograv::cli
