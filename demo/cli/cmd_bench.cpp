// autograv bench: speed and iteration figures measured side by side in one run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/sim/friction.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/verification.h"
#include "cli_support.h"
#include "commands.h"
#include "error_translation.h"
#include "friction_option.h"
#include "servo_timing_option.h"

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
  bool methods = false;  ///< --methods: the friction sweep for the paper's method and the dither's
  int seeds = 3;         ///< Seeds 1..seeds of every --methods cell.
  EstimationMethod method = EstimationMethod::kDither;
  int sweep_grid = 4;
  int sweep_points = 12;
  std::string plot_path;
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;
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
  ServoLoopStats::Summary servo_loop;
};

CalibrationFigures calibrationFigures(sim::SimulatedDevice& device, int resolution,
                                      bool extrapolate, EstimationMethod method,
                                      GravityMap* map_out, sim::ServoTiming timing,
                                      std::uint64_t timing_seed) {
  // The classic cube (80 % of the cube inscribed in the workspace sphere), every vertex
  // reachable: the figures compare estimators, not the fitted box's unreachable corners.
  const double side_m = defaultGridSide_m(device.specifications().workspace_radius_m);
  const WorkspaceGrid grid(device.workspaceCenter_m(), side_m, resolution);
  sim::CalibrationRunOptions options;
  options.grid_center_m = grid.center_m();
  options.grid_size_m = grid.size_m();
  options.grid_resolution = grid.resolution();
  options.calibrator.extrapolate_initial_estimate = extrapolate;
  options.parameters =
      method == EstimationMethod::kDither ? EstimationParameters{} : EstimationParameters::paper();
  options.parameters.k0_n_per_m = defaultInitializationStiffness(device.specifications());
  options.servo_timing = timing;
  options.servo_timing_seed = timing_seed;
  const auto start = Clock::now();
  const sim::CalibrationRunResult result = sim::runSimulatedCalibration(device, options);
  CalibrationFigures figures;
  figures.wall_s = secondsSince(start);
  figures.simulated_s = result.simulated_seconds;
  figures.servo_loop = result.servo_loop;
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
  const GravityMap map(grid, result.vertices,
                       MapMetadata{device.specifications().model_name, "", "", {}, {}});
  figures.accuracy = sim::measureAccuracy(map, device, 1000);
  if (map_out != nullptr) *map_out = map;
  return figures;
}

/// One row of the friction sweep: calibration and verify on one device at one friction level, with
/// one method and one seed.
struct SweepRow {
  std::string device;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  EstimationMethod method = EstimationMethod::kDither;
  int seed = 1;
  CalibrationFigures calibration;
  sim::Percentiles residual_n;
  std::string failure;  ///< Why the calibration or verify could not run; empty when they did.
};

SweepRow runSweepCell(const BenchOptions& options, const std::string& name,
                      sim::FrictionLevel friction, EstimationMethod method, int seed) {
  SweepRow row;
  row.device = name;
  row.friction = friction;
  row.method = method;
  row.seed = seed;
  std::shared_ptr<sim::SimulatedDevice> device =
      openSimulatedDevice(name, static_cast<std::uint64_t>(seed), friction);
  auto map = std::make_shared<GravityMap>(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2),
                                          std::vector<VertexEstimate>(8), MapMetadata{});
  try {
    row.calibration = calibrationFigures(*device, options.sweep_grid, true, method, map.get(),
                                         options.servo_timing, static_cast<std::uint64_t>(seed));
    sim::VerificationOptions verification;
    verification.points = options.sweep_points;
    verification.servo_timing = options.servo_timing;
    verification.servo_timing_seed = static_cast<std::uint64_t>(seed);
    verification.compare_uncompensated = false;
    row.residual_n =
        sim::verifyMapOnSimulatedDevice(device, std::move(map), verification).residual_force_n;
  } catch (const Error& error) {
    row.failure =
        inCommandLineTerms(error.what());  // a level the calibration cannot handle is a result too
  }
  return row;
}

