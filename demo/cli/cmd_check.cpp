// autograv check: does the saved map still fit this device? Exit status 0 when it does, 1 when
// it does not (with the reason and what to run instead).
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/maintenance/map_check.h"
#include "cli_support.h"
#include "commands.h"
#include "error_translation.h"
#include "map_maintenance_support.h"

namespace autograv::cli {

namespace {

void runCheckCommand(const MaintenanceOptions& options, const AdvancedOptions& advanced,
                     int vertices, double tolerance_percent) {
  MaintenanceSetup setup = openForMaintenance(options, advanced);
  MapCheckOptions check;
  check.measurement.parameters = setup.parameters;
  check.vertex_count = vertices;
  check.tolerance_rel = tolerance_percent * 1e-2;
  const auto ticks =
      makeTickSource(setup.device, setup.parameters.servo_period_s, /*real_time=*/false);
  const MapCheckResult result = checkMap(*setup.device.device, *ticks, setup.map, check);
  std::printf("%s: %s\n", setup.device.name.c_str(), inCommandLineTerms(result.reason).c_str());
  std::printf("field model: %s\n", describeFieldModel(setup.map).c_str());
  nlohmann::json report = {{"device", setup.device.name},
                           {"map", setup.map_path},
                           {"field_model", toString(setup.map.fieldModel())},
                           {"fit", toString(result.fit)},
                           {"fits", result.fit == MapFit::kFits},
                           {"reason", inCommandLineTerms(result.reason)},
                           {"max_error_rel", result.max_error_rel},
                           {"payload_estimate_g", result.payload_kg * 1e3},
                           {"tilt_estimate_deg", result.tilt_rad * 180.0 / 3.14159265358979323846},
                           {"vertices", result.measurement.vertices},
                           {"simulated_seconds", result.measurement.seconds}};
  addServoPriorityJson(report, setup.servo_priority);
  writeJsonReport(options.report_path, report);
  if (result.fit != MapFit::kFits) throw CLI::RuntimeError(1);  // exit status 1, reason printed
}

void addCheckCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<MaintenanceOptions>();
  auto vertices = std::make_shared<int>(3);
  auto tolerance_percent = std::make_shared<double>(MapCheckOptions().tolerance_rel * 100.0);
  CLI::App* command = app.add_subcommand(
      "check",
      "Health check (~10 s): does the saved map still fit this device? Exit 0 if so, 1 if not "
      "(then it says whether to retare or calibrate again)");
  command->add_option("--map", options->map_path,
                      "Map to check (default: the device's map in the library)");
  addMaintenanceOptions(*command, *options, *advanced);
  command->add_option("--vertices", *vertices, "Vertices to measure at")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  command
      ->add_option("--tolerance-percent", *tolerance_percent,
                   "Largest difference from the map at a vertex that still fits [% of |G|]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->callback([options, advanced, vertices, tolerance_percent] {
    runCheckCommand(*options, *advanced, *vertices, *tolerance_percent);
  });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(56, addCheckCommand);

}  // namespace autograv::cli
