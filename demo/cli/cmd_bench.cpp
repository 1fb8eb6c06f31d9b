// autograv bench: speed and iteration figures measured side by side in one run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autograv/error.h"
#include "autograv/device/gravity_compensated_device.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/sim/friction.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/verification.h"
#include "cli_support.h"
#include "commands.h"
#include "friction_option.h"

#ifdef AUTOGRAV_HAVE_VIZ
#include "autograv/viz/image.h"
#include "autograv/viz/plots.h"
#endif

namespace autograv::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct BenchOptions {
  std::string report_path;
  int grid = 5;
  bool quick = false;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  bool friction_sweep = false;
  int sweep_grid = 4;
  int sweep_points = 12;
  std::string plot_path;
};

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Simulated seconds per wall second with zero commanded force (10 kHz inside, 1 kHz servo).
double realTimeFactor(const std::string& name, double simulated_s) {
  auto device = openSimulatedDevice(name, 1);
  device->resetState(device->workspaceCenter_m());
  device->hand().grab(device->workspaceCenter_m());  // keep it off the end stops
  const auto start = Clock::now();
  for (double t = 0.0; t < simulated_s; t += 1e-3) {
    device->setForce(Eigen::Vector3d::Zero());
    device->advance(1e-3);
  }
  return simulated_s / secondsSince(start);
}

// Wall time of one servo tick (read position, send force), raw device against the decorator,
// interleaved in rounds so both see the same machine load.
struct DecoratorCost {
  double raw_ns = 0.0;
  double decorated_ns = 0.0;
};

DecoratorCost decoratorCost(const std::string& name, const GravityMap& map, int ticks) {
  std::shared_ptr<sim::SimulatedDevice> raw = openSimulatedDevice(name, 1);
  std::shared_ptr<sim::SimulatedDevice> inner = openSimulatedDevice(name, 1);
  GravityCompensatedDevice decorated(inner);
  decorated.open();
  decorated.publishMap(std::make_shared<const GravityMap>(map));
  const Eigen::Vector3d force(0.1, 0.0, 0.0);
  Eigen::Vector3d position;
  double raw_s = 0.0, decorated_s = 0.0;
  const int rounds = 10;
  for (int round = 0; round < rounds; ++round) {
    auto start = Clock::now();
    for (int k = 0; k < ticks / rounds; ++k) {
      raw->getPosition(position);
      raw->setForce(force);
    }
    raw_s += secondsSince(start);
    start = Clock::now();
    for (int k = 0; k < ticks / rounds; ++k) {
      decorated.getPosition(position);
      decorated.setForce(force);
    }
    decorated_s += secondsSince(start);
  }
  return {raw_s / ticks * 1e9, decorated_s / ticks * 1e9};
}

struct CalibrationFigures {
  double iterations_median = 0.0;
  int iterations_max = 0;
  double seconds_per_vertex = 0.0;
  double simulated_s = 0.0;
  double wall_s = 0.0;
  int converged = 0;
  int vertices = 0;
  sim::AccuracyReport accuracy;
};

CalibrationFigures calibrationFigures(sim::SimulatedDevice& device, int resolution,
                                      bool extrapolate, GravityMap* map_out) {
  const double side_m = defaultGridSide_m(device.specifications().workspace_radius_m);
  sim::CalibrationRunOptions options;
  options.grid_center_m = device.workspaceCenter_m();
  options.grid_side_m = side_m;
  options.grid_resolution = resolution;
  options.calibrator.extrapolate_initial_estimate = extrapolate;
  options.parameters.k0_n_per_m = defaultInitializationStiffness(device.specifications());
  const auto start = Clock::now();
  const sim::CalibrationRunResult result = sim::runSimulatedCalibration(device, options);
  CalibrationFigures figures;
  figures.wall_s = secondsSince(start);
  figures.simulated_s = result.simulated_seconds;
  std::vector<double> iterations;
  for (const auto& vertex : result.vertices) {
    iterations.push_back(vertex.iterations);
    figures.seconds_per_vertex += vertex.seconds;
    figures.converged += vertex.outcome == VertexOutcome::kConverged;
  }
  figures.vertices = static_cast<int>(iterations.size());
  figures.seconds_per_vertex /= figures.vertices;
  const sim::Percentiles spread = sim::percentiles(iterations);
  figures.iterations_median = spread.median;
  figures.iterations_max = static_cast<int>(spread.max);
  const GravityMap map(WorkspaceGrid(options.grid_center_m, side_m, resolution), result.vertices,
                       MapMetadata{device.specifications().model_name, "", "", {}});
  figures.accuracy = sim::measureAccuracy(map, device, 1000);
  if (map_out != nullptr) *map_out = map;
  return figures;
}