/// Every simulated device at every friction level, for each of `methods` and seeds 1..`seeds`.
std::vector<SweepRow> runFrictionSweep(const BenchOptions& options,
                                       const std::vector<EstimationMethod>& methods, int seeds) {
  const std::vector<std::string> devices = sim::simulatedDeviceNames();
  const std::vector<std::string> levels = sim::frictionLevelNames();
  std::vector<SweepRow> rows;
  ProgressBar progress(methods.size() > 1 ? "methods" : "friction sweep");
  const int total = static_cast<int>(devices.size() * levels.size() * methods.size()) * seeds;
  for (const std::string& name : devices) {
    for (const std::string& level : levels) {
      for (const EstimationMethod method : methods) {
        for (int seed = 1; seed <= seeds; ++seed) {
          progress.update(
              static_cast<int>(rows.size()), total,
              name + " " + level + " " + toString(method) + " seed " + std::to_string(seed));
          rows.push_back(runSweepCell(options, name, sim::parseFrictionLevel(level), method, seed));
        }
      }
    }
  }
  progress.update(total, total, "done");
  progress.finish();
  return rows;
}

/// The rows of one device, friction level and method over its seeds, folded into one: vertices
/// and convergence add up, iterations and residuals take the median of the seeds' medians and the
/// largest maximum, errors the worst vertex and the mean RMS, time the mean.
SweepRow foldSeeds(const std::vector<const SweepRow*>& seeds) {
  SweepRow folded = *seeds.front();
  CalibrationFigures& f = folded.calibration;
  f = CalibrationFigures{};
  std::vector<double> iteration_medians, residual_medians;
  double rms_n = 0.0, rms_rel = 0.0;
  int ran = 0;
  for (const SweepRow* row : seeds) {
    if (!row->failure.empty()) {
      folded.failure = "seed " + std::to_string(row->seed) + ": " + row->failure;
      continue;
    }
    const CalibrationFigures& c = row->calibration;
    f.converged += c.converged;
    f.vertices += c.vertices;
    f.iterations_max = std::max(f.iterations_max, c.iterations_max);
    f.seconds_per_vertex += c.seconds_per_vertex;
    if (c.accuracy.max_error_rel >= f.accuracy.max_error_rel) {
      f.accuracy.max_error_rel = c.accuracy.max_error_rel;
      f.accuracy.max_error_n = c.accuracy.max_error_n;
    }
    rms_n += c.accuracy.rms_residual_n;
    rms_rel += c.accuracy.rms_residual_rel;
    iteration_medians.push_back(c.iterations_median);
    residual_medians.push_back(row->residual_n.median);
    folded.residual_n.max = std::max(folded.residual_n.max, row->residual_n.max);
    ++ran;
  }
  if (ran == 0) return folded;
  if (ran == static_cast<int>(seeds.size())) folded.failure.clear();
  f.seconds_per_vertex /= ran;
  f.accuracy.rms_residual_n = rms_n / ran;
  f.accuracy.rms_residual_rel = rms_rel / ran;
  f.iterations_median = sim::percentiles(iteration_medians).median;
  folded.residual_n.median = sim::percentiles(residual_medians).median;
  return folded;
}

/// Rows of the same device, friction level and method, seeds folded (foldSeeds), in sweep order.
std::vector<SweepRow> foldSweepSeeds(const std::vector<SweepRow>& rows) {
  std::vector<SweepRow> folded;
  for (std::size_t first = 0; first < rows.size();) {
    std::vector<const SweepRow*> group;
    std::size_t next = first;
    while (next < rows.size() && rows[next].device == rows[first].device &&
           rows[next].friction == rows[first].friction && rows[next].method == rows[first].method) {
      group.push_back(&rows[next++]);
    }
    folded.push_back(foldSeeds(group));
    first = next;
  }
  return folded;
}

