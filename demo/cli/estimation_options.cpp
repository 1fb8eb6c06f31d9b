#include "estimation_options.h"

#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/workspace_fit.h"
#include "autograv/sim/procedures.h"

namespace autograv::cli {

namespace {

/// "A" or "AxBxC" into three positive numbers (A repeated for a single one). False on anything
/// else.
bool parseTriple(const std::string& text, Eigen::Vector3d& values) {
  std::vector<std::string> parts;
  std::string::size_type start = 0;
  while (true) {
    const auto x = text.find_first_of("xX", start);
    parts.push_back(text.substr(start, x == std::string::npos ? std::string::npos : x - start));
    if (x == std::string::npos) break;
    start = x + 1;
  }
  if (parts.size() != 1 && parts.size() != 3) return false;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(parts[i], &used);
    } catch (const std::exception&) {
      return false;
    }
    if (used != parts[i].size() || !std::isfinite(value) || !(value > 0.0)) return false;
    values[static_cast<int>(i)] = value;
  }
  if (parts.size() == 1) values.setConstant(values[0]);
  return true;
}

}  // namespace

void addGridOptions(CLI::App& command, GridOptions& options) {
  command.add_option("--grid", options.grid,
                     "Vertices per axis: 5, or 7x5x4 along x, y, z (default 5; 2-16 each)");
  auto* box = command.add_option(
      "--box-mm", options.box_mm,
      "Grid box extents [mm]: 160x120x70 along x, y, z, or one number for a cube (default: "
      "the box around the workspace the device explores before the grid run)");
  command
      .add_option("--side-mm", options.side_mm, "Grid edge of a cubic grid [mm] (as --box-mm N)")
      ->check(CLI::PositiveNumber)
      ->excludes(box);
}

Eigen::Vector3i gridResolution(const GridOptions& options) {
  if (options.grid.empty()) return Eigen::Vector3i::Constant(5);
  Eigen::Vector3d counts;
  if (!parseTriple(options.grid, counts) || (counts.array() != counts.array().round()).any() ||
      (counts.array() < 2.0).any() || (counts.array() > 16.0).any()) {
    throw Error("--grid: expected vertices per axis, 2 to 16, as N or NxNxN (e.g. 7x5x4), got \"" +
                options.grid + "\"");
  }
  return counts.cast<int>();
}

WorkspaceGrid resolveGrid(const GridOptions& options, const HapticDevice& device,
                          const sim::SimulatedDevice* simulation, double& workspace_coverage) {
  // A simulation knows what it reaches; a real device is taken as the sphere of its specified
  // workspace radius about the origin, where CHAI3D centres its positions.
  const double radius_m = device.specifications().workspace_radius_m;
  const Eigen::Vector3d sphere_center_m =
      simulation != nullptr ? simulation->workspaceCenter_m() : Eigen::Vector3d::Zero();
  const ReachabilityTest reachable = [&](const Eigen::Vector3d& position_m) {
    return simulation != nullptr ? simulation->isReachable(position_m)
                                 : (position_m - sphere_center_m).norm() <= radius_m;
  };
  const Eigen::Vector3i resolution = gridResolution(options);
  Eigen::Vector3d size_m;
  const Eigen::Vector3d center_m = sphere_center_m;
  if (!options.box_mm.empty()) {
    Eigen::Vector3d size_mm;
    if (!parseTriple(options.box_mm, size_mm)) {
      throw Error(
          "--box-mm: expected positive extents in mm as N or XxYxZ (e.g. 160x120x70), got \"" +
          options.box_mm + "\"");
    }
    size_m = size_mm * 1e-3;
  } else if (options.side_mm > 0.0) {
    size_m.setConstant(options.side_mm * 1e-3);
  } else {
    const WorkspaceFit fit = simulation != nullptr
                                 ? sim::fitGridToDevice(*simulation)
                                 : fitWorkspaceBox(reachable, sphere_center_m, radius_m);
    workspace_coverage = fit.workspace_coverage;
    return WorkspaceGrid(fit.center_m, fit.size_m, resolution);
  }
  const WorkspaceGrid grid(center_m, size_m, resolution);
  workspace_coverage = simulation != nullptr
                           ? sim::deviceWorkspaceCoverage(*simulation, grid)
                           : workspaceCoverage(grid, reachable, sphere_center_m, radius_m);
  return grid;
}

nlohmann::json parametersJson(const EstimationParameters& p) {
  return nlohmann::json::parse(parametersToJson(p));  // the map file's own encoding
}

}  // namespace autograv::cli
