// autograv bench: speed and iteration figures measured side by side in one run.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "cli_support.h"
#include "commands.h"
#include "error_translation.h"
#include "servo_timing_option.h"
#include "sim/experiments.h"
#include "sweep_report.h"

namespace autograv::cli {

namespace {

struct BenchOptions {
  std::string report_path;
  int grid = 5;
  bool quick = false;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  sim::SimulatedUnit unit;
  bool friction_sweep = false;
  bool methods = false;  ///< --methods: the friction sweep for the paper's method and the dither's
  int seeds = 3;         ///< Seeds 1..seeds of every --methods cell.
  EstimationMethod method = EstimationMethod::kDither;
  int sweep_grid = 4;
  int sweep_points = 12;
  std::string plot_path;
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;
};

void runFrictionSweep(const BenchOptions& options, nlohmann::json& report) {
  sim::FrictionSweepOptions sweep;
  sweep.grid = options.sweep_grid;
  sweep.points = options.sweep_points;
  sweep.servo_timing = options.servo_timing;
  if (options.methods) {
    sweep.methods = {EstimationMethod::kPaper, EstimationMethod::kDither};
    sweep.seeds = options.seeds;
  } else {
    sweep.methods = {options.method};
  }
  ProgressBar progress(comparesMethods(sweep) ? "methods" : "friction sweep");
  sweep.on_progress = [&progress](int done, int total, const std::string& cell) {
    progress.update(done, total, cell);
  };
  std::vector<sim::SweepRow> rows = sim::runFrictionSweep(sweep);
  progress.finish();
  for (sim::SweepRow& row : rows) row.failure = inCommandLineTerms(row.failure);
  rows = sim::foldSweepSeeds(rows);
  printFrictionSweep(rows, sweep, report);
  if (!options.plot_path.empty()) plotFrictionSweep(rows, sweep, options.plot_path);
}

// The default cube on every simulated device, eq. (9)'s start against the extrapolated one;
// returns sim:omni's extrapolated map for the timings.
std::shared_ptr<const GravityMap> runCalibrations(const BenchOptions& options,
                                                  nlohmann::json& report) {
  std::printf(
      "\nCalibration, %d^3 cube grid, default side, seed 1, friction %s, method %s (paper: 14 "
      "iterations at one vertex)\n",
      options.grid, sim::toString(options.friction), toString(options.method));
  report["friction"] = sim::toString(options.friction);
  report["method"] = toString(options.method);
  report["servo_timing"] = sim::toString(options.servo_timing);
  std::printf("  %-10s %-12s %6s %6s %10s %10s %9s %8s\n", "device", "start", "median", "max",
              "s/vertex", "sim [s]", "wall [s]", "worst");
  std::shared_ptr<const GravityMap> omni_map;
  for (const std::string& name : sim::simulatedDeviceNames()) {
    for (bool extrapolate : {false, true}) {
      auto device = openSimulatedDevice(name, 1, options.friction, options.unit);
      sim::DefaultCubeOptions cube;
      cube.resolution = options.grid;
      cube.method = options.method;
      cube.extrapolate_initial_estimate = extrapolate;
      cube.servo_timing = options.servo_timing;
      const sim::DefaultCubeCalibration calibration = sim::calibrateDefaultCube(*device, cube);
      const sim::CalibrationFigures f = sim::calibrationFigures(calibration, *device);
      const char* start = extrapolate ? "extrapolate" : "eq. (9)";
      std::printf("  %-10s %-12s %6.1f %6d %10.2f %10.1f %9.2f %7.2f%%\n", name.c_str(), start,
                  f.iterations_median, f.iterations_max, f.seconds_per_vertex, f.simulated_s,
                  f.wall_s, 100.0 * f.accuracy.max_error_rel);
      nlohmann::json entry = calibrationFiguresJson(f);
      entry["simulated_seconds"] = f.simulated_s;
      entry["wall_seconds"] = f.wall_s;
      entry["servo_loop"] = servoLoopJson(options.servo_timing, f.servo_loop);
      report["calibration"][name][extrapolate ? "extrapolate" : "copy"] = entry;
      if (extrapolate) {
        std::printf("  %-10s ", "");
        printServoLoop(options.servo_timing, f.servo_loop);
      }
      if (extrapolate && name == "sim:omni") omni_map = calibration.map;
    }
  }
  return omni_map;
}

void runBenchCommand(BenchOptions options, const AdvancedOptions& advanced) {
  options.friction = advanced.simulation().friction;
  options.unit = advanced.simulation().unit;
  options.servo_timing = advanced.simulation().servo_timing;
  options.method = advanced.estimation().method.value_or(EstimationMethod::kDither);
  nlohmann::json report;
  if (options.friction_sweep || options.methods) {
    runFrictionSweep(options, report);
    writeJsonReport(options.report_path, report);
    return;
  }
  const double simulated_s = options.quick ? 2.0 : 10.0;
  std::printf("Simulators (10 kHz inside, 1 kHz servo), %g simulated s each; target >= 1000x\n",
              simulated_s);
  for (const std::string& name : sim::simulatedDeviceNames()) {
    const double factor = sim::measureRealTimeFactor(name, simulated_s);
    std::printf("  %-10s %10.0fx real time\n", name.c_str(), factor);
    report["simulator"][name]["realtime_factor"] = factor;
  }
  const std::shared_ptr<const GravityMap> omni_map = runCalibrations(options, report);
  if (omni_map) {
    const int ticks = options.quick ? 200000 : 2000000;
    const sim::DecoratorCost cost = sim::measureDecoratorCost("sim:omni", *omni_map, ticks);
    std::printf("\nServo tick (getPosition + setForce) on sim:omni, %d ticks interleaved\n", ticks);
    std::printf("  raw %.1f ns, decorated %.1f ns: +%.1f ns, ratio %.2f\n", cost.raw_ns,
                cost.decorated_ns, cost.decorated_ns - cost.raw_ns,
                cost.decorated_ns / cost.raw_ns);
    report["decorator"] = {{"raw_ns", cost.raw_ns},
                           {"decorated_ns", cost.decorated_ns},
                           {"overhead_ns", cost.decorated_ns - cost.raw_ns},
                           {"ratio", cost.decorated_ns / cost.raw_ns}};
    const sim::MapQueryCost query = sim::measureMapQueryCost(*omni_map, ticks);
    std::printf("  GravityMap::gravityAt: %.1f ns per query (checksum %.3f)\n", query.query_ns,
                query.checksum_n);
    report["map_query_ns"] = query.query_ns;
  }
  writeJsonReport(options.report_path, report);
}

void addBenchCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<BenchOptions>();
  CLI::App* command = app.add_subcommand(
      "bench", "Measure simulator speed, calibration iterations and time, and decorator cost");
  command->group(kResearchCommands);
  // A count within [least, most], its default shown.
  const auto add_count = [command](const char* flag, int& count, const char* description, int least,
                                   int most) {
    command->add_option(flag, count, description)
        ->check(CLI::Range(least, most))
        ->capture_default_str();
  };
  add_count("--grid", options->grid, "Vertices per axis of the benchmark calibration", 2, 8);
  command->add_flag("--quick", options->quick, "Shorter runs (noisier figures)");
  command->add_flag("--friction-sweep", options->friction_sweep,
                    "Instead: calibrate and verify every simulated device at every friction level");
  add_count("--sweep-grid", options->sweep_grid, "Vertices per axis in the sweep", 2, 8);
  add_count("--sweep-points", options->sweep_points, "verify points in the sweep", 1, 1000);
  command->add_flag("--methods", options->methods,
                    "Instead: the friction sweep for the paper's method and the dither method, "
                    "side by side on the same seeds");
  add_count("--seeds", options->seeds, "Seeds 1..N of every --methods cell", 1, 20);
  command->add_option("--plot", options->plot_path,
                      "With --friction-sweep or --methods: plot it to this PNG");
  addReportOption(*command, options->report_path);
  advanced->accept(*command,
                   {{"--friction", "--unit", "--actuators"}, knob::kServoTiming, knob::kMethod});
  command->callback([options, advanced] { runBenchCommand(*options, *advanced); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(90, addBenchCommand);

}  // namespace autograv::cli
