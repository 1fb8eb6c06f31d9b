#pragma once

// What `autograv session` writes: its JSON report and its curves.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autograv/sim/actuators.h"
#include "autograv/sim/session_workload.h"

namespace autograv::cli {

/// One session's scores, minute by minute, with the unit's conditions and its force accounting.
nlohmann::json sessionJson(const sim::SessionWorkloadResult& result,
                           const sim::SimulatedUnit& unit);

/// The sessions' field p90 and p99, hottest winding and lowest gain factor over the minutes, one
/// line per session named by `names`, to a PNG at `path`. Needs a display (VTK). Throws
/// autograv::Error when autograv was built without its plots.
void plotSessions(const std::string& path, const std::vector<sim::SessionWorkloadResult>& runs,
                  const std::vector<std::string>& names, const std::string& device);

}  // namespace autograv::cli
