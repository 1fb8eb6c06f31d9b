#include "map_maintenance_support.h"

#include <algorithm>
#include <cmath>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"

namespace autograv::cli {

void addMaintenanceOptions(CLI::App& command, MaintenanceOptions& options,
                           AdvancedOptions& advanced) {
  addDeviceOption(command, options.device);
  addMapsOption(command, options.maps_dir);
  addReportOption(command, options.report_path);
  advanced.accept(command, {knob::kSimulatedDevice, knob::kSimulatedLoad, knob::kEstimation});
}

MaintenanceSetup openForMaintenance(const MaintenanceOptions& options,
                                    const AdvancedOptions& advanced) {
  const SimulationKnobs& simulation = advanced.simulation();
  DeviceHandle device =
      openDevice(options.device, simulation.seed, simulation.friction, simulation.unit);
  applySimulatedLoad(device, simulation.load);
  const DeviceSpecifications& specifications = device.device->specifications();
  std::string path = options.map_path;
  if (path.empty()) path = MapLibrary(options.maps_dir).find(specifications);
  GravityMap map = path.empty() ? loadMapForDevice(specifications, options.maps_dir)  // throws
                                : loadMap(path, MapLoadOptions{specifications.model_name, false});
  const EstimationParameters parameters =
      estimationParameters(advanced.estimation(), EstimationMethod::kDither, specifications);
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
