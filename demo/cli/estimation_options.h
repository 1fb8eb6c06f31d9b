#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/device_specifications.h"
#include "autograv/estimation_parameters.h"

namespace autograv::cli {

/// Adds --alpha, --beta, --k0, --n-s, --eps-s, --n-g, --eps-g, --max-iterations to `command`,
/// in the paper's units (N/mm, mm/s, grams-force) and writing SI values into `parameters`.
void addEstimationOptions(CLI::App& command, EstimationParameters& parameters);

/// Fills in what depends on the device and was not given on the command line: k0 (see
/// defaultInitializationStiffness). Call after parsing, once the device is open.
void applyDeviceDefaults(const CLI::App& command, EstimationParameters& parameters,
                         const DeviceSpecifications& specifications);

/// Every field of `parameters` with its SI unit in the key.
nlohmann::json parametersJson(const EstimationParameters& parameters);

}  // namespace autograv::cli
