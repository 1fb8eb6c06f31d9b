#pragma once

// How `autograv bench` shows a friction sweep: the table, its JSON and its plot.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sim/experiments.h"

namespace autograv::cli {

/// The JSON of a calibration's figures shared by every bench table: convergence, iterations, time
/// per vertex and the worst vertex's error.
nlohmann::json calibrationFiguresJson(const sim::CalibrationFigures& figures);

/// True for the sweep of --methods (several methods side by side), false for --friction-sweep.
inline bool comparesMethods(const sim::FrictionSweepOptions& sweep) {
  return sweep.methods.size() > 1;
}

/// Prints the folded rows of a sweep run with `sweep` as a table, and puts them in `report` under
/// "methods" or "friction_sweep".
void printFrictionSweep(const std::vector<sim::SweepRow>& rows,
                        const sim::FrictionSweepOptions& sweep, nlohmann::json& report);

/// The sweep as four panels over the friction levels, one line per device (and method, when the
/// sweep compares methods), written to the PNG `path`. Throws autograv::Error in a build without
/// the viz library.
void plotFrictionSweep(const std::vector<sim::SweepRow>& rows,
                       const sim::FrictionSweepOptions& sweep, const std::string& path);

}  // namespace autograv::cli
