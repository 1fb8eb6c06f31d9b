#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/estimation_parameters.h"

namespace autograv::cli {

/// Adds --alpha, --beta, --k0, --n-s, --eps-s, --n-g, --eps-g, --max-iterations to `command`,
/// in the paper's units (N/mm, mm/s, grams-force) and writing SI values into `parameters`.
void addEstimationOptions(CLI::App& command, EstimationParameters& parameters);

/// Every field of `parameters` with its SI unit in the key.
nlohmann::json parametersJson(const EstimationParameters& parameters);

}  // namespace autograv::cli
