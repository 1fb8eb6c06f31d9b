// autograv bench: speed and iteration figures measured side by side in one run.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autograv/device/gravity_compensated_device.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/sim/procedures.h"
#include "cli_support.h"
#include "commands.h"
#include "friction_option.h"

namespace autograv::cli {

namespace {

using Clock = std::chrono::steady_clock;

struct BenchOptions {
  std::string report_path;
  int grid = 5;
  bool quick = false;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
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
  double max_error_rel = 0.0;
};

CalibrationFigures calibrationFigures(const std::string& name, sim::FrictionLevel friction,
                                      int resolution, bool extrapolate, GravityMap* map_out) {
  auto device = openSimulatedDevice(name, 1, friction);
  const double side_m = defaultGridSide_m(device->specifications().workspace_radius_m);
  sim::CalibrationRunOptions options;
  options.grid_center_m = device->workspaceCenter_m();
  options.grid_side_m = side_m;
  options.grid_resolution = resolution;
  options.calibrator.extrapolate_initial_estimate = extrapolate;
  options.parameters.k0_n_per_m = defaultInitializationStiffness(device->specifications());
  const auto start = Clock::now();
  const sim::CalibrationRunResult result = sim::runSimulatedCalibration(*device, options);
  CalibrationFigures figures;
  figures.wall_s = secondsSince(start);
  figures.simulated_s = result.simulated_seconds;
  std::vector<int> iterations;
  for (const auto& vertex : result.vertices) {
    iterations.push_back(vertex.iterations);
    figures.seconds_per_vertex += vertex.seconds;
    figures.converged += vertex.outcome == VertexOutcome::kConverged;
  }
  figures.vertices = static_cast<int>(iterations.size());
  figures.seconds_per_vertex /= figures.vertices;
  std::sort(iterations.begin(), iterations.end());
  const std::size_t n = iterations.size();
  figures.iterations_median =
      n % 2 ? iterations[n / 2] : 0.5 * (iterations[n / 2 - 1] + iterations[n / 2]);
  figures.iterations_max = iterations.back();
  const GravityMap map(WorkspaceGrid(options.grid_center_m, side_m, resolution), result.vertices,
                       MapMetadata{device->specifications().model_name, "", "", {}});
  figures.max_error_rel = sim::measureAccuracy(map, *device, 0).max_error_rel;
  if (map_out != nullptr) *map_out = map;
  return figures;
}

void runBenchCommand(const BenchOptions& options) {
  nlohmann::json report;
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
      const CalibrationFigures f =
          calibrationFigures(name, options.friction, options.grid, extrapolate, &map);
      const char* start = extrapolate ? "extrapolate" : "eq. (9)";
      std::printf("  %-10s %-12s %6.1f %6d %10.2f %10.1f %9.2f %7.2f%%\n", name.c_str(), start,
                  f.iterations_median, f.iterations_max, f.seconds_per_vertex, f.simulated_s,
                  f.wall_s, 100.0 * f.max_error_rel);
      report["calibration"][name][extrapolate ? "extrapolate" : "copy"] = {
          {"iterations_median", f.iterations_median},
          {"iterations_max", f.iterations_max},
          {"seconds_per_vertex", f.seconds_per_vertex},
          {"simulated_seconds", f.simulated_s},
          {"wall_seconds", f.wall_s},
          {"converged", f.converged},
          {"vertices", f.vertices},
          {"max_error_rel", f.max_error_rel}};
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
  command->add_option("--report", options->report_path, "Write a JSON report here");
  command->callback([options] { runBenchCommand(*options); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(90, addBenchCommand);

}  // namespace autograv::cli
