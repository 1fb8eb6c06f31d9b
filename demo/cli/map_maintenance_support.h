#pragma once

// What `autograv retare` and `autograv check` share: the device, the map it should fit, and the
// estimation parameters for a few vertices of that map.

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "advanced_options.h"
#include "autograv/device/real_time_priority.h"
#include "autograv/devices/device_registry.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/map/gravity_map.h"
#include "cli_support.h"

namespace autograv::cli {

struct MaintenanceOptions {
  std::string device;
  std::string map_path;  ///< Empty: the device's map in the library.
  std::string maps_dir;
  std::string report_path;
};

/// --device, --maps and --report; and takes the simulated device's options (--seed, --friction,
/// --unit, --actuators, --payload-g, --tilt-deg) and the estimation options of `advanced`.
void addMaintenanceOptions(CLI::App& command, MaintenanceOptions& options,
                           AdvancedOptions& advanced);

struct MaintenanceSetup {
  DeviceHandle device;              ///< Open and homed, with the simulated load applied.
  GravityMap map;                   ///< The map to check or re-tare.
  std::string map_path;             ///< Where it came from.
  EstimationParameters parameters;  ///< The command line's, with the device's defaults.
  /// What the calling thread, the servo loop's, got on hardware; none for a simulation.
  std::optional<RealTimePriority> servo_priority;
};

/// Opens the device (simulated ones as `advanced` describes them) and finds its map (the file
/// given, else the library's), and on hardware raises the calling thread, which runs the servo
/// loop, to real-time priority where permitted. Throws autograv::Error when the device or the map
/// fails, saying what to do.
MaintenanceSetup openForMaintenance(const MaintenanceOptions& options,
                                    const AdvancedOptions& advanced);

/// Largest |a - b| / |b| over the vertices of two maps on the same grid; throws autograv::Error
/// when the grids differ.
double maxVertexDifferenceRel(const GravityMap& a, const GravityMap& b);

}  // namespace autograv::cli
