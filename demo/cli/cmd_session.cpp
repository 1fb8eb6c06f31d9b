// autograv session: a map in use for an hour on a simulated device whose motors warm, scored
// minute by minute against the device's truth, beside the same unit whose motors never warm.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/session_workload.h"
#include "cli_support.h"
#include "commands.h"
#include "session_report.h"

namespace autograv::cli {

namespace {

struct SessionCommandOptions {
  std::string device;
  std::string map_path;
  std::string report_path;
  std::string plot_path;
  sim::SessionWorkloadOptions workload;
  bool baseline = true;
};

/// One session on a fresh device of `unit`, printing a row per score.
sim::SessionWorkloadResult runOne(const SessionCommandOptions& options,
                                  const SimulationKnobs& simulation, const sim::SimulatedUnit& unit,
                                  const std::shared_ptr<const GravityMap>& map, const char* label) {
  auto device = openSimulatedDevice(options.device, simulation.seed, simulation.friction, unit);
  applySimulatedLoad(*device, simulation.load);
  device->resetState(device->workspaceCenter_m());
  sim::SessionWorkloadOptions workload = options.workload;
  workload.servo_timing = simulation.servo_timing;
  if (!unit.thermal.enabled) {
    // Motors that never warm: the map as measured is the reference, not a correction for a
    // warming that does not happen there.
    workload.thermal_correction = false;
    workload.initial_thermal_load = 0.0;
  }
  std::printf("\n%s: %s, thermal %s (ambient %.1f C, motors from %.1f C), session %d\n", label,
              options.device.c_str(), unit.thermal.enabled ? "on" : "off", unit.thermal.ambient_c,
              unit.thermal.start_c, unit.session);
  std::printf("%7s %7s %7s %7s %9s %7s %7s %13s %9s %9s %6s %8s\n", "minute", "p50 %", "p90 %",
              "p99 %", "path p90", "correct", "scale", "scaled p90/99", "winding C", "gain min",
              "load", "cont. s");
  std::fflush(stdout);
  return sim::runSessionWorkload(*device, map, workload, [](const sim::SessionSample& sample) {
    std::printf("%7.1f %7.3f %7.3f %7.3f %9.3f %7.4f %7.4f %6.3f/%6.3f %9.1f %9.4f %6.3f %8.1f\n",
                sample.minute, 100 * sample.field.p50_rel, 100 * sample.field.p90_rel,
                100 * sample.field.p99_rel, 100 * sample.path_p90_rel, sample.thermal_scale,
                sample.best_scale, 100 * sample.rescaled_field.p90_rel,
                100 * sample.rescaled_field.p99_rel, sample.hottest_winding_c,
                sample.lowest_gain_factor, sample.thermal_load,
                sample.seconds_above_continuous_force);
    std::fflush(stdout);
  });
}

void runSessionCommand(const SessionCommandOptions& options, const AdvancedOptions& advanced) {
  const SimulationKnobs& simulation = advanced.simulation();
  auto map = std::make_shared<const GravityMap>(loadMap(options.map_path));
  if (!options.report_path.empty()) checkWritable(options.report_path, "report");
  std::vector<sim::SessionWorkloadResult> runs;
  std::vector<std::string> names;
  std::vector<sim::SimulatedUnit> units = {simulation.unit};
  names.push_back(simulation.unit.thermal.enabled ? "warming" : "never warming");
  if (options.baseline && (simulation.unit.thermal.enabled || simulation.unit.session != 1)) {
    units.push_back({simulation.unit.number, simulation.unit.actuators, 1, {}});
    names.push_back("never warming, session 1");
  }
  nlohmann::json report = {{"device", options.device},
                           {"map", options.map_path},
                           {"minutes", options.workload.minutes},
                           {"sessions", nlohmann::json::array()}};
  for (std::size_t u = 0; u < units.size(); ++u) {
    runs.push_back(runOne(options, simulation, units[u], map, names[u].c_str()));
    report["sessions"].push_back(sessionJson(runs.back(), units[u]));
    std::printf("force: %llu ticks at the limit, %.1f s above the continuous rating, peak %.2f N\n",
                static_cast<unsigned long long>(runs.back().force_limit_ticks),
                runs.back().seconds_above_continuous_force, runs.back().peak_force_n);
  }
  writeJsonReport(options.report_path, report);
  if (!options.plot_path.empty()) plotSessions(options.plot_path, runs, names, options.device);
}

void addSessionCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<SessionCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "session",
      "Use a map for a session on a simulated device (the hand carries, holds and lets go of the "
      "stylus; the scene adds forces) and score it every minute against the device's truth, "
      "beside the same unit whose motors never warm");
  addDeviceOption(*command, options->device)->check(simulatedOnly("session"));
  command->add_option("--map", options->map_path, "Map file to use (JSON)")->required();
  command->add_option("--minutes", options->workload.minutes, "Device time of the session [min]")
      ->check(CLI::Range(0.1, 1440.0))
      ->capture_default_str();
  command
      ->add_option("--sample-s", options->workload.sample_period_s,
                   "Device time between two scores of the field [s]")
      ->check(CLI::Range(1.0, 3600.0))
      ->capture_default_str();
  command
      ->add_option("--field-samples", options->workload.field_samples,
                   "Points each score draws over the reachable workspace")
      ->check(CLI::Range(100, 10000000))
      ->capture_default_str();
  command
      ->add_option("--workload-seed", options->workload.seed,
                   "Draws the hand's path, pauses and the scene's contacts")
      ->capture_default_str();
  command->add_flag("!--no-baseline", options->baseline,
                    "Do not run the same unit without warming and re-homing beside it");
  command->add_flag("!--no-thermal-correction", options->workload.thermal_correction,
                    "Compensate with the map as measured, without its correction for warm motors");
  command
      ->add_option("--initial-thermal-load", options->workload.initial_thermal_load,
                   "The motors' thermal load the decorator starts from (0: at room temperature; "
                   "right after a calibration, its report's thermal_load_again)")
      ->check(CLI::Range(0.0, 10.0))
      ->capture_default_str();
  addReportOption(*command, options->report_path);
  command->add_option("--plot", options->plot_path, "Write the curves here (PNG; needs a display)");
  advanced->accept(*command, {knob::kSimulatedDevice, knob::kSimulatedLoad, knob::kServoTiming});
  command->callback([options, advanced] { runSessionCommand(*options, *advanced); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(75, addSessionCommand);

}  // namespace autograv::cli