void printFrictionSweep(const std::vector<SweepRow>& rows, const BenchOptions& options, int seeds,
                        const char* key, nlohmann::json& report) {
  std::printf(
      "\n%s: calibration on a %d^3 grid, then verify at %d points (seeds 1-%d)\n"
      "  error: |G_hat - G| against the simulation's ground truth, worst vertex and RMS over\n"
      "  the grid; residual: verify's measured residual force (median / max)%s\n",
      options.methods ? "Methods, side by side" : "Friction sweep", options.sweep_grid,
      options.sweep_points, seeds,
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
    list.push_back({{"device", row.device},
                    {"friction", sim::toString(row.friction)},
                    {"method", toString(row.method)},
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
  if (options.servo_timing != sim::ServoTiming::kExact && !rows.empty() &&
      rows.front().failure.empty()) {
    printServoLoop(options.servo_timing, rows.front().calibration.servo_loop);
  }
  report[key] = {{"grid", options.sweep_grid},
                 {"servo_timing", sim::toString(options.servo_timing)},
                 {"verify_points", options.sweep_points},
                 {"seeds", seeds},
                 {"rows", list}};
}

/// The sweep as four panels over the friction levels, one line per device (and method, when the
/// rows hold several).
void plotFrictionSweep(const std::vector<SweepRow>& rows,
                       const std::vector<EstimationMethod>& methods, const std::string& title,
                       const std::string& path) {
#ifdef AUTOGRAV_HAVE_VIZ
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
  plot.title = title;
  viz::writePng(viz::renderSweepPlot(levels, "friction level", panels, plot), path);
  std::printf("\nwrote %s\n", path.c_str());
#else
  (void)rows;
  (void)methods;
  (void)title;
  throw Error("--plot " + path + ": autograv was built without AUTOGRAV_BUILD_VIZ=ON");
#endif
}

void runBenchCommand(const BenchOptions& options) {
  nlohmann::json report;
  if (options.friction_sweep || options.methods) {
    const std::vector<EstimationMethod> methods =
        options.methods
            ? std::vector<EstimationMethod>{EstimationMethod::kPaper, EstimationMethod::kDither}
            : std::vector<EstimationMethod>{options.method};
    const int seeds = options.methods ? options.seeds : 1;
    const std::vector<SweepRow> rows = foldSweepSeeds(runFrictionSweep(options, methods, seeds));
    printFrictionSweep(rows, options, seeds, options.methods ? "methods" : "friction_sweep",
                       report);
    if (!options.plot_path.empty()) {
      plotFrictionSweep(rows, methods,
                        options.methods ? "Paper's method against the dither method"
                                        : "Friction sweep, simulated devices",
                        options.plot_path);
    }
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
      "\nCalibration, %d^3 cube grid, default side, seed 1, friction %s, method %s (paper: 14 "
      "iterations at one vertex)\n",
      options.grid, sim::toString(options.friction), toString(options.method));
  report["friction"] = sim::toString(options.friction);
  report["method"] = toString(options.method);
  report["servo_timing"] = sim::toString(options.servo_timing);
  std::printf("  %-10s %-12s %6s %6s %10s %10s %9s %8s\n", "device", "start", "median", "max",
              "s/vertex", "sim [s]", "wall [s]", "worst");
  std::unique_ptr<GravityMap> omni_map;
  for (const std::string& name : sim::simulatedDeviceNames()) {
    for (bool extrapolate : {false, true}) {
      GravityMap map(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 2), std::vector<VertexEstimate>(8),
                     MapMetadata{});
      auto device = openSimulatedDevice(name, 1, options.friction);
      const CalibrationFigures f = calibrationFigures(
          *device, options.grid, extrapolate, options.method, &map, options.servo_timing, 1);
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
          {"max_error_n", f.accuracy.max_error_n},
          {"servo_loop", servoLoopJson(options.servo_timing, f.servo_loop)}};
      if (extrapolate) {
        std::printf("  %-10s ", "");
        printServoLoop(options.servo_timing, f.servo_loop);
      }
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
  addServoTimingOption(*command, options->servo_timing);
  command->add_flag("--friction-sweep", options->friction_sweep,
                    "Instead: calibrate and verify every simulated device at every friction level");
  command->add_option("--sweep-grid", options->sweep_grid, "Vertices per axis in the sweep")
      ->check(CLI::Range(2, 8))
      ->capture_default_str();
  command->add_option("--sweep-points", options->sweep_points, "verify points in the sweep")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  command->add_flag("--methods", options->methods,
                    "Instead: the friction sweep for the paper's method and the dither method, "
                    "side by side on the same seeds");
  command->add_option("--seeds", options->seeds, "Seeds 1..N of every --methods cell")
      ->check(CLI::Range(1, 20))
      ->capture_default_str();
  command
      ->add_option_function<std::string>(
          "--method",
          [options](const std::string& name) { options->method = parseEstimationMethod(name); },
          "Estimation method of the calibrations (default dither)")
      ->check(CLI::IsMember({"paper", "dither"}));
  command->add_option("--plot", options->plot_path,
                      "With --friction-sweep or --methods: plot it to this PNG");
  command->add_option("--report", options->report_path, "Write a JSON report here");
  command->callback([options] { runBenchCommand(*options); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(90, addBenchCommand);

}  // namespace autograv::cli
