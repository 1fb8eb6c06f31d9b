#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/sim/simulated_device.h"

namespace autograv::cli {

/// Opens a simulated device by name ("sim:omega", "sim:omni") with the given friction and calls
/// open() and calibrate(). Throws autograv::Error with the valid names for an unknown one.
std::unique_ptr<sim::SimulatedDevice> openSimulatedDevice(
    const std::string& name, std::uint64_t seed,
    sim::FrictionLevel friction = sim::FrictionLevel::kTypical);

/// Writes `report` as indented JSON, atomically (temporary file, then rename). Throws
/// autograv::Error naming the path when it cannot. An empty path writes nothing.
void writeJsonReport(const std::string& path, const nlohmann::json& report);

/// True when standard error is a terminal (progress bars redraw in place only then).
bool stderrIsTerminal();
/// Width of the terminal on standard error, or 80 when unknown.
int terminalColumns();

/// A one-line progress bar on standard error: redrawn in place on a terminal, printed at most every
/// few seconds as plain lines otherwise (logs and CI stay readable).
class ProgressBar {
 public:
  explicit ProgressBar(std::string label);
  /// `done` of `total` finished; `detail` is appended (e.g. "iter 7, delta 0.02 mm").
  void update(int done, int total, const std::string& detail);
  /// Ends the line.
  void finish();

 private:
  std::string label_;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_draw_;
  bool terminal_;
  bool drawn_ = false;
};

/// "1m 05s", "42s", "0.3s".
std::string formatDuration(double seconds);

}  // namespace autograv::cli
