#pragma once
// `autograv calibrate --like MAP`: a simulated unit's map corrected from another unit's.

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "autograv/maintenance/unit_transfer.h"
#include "autograv/map/gravity_map.h"

namespace autograv::cli {

/// The word `--like` takes instead of a path: the map library's newest map of another unit of
/// the device's model (MapLibrary::findOtherUnit).
inline constexpr const char* kLikeLibrary = "library";

/// Adds `--like MAP` to `command`, which must already have --resume and the grid options: none of
/// them means anything for a corrected map, so each is refused beside it.
CLI::Option* addLikeOption(CLI::App& command, std::string& like);

/// The report keys a correction has on either command: accepted, the device time, the points,
/// the correction and its scores, the check, the workspace check and the forces sent.
nlohmann::json transferReportJson(const TransferResult& result);

/// Loads the prior `like` names (a path, or kLikeLibrary with `maps_dir`, empty for the default
/// folder) for a device of `model` and serial `serial`, and checks it against that model
/// (checkTransferPrior) before anything moves. Throws autograv::Error saying what to do instead.
GravityMap loadPrior(const std::string& like, const std::string& maps_dir, const std::string& model,
                     const std::string& serial, const TransferOptions& options,
                     std::string& source);

/// Prints what transferMap measured and chose, a line each, in the calibrate report's layout.
void printTransfer(const TransferResult& result);

/// Corrects the map `like` names to the simulated device `device` (with `advanced`'s simulation
/// and estimation knobs), saves it to `out_path`, scores it against the simulator's truth, and
/// writes the JSON report to `report_path` (none when empty). Throws autograv::Error, saving
/// nothing, when the correction is refused.
void runCalibrateLike(const std::string& device, const std::string& like,
                      const std::string& out_path, const std::string& report_path,
                      const AdvancedOptions& advanced);

}  // namespace autograv::cli