/// One row of the friction sweep: calibration and verify on one device at one friction level.
struct SweepRow {
  std::string device;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  CalibrationFigures calibration;
  sim::Percentiles residual_n;
  std::string failure;  ///< Why the calibration or verify could not run; empty when they did.
};

std::vector<SweepRow> runFrictionSweep(const BenchOptions& options) {
  const std::vector<std::string> devices = sim::simulatedDeviceNames();
  const std::vector<std::string> levels = sim::frictionLevelNames();
  std::vector<SweepRow> rows;
  ProgressBar progress("friction sweep");
  const int total = static_cast<int>(devices.size() * levels.size());
  for (const std::string& name : devices) {
    for (const std::string& level : levels) {
      progress.update(static_cast<int>(rows.size()), total, name + " " + level);
      SweepRow row;
      row.device = name;
      row.friction = sim::parseFrictionLevel(level);
      std::shared_ptr<sim::SimulatedDevice> device = openSimulatedDevice(name, 1, row.friction);
      auto map = std::make_shared<GravityMap>(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2),
                                              std::vector<VertexEstimate>(8), MapMetadata{});
      try {
        row.calibration = calibrationFigures(*device, options.sweep_grid, true, map.get());
        sim::VerificationOptions verification;
        verification.points = options.sweep_points;
        verification.compare_uncompensated = false;
        row.residual_n =
            sim::verifyMapOnSimulatedDevice(device, std::move(map), verification).residual_force_n;
      } catch (const Error& error) {
        row.failure = error.what();  // a level the calibration cannot handle is a result too
      }
      rows.push_back(row);
    }
  }
  progress.update(total, total, "done");
  progress.finish();
  return rows;
}

void printFrictionSweep(const std::vector<SweepRow>& rows, const BenchOptions& options,
                        nlohmann::json& report) {
  std::printf(
      "\nFriction sweep: calibration on a %d^3 grid, then verify at %d points (seed 1)\n"
      "  error: |G_hat - G| against the simulation's ground truth, worst vertex and RMS over\n"
      "  the grid; residual: verify's measured residual force (median / max)\n",
      options.sweep_grid, options.sweep_points);
  std::printf("  %-10s %-8s %9s %11s %9s %18s %18s %15s\n", "device", "friction", "converged",
              "iter med/max", "s/vertex", "worst [mN] [%]", "RMS [mN] [%]", "residual [mN]");
  nlohmann::json list = nlohmann::json::array();
  for (const SweepRow& row : rows) {
    if (!row.failure.empty()) {
      std::printf("  %-10s %-8s FAILED: %s\n", row.device.c_str(), sim::toString(row.friction),
                  row.failure.c_str());
      list.push_back({{"device", row.device},
                      {"friction", sim::toString(row.friction)},
                      {"failure", row.failure}});
      continue;
    }
    const CalibrationFigures& f = row.calibration;
    const sim::AccuracyReport& a = f.accuracy;
    std::printf(
        "  %-10s %-8s %5d/%-3d %6.1f/%-4d %9.2f %10.2f %6.2f%% %10.2f %6.2f%% %7.2f/%-7.2f\n",
        row.device.c_str(), sim::toString(row.friction), f.converged, f.vertices,
        f.iterations_median, f.iterations_max, f.seconds_per_vertex, a.max_error_n * 1e3,
        100.0 * a.max_error_rel, a.rms_residual_n * 1e3, 100.0 * a.rms_residual_rel,
        row.residual_n.median * 1e3, row.residual_n.max * 1e3);
    list.push_back({{"device", row.device},
                    {"friction", sim::toString(row.friction)},
                    {"converged", f.converged},
                    {"vertices", f.vertices},
                    {"iterations_median", f.iterations_median},
                    {"iterations_max", f.iterations_max},
                    {"seconds_per_vertex", f.seconds_per_vertex},
                    {"max_error_n", a.max_error_n},
                    {"max_error_rel", a.max_error_rel},
                    {"rms_error_n", a.rms_residual_n},
                    {"rms_error_rel", a.rms_residual_rel},
                    {"residual_force_median_n", row.residual_n.median},
                    {"residual_force_max_n", row.residual_n.max}});
  }
  report["friction_sweep"] = {
      {"grid", options.sweep_grid}, {"verify_points", options.sweep_points}, {"rows", list}};
}

