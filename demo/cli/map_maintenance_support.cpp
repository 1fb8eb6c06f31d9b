#include "map_maintenance_support.h"

#include <algorithm>
#include <cmath>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "estimation_options.h"
#include "friction_option.h"

namespace autograv::cli {

void addMaintenanceOptions(CLI::App& command, MaintenanceOptions& options) {
  addDeviceOption(command, options.device);
  addMapsOption(command, options.maps_dir);
  command.add_option("--seed", options.seed, "Noise seed of simulated devices")
      ->capture_default_str();
  addReportOption(command, options.report_path);
  addFrictionOption(command, options.friction);
  addSimulatedUnitOptions(command, options.unit);
  addSimulatedLoadOptions(command, options.load);
  addEstimationOptions(command, options.parameters);
}

MaintenanceSetup openForMaintenance(const MaintenanceOptions& options, const CLI::App& command) {
  DeviceHandle device = openDevice(options.device, options.seed, options.friction, options.unit);
  applySimulatedLoad(device, options.load);
  const DeviceSpecifications& specifications = device.device->specifications();
  std::string path = options.map_path;
  if (path.empty()) path = MapLibrary(options.maps_dir).find(specifications);
  GravityMap map = path.empty() ? loadMapForDevice(specifications, options.maps_dir)  // throws
                                : loadMap(path, MapLoadOptions{specifications.model_name, false});
  EstimationParameters parameters = options.parameters;
  applyDeviceDefaults(command, parameters, specifications);
  std::optional<RealTimePriority> servo_priority = enterServoPriority(device);
  return {std::move(device), std::move(map), path, parameters, servo_priority};
}

double maxVertexDifferenceRel(const GravityMap& a, const GravityMap& b) {
  if (!a.grid().sameGeometry(b.grid())) {
    throw Error("the two maps have different grids, so they cannot be compared vertex by vertex");
  }
  double worst = 0.0;
  for (std::size_t i = 0; i < a.vertices().size(); ++i) {
    const Eigen::Vector3d& reference_n = b.vertices()[i].gravity_n;
    worst = std::max(worst, (a.vertices()[i].gravity_n - reference_n).norm() / reference_n.norm());
  }
  return worst;
}

}  // namespace autograv::cli
