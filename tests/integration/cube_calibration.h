#pragma once

// The calibration several integration tests start from: the tools' method on the default cube.

#include "autograv/estimation/estimation_parameters.h"
#include "autograv/estimation/pd_design.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::testing {

/// What the tools use: the dither method, which converges through dry friction, with the
/// device-aware initialization stiffness.
inline EstimationParameters toolParameters(const sim::SimulatedDevice& device) {
  EstimationParameters parameters = EstimationParameters{};
  parameters.k0_n_per_m = defaultInitializationStiffness(device.specifications());
  return parameters;
}

/// Calibrates `device` (open) on `resolution` vertices per axis over the default cube (80 % of
/// the cube inscribed in the workspace sphere: every vertex reachable) with toolParameters, and
/// returns the map, labelled with the device's model. Not real-time safe.
inline GravityMap calibrateDefaultCube(sim::SimulatedDevice& device, int resolution) {
  sim::CalibrationRunOptions options;
  options.explore = false;  // every vertex of the default cube is reachable
  options.grid_center_m = device.workspaceCenter_m();
  options.grid_size_m =
      Eigen::Vector3d::Constant(defaultGridSide_m(device.specifications().workspace_radius_m));
  options.grid_resolution = Eigen::Vector3i::Constant(resolution);
  options.parameters = toolParameters(device);
  const sim::CalibrationRunResult run = sim::runSimulatedCalibration(device, options);
  MapMetadata metadata;
  metadata.device_model = device.specifications().model_name;
  metadata.parameters = options.parameters;
  return GravityMap(
      WorkspaceGrid(options.grid_center_m, options.grid_size_m, options.grid_resolution),
      run.vertices, metadata);
}

}  // namespace autograv::testing
