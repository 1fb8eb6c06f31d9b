#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/device/device_specifications.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv::cli {

/// Resets `parameters` to the defaults of `default_method` (EstimationParameters{} for the paper's,
/// frictionRobust() for the dither method) and adds --method, --alpha, --beta, --k0, --n-s,
/// --eps-s, --n-g, --eps-g, --max-iterations and --dither-mn to `command`, in the paper's units
/// (N/mm, mm/s, grams-force, mN) and writing SI values into `parameters`.
void addEstimationOptions(CLI::App& command, EstimationParameters& parameters,
                          EstimationMethod default_method = EstimationMethod::kDither);

/// Adds --grid (vertices per axis, 2-16) and --side-mm (grid edge) to `command`; 0 in either
/// stands for the default: 5 per axis, and defaultGridSide_m of the device's workspace.
void addGridOptions(CLI::App& command, int& grid, double& side_mm);

/// Fills in what depends on the device or the method and was not given on the command line: k0
/// (see defaultInitializationStiffness) and n_G (5 for the paper's method, 3 for the dither
/// method). Call after parsing, once the device is open.
void applyDeviceDefaults(const CLI::App& command, EstimationParameters& parameters,
                         const DeviceSpecifications& specifications);

/// Every field of `parameters` with its SI unit in the key.
nlohmann::json parametersJson(const EstimationParameters& parameters);

}  // namespace autograv::cli