/// The sweep as four panels over the friction levels, one line per device.
void plotFrictionSweep(const std::vector<SweepRow>& rows, const std::string& path) {
#ifdef AUTOGRAV_HAVE_VIZ
  const std::vector<std::string> levels = sim::frictionLevelNames();
  const auto panel = [&](const std::string& y_title, auto&& value) {
    viz::SweepPanel result{y_title, {}};
    for (const std::string& device : sim::simulatedDeviceNames()) {
      viz::SweepSeries series{device, std::vector<double>(levels.size(), std::nan(""))};
      for (const SweepRow& row : rows) {
        if (row.device != device || !row.failure.empty()) continue;
        series.values[static_cast<std::size_t>(row.friction)] = value(row);
      }
      result.series.push_back(series);
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
  plot.title = "Friction sweep, simulated devices";
  viz::writePng(viz::renderSweepPlot(levels, "friction level", panels, plot), path);
  std::printf("\nwrote %s\n", path.c_str());
#else
  (void)rows;
  throw Error("--plot " + path + ": autograv was built without AUTOGRAV_BUILD_VIZ=ON");
#endif
}

void runBenchCommand(const BenchOptions& options) {
  nlohmann::json report;
  if (options.friction_sweep) {
    const std::vector<SweepRow> rows = runFrictionSweep(options);
    printFrictionSweep(rows, options, report);
    if (!options.plot_path.empty()) plotFrictionSweep(rows, options.plot_path);
    writeJsonReport(options.report_path, report);
    return;
  }
  const double simulated_s = options.quick ? 2.0 : 10.0;
  std::printf("Simulators (10 kHz inside, 1 kHz servo), %g simulated s each; target >= 1000x\n",
              simulated_s);
  for (const std::string& name : sim::simulatedDeviceNames()) {
    const double factor = realTimeFactor(name, simulated_s);
    std::printf("  %-10s %10.0fx real time\n", name.c_str(), factor);
    report["simulator"][name]["realtime_factor"] = factor;
  }

  std::printf(
      "\nCalibration, %d^3 grid, default side, seed 1, friction %s (paper: 14 iterations at one "
      "vertex)\n",
      options.grid, sim::toString(options.friction));
  report["friction"] = sim::toString(options.friction);
  std::printf("  %-10s %-12s %6s %6s %10s %10s %9s %8s\n", "device", "start", "median", "max",
              "s/vertex", "sim [s]", "wall [s]", "worst");
  std::unique_ptr<GravityMap> omni_map;
  for (const std::string& name : sim::simulatedDeviceNames()) {
    for (bool extrapolate : {false, true}) {
      GravityMap map(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2), std::vector<VertexEstimate>(8),
                     MapMetadata{});
      auto device = openSimulatedDevice(name, 1, options.friction);
      const CalibrationFigures f = calibrationFigures(*device, options.grid, extrapolate, &map);
      const char* start = extrapolate ? "extrapolate" : "eq. (9)";
      std::printf("  %-10s %-12s %6.1f %6d %10.2f %10.1f %9.2f %7.2f%%\n", name.c_str(), start,
                  f.iterations_median, f.iterations_max, f.seconds_per_vertex, f.simulated_s,
                  f.wall_s, 100.0 * f.accuracy.max_error_rel);
      report["calibration"][name][extrapolate ? "extrapolate" : "copy"] = {
          {"iterations_median", f.iterations_median},
          {"iterations_max", f.iterations_max},
          {"seconds_per_vertex", f.seconds_per_vertex},
          {"simulated_seconds", f.simulated_s},
          {"wall_seconds", f.wall_s},
          {"converged", f.converged},
          {"vertices", f.vertices},
          {"max_error_rel", f.accuracy.max_error_rel},
          {"max_error_n", f.accuracy.max_error_n}};
      if (extrapolate && name == "sim:omni") omni_map = std::make_unique<GravityMap>(map);
    }
  }

  if (omni_map) {
    const int ticks = options.quick ? 200000 : 2000000;
    const DecoratorCost cost = decoratorCost("sim:omni", *omni_map, ticks);
    std::printf("\nServo tick (getPosition + setForce) on sim:omni, %d ticks interleaved\n", ticks);
    std::printf("  raw %.1f ns, decorated %.1f ns: +%.1f ns, ratio %.2f\n", cost.raw_ns,
                cost.decorated_ns, cost.decorated_ns - cost.raw_ns,
                cost.decorated_ns / cost.raw_ns);
    report["decorator"] = {{"raw_ns", cost.raw_ns},
                           {"decorated_ns", cost.decorated_ns},
                           {"overhead_ns", cost.decorated_ns - cost.raw_ns},
                           {"ratio", cost.decorated_ns / cost.raw_ns}};
    const int queries = ticks;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    const auto start = Clock::now();
    for (int k = 0; k < queries; ++k) {
      const double s = (k % 1000) * 1e-3 - 0.5;
      sum += omni_map->gravityAt(omni_map->grid().center_m() + 0.05 * Eigen::Vector3d(s, -s, s));
    }
    const double query_ns = secondsSince(start) / queries * 1e9;
    std::printf("  GravityMap::gravityAt: %.1f ns per query (checksum %.3f)\n", query_ns,
                sum.sum());
    report["map_query_ns"] = query_ns;
  }
  writeJsonReport(options.report_path, report);
}

void addBenchCommand(CLI::App& app) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* command = app.add_subcommand(
      "bench", "Measure simulator speed, calibration iterations and time, and decorator cost");
  command->add_option("--grid", options->grid, "Vertices per axis of the benchmark calibration")
      ->check(CLI::Range(2, 8))
      ->capture_default_str();
  command->add_flag("--quick", options->quick, "Shorter runs (noisier figures)");
  addFrictionOption(*command, options->friction);
  command->add_flag("--friction-sweep", options->friction_sweep,
                    "Instead: calibrate and verify every simulated device at every friction level");
  command->add_option("--sweep-grid", options->sweep_grid, "Vertices per axis in the sweep")
      ->check(CLI::Range(2, 8))
      ->capture_default_str();
  command->add_option("--sweep-points", options->sweep_points, "verify points in the sweep")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  command->add_option("--plot", options->plot_path, "With --friction-sweep: plot it to this PNG");
  command->add_option("--report", options->report_path, "Write a JSON report here");
  command->callback([options] { runBenchCommand(*options); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(90, addBenchCommand);

}  // namespace autograv::cli
