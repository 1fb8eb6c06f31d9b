#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::cli {

/// The calibration grid as given on the command line.
struct GridOptions {
  std::string grid;    ///< "--grid": "5" (per axis) or "7x5x4"; empty: 5 per axis.
  std::string box_mm;  ///< "--box-mm": "160x120x70" or "100" (a cube); empty: see side_mm.
  double side_mm = 0;  ///< "--side-mm": cube edge; 0 (and no box): fitted to the device.
};

/// Adds --grid, --box-mm and --side-mm to `command`.
void addGridOptions(CLI::App& command, GridOptions& options);

/// The grid `options` describe for `device`: an explicit box or cube centred on the workspace
/// centre, or by default the box fitted to the device's reachable workspace (at least 90 % of it
/// inside): what `simulation` reaches, or for a real device (`simulation` null) the sphere of its
/// specified workspace radius about the origin. `workspace_coverage` receives the fraction of the
/// reachable workspace inside the grid either way. Throws autograv::Error naming the option on a
/// malformed value.
WorkspaceGrid resolveGrid(const GridOptions& options, const HapticDevice& device,
                          const sim::SimulatedDevice* simulation, double& workspace_coverage);

/// Vertices per axis that `options.grid` asks for (5 per axis when empty). Throws autograv::Error
/// naming --grid on a malformed value.
Eigen::Vector3i gridResolution(const GridOptions& options);
/// True when no box was given: the grid is then fitted to the explored workspace.
inline bool gridFromWorkspace(const GridOptions& options) {
  return options.box_mm.empty() && !(options.side_mm > 0.0);
}

/// Every field of `parameters` with its SI unit in the key.
nlohmann::json parametersJson(const EstimationParameters& parameters);

}  // namespace autograv::cli
