// autograv retare: after a handle change, measure the added weight at a few vertices and shift the
// map, instead of calibrating the whole grid again.
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/error.h"
#include "autograv/maintenance/retare.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "autograv/sim/procedures.h"
#include "cli_support.h"
#include "commands.h"
#include "map_maintenance_support.h"

namespace autograv::cli {

namespace {

struct RetareCommandOptions {
  MaintenanceOptions common;
  std::string out_path;  // empty: back into the library
  std::string compare_path;
  int vertices = 3;
};

void runRetareCommand(const RetareCommandOptions& options, const AdvancedOptions& advanced) {
  MaintenanceSetup setup = openForMaintenance(options.common, advanced);
  const SimulatedLoad& load = advanced.simulation().load;
  const std::string& name = setup.device.name;
  std::printf(
      "re-taring %s for %s: measuring at %d vertices near the centre; keep the "
      "end-effector free\n",
      setup.map_path.empty() ? "the library's map" : setup.map_path.c_str(), name.c_str(),
      options.vertices);
  RetareOptions retare;
  retare.measurement.parameters = setup.parameters;
  retare.vertex_count = options.vertices;
  const auto ticks =
      makeTickSource(setup.device, setup.parameters.servo_period_s, /*real_time=*/false);
  const RetareResult result = retareMap(*setup.device.device, *ticks, setup.map, retare);

  const std::string out_path = options.out_path.empty()
                                   ? MapLibrary(options.common.maps_dir).save(result.map)
                                   : (saveMap(result.map, options.out_path), options.out_path);
  std::printf(
      "added weight %+.1f g (shift [%.4f %.4f %.4f] N, vertices agree within %.2f %% of "
      "|G|) in %.1f s of servo time; re-tared map saved to %s\n",
      result.payload_kg * 1e3, result.shift_n.x(), result.shift_n.y(), result.shift_n.z(),
      100.0 * result.disagreement_rel, result.measurement.seconds, out_path.c_str());

  nlohmann::json report = {{"device", name},
                           {"map", setup.map_path},
                           {"out", out_path},
                           {"payload_estimate_g", result.payload_kg * 1e3},
                           {"shift_n", vectorJson(result.shift_n)},
                           {"disagreement_rel", result.disagreement_rel},
                           {"vertices", result.measurement.vertices},
                           {"simulated_seconds", result.measurement.seconds},
                           {"payload_true_g", load.payload_g}};
  if (setup.device.simulation) {
    const sim::AccuracyReport accuracy = sim::measureAccuracy(result.map, *setup.device.simulation,
                                                              1000, advanced.simulation().seed);
    report["max_error_rel"] = accuracy.max_error_rel;  // against the simulation's ground truth
    report["rms_residual_rel"] = accuracy.rms_residual_rel;
    if (load.tilt_deg == 0.0) {
      // The re-tare's own error: its shift against the true weight of the simulated payload
      // (the rest of max_error_rel is the original map's).
      const Eigen::Vector3d weight_n(0.0, 0.0, load.payload_g * 1e-3 * kStandardGravity);
      const double shift_error_rel = (result.shift_n - weight_n).norm() / accuracy.mean_true_norm_n;
      report["shift_error_rel"] = shift_error_rel;
      std::printf("the shift is %.3f %% of mean |G| off the payload's true weight\n",
                  100.0 * shift_error_rel);
    }
    std::printf("against the simulation's truth: worst vertex %.3f %% of |G|\n",
                100.0 * accuracy.max_error_rel);
  }
  if (!options.compare_path.empty()) {
    const double difference = maxVertexDifferenceRel(result.map, loadMap(options.compare_path));
    report["compare"] = options.compare_path;
    report["max_difference_rel"] = difference;
    std::printf("against %s: worst vertex differs by %.3f %% of |G|\n",
                options.compare_path.c_str(), 100.0 * difference);
  }
  addServoPriorityJson(report, setup.servo_priority);
  writeJsonReport(options.common.report_path, report);
}

void addRetareCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<RetareCommandOptions>();
  CLI::App* command = app.add_subcommand(
      "retare",
      "After a handle change: measure the added weight at 1-3 vertices (seconds) and shift the "
      "map");
  command->add_option("map", options->common.map_path,
                      "Map to re-tare (default: the device's map in the library)");
  addMaintenanceOptions(*command, options->common, *advanced);
  command->add_option("--out", options->out_path,
                      "Where to write the re-tared map (default: back into the library)");
  command->add_option("--vertices", options->vertices, "Vertices to measure at")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  command->add_option("--compare", options->compare_path,
                      "A map to compare the result with, vertex by vertex (e.g. a full "
                      "calibration made with the new handle)");
  command->callback([options, advanced] { runRetareCommand(*options, *advanced); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(55, addRetareCommand);

}  // namespace autograv::cli
