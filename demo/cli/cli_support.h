#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/device/real_time_priority.h"
#include "autograv/devices/device_registry.h"
#include "autograv/map/field_fit.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/simulated_device.h"
#include "sim/experiments.h"

namespace autograv::cli {

/// Opens a simulated device by name ("sim:omega", "sim:omni") with the given friction and calls
/// open() and calibrate(). Throws autograv::Error with the valid names for an unknown one.
using sim::openSimulatedDevice;

/// [x, y, z] of a 3-vector, as every JSON report writes one.
template <typename Scalar>
nlohmann::json vectorJson(const Eigen::Matrix<Scalar, 3, 1>& vector) {
  return {vector.x(), vector.y(), vector.z()};
}

/// A grid in a JSON report: its resolution, size_m and center_m.
nlohmann::json gridJson(const WorkspaceGrid& grid);

/// The device of every command that takes --device and is not given one: the paper's device, the
/// one autograv-demo simulates by default, and the quickest simulated calibration; the same
/// everywhere, so that `autograv calibrate --out m.json` then `autograv verify m.json` (or check,
/// retare) run on the device the map was made for.
inline constexpr const char* kDefaultDevice = "sim:omega";

/// How every command names its device: adds `--device` (sim:omni, sim:omega, chai3d:N; checked when
/// the device is opened, since CHAI3D's devices are only known then), kDefaultDevice by default
/// (`device` is set to it).
CLI::Option* addDeviceOption(CLI::App& command, std::string& device);

/// A point load and a tilt for simulated devices (`--payload-g`, `--tilt-deg`), to test against
/// the truth what a handle change or a moved device does to a map.
struct SimulatedLoad {
  double payload_g = 0.0;
  double tilt_deg = 0.0;
};
void addSimulatedLoadOptions(CLI::App& command, SimulatedLoad& load);

/// Which simulated unit a command runs on (`--unit N`, `--actuators ideal|typical|high`): the same
/// unit has the same actuators whatever `--seed` draws.
void addSimulatedUnitOptions(CLI::App& command, sim::SimulatedUnit& unit);
/// Applies `load` to the simulation behind `device`; throws autograv::Error when one is asked for
/// on a device that is not simulated.
void applySimulatedLoad(const DeviceHandle& device, const SimulatedLoad& load);
void applySimulatedLoad(sim::SimulatedDevice& device, const SimulatedLoad& load);

/// `--device` for commands that run on a simulated device only: one of simulatedDeviceNames(),
/// kDefaultDevice by default.
CLI::Option* addSimulatedDeviceOption(CLI::App& command, std::string& device);

/// `--report PATH`: where a command writes its JSON report (writeJsonReport).
CLI::Option* addReportOption(CLI::App& command, std::string& report_path);

/// A --device check for commands that need a simulation (no person in the loop): accepts
/// sim::simulatedDeviceNames() and says what to use instead for any other device.
CLI::Validator simulatedOnly(const std::string& command);

/// Adds `--maps DIR`: the map library's folder (default: $XDG_DATA_HOME/autograv/maps).
void addMapsOption(CLI::App& command, std::string& maps_dir);

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

/// Prints the field error over the workspace and within 5 mm of the stops, two report lines.
void printFieldError(const sim::FieldErrorReport& field);

/// Adds the field error to a JSON report: field_samples, field_error_{p50,p90,p99,max}_rel and
/// the same with shell_ for the points near the stops.
void addFieldErrorJson(nlohmann::json& report, const sim::FieldErrorReport& field);

/// How a map's measurements agree with one another (measurementAgreement), judged once for what
/// a command prints and reports: the agreement, or why the measurements cannot be judged.
struct MapAgreement {
  std::optional<MeasurementAgreement> agreement;
  std::string unavailable;  ///< Why not, when agreement is empty.
};
MapAgreement judgeAgreement(const GravityMap& map);

/// The same as the commands print it: `summary` "median ... %, 90th percentile ... %, largest
/// ... % of |G_hat|" (or why not), `least_sure` the vertices where more measurements would help
/// most, with their points, or that every measurement agrees (empty when not judged).
struct AgreementText {
  std::string summary;
  std::string least_sure;
  std::string field_model;                ///< describeFieldModel
  std::vector<std::string> model_scores;  ///< describeFieldModelScores
};
AgreementText describeAgreement(const GravityMap& map, const MapAgreement& judged);

/// Prints the field model and its candidates' scores, then `text` as two summary lines under
/// `label`, as calibrate and wizard show their figures.
void printAgreement(const char* label, const AgreementText& text);

/// Adds the agreement to a JSON report: leave_one_out_{median,p90,max}_rel and
/// least_sure_vertices, or leave_one_out_unavailable with the reason.
void addAgreementJson(nlohmann::json& report, const MapAgreement& judged);

/// The map's field model as the commands print it: "corrected (curl weight 0.3), chosen from
/// the measurements by leave-one-out" or "conservative (given)", with the thin plate's fallback.
std::string describeFieldModel(const GravityMap& map);
/// One line per candidate: "conservative  leave-one-out median 0.21 %, 90th percentile 1.55 %,
/// mean 0.86 %" (of |G_hat|). Empty when the model was given, not chosen.
std::vector<std::string> describeFieldModelScores(const std::vector<FieldModelScore>& scores);
/// Adds field_model, field_model_curl_weight and field_model_scores (each candidate's name,
/// curl weight and leave-one-out median, p90 and rms over |G_hat|) to a JSON report.
void addFieldModelJson(nlohmann::json& report, const GravityMap& map);
/// One line per measurement the calibration measured again because the others contradicted it
/// (MapMetadata::reviewed_measurements): where, how far off, where measured again, and whether
/// it was kept or left out of the fit.
std::vector<std::string> describeReviewedMeasurements(
    const std::vector<ReviewedMeasurement>& reviewed);
/// Adds measured_again, left_out and reviewed_measurements (each one's vertex, points and
/// leave-one-out figures over |G_hat|), and the thermal drift's thermal_drift_points,
/// thermal_drift_rel, thermal_gain_loss_per_load (+ _standard_error), thermal_load_first and
/// thermal_load_again, to a JSON report.
void addReviewedJson(nlohmann::json& report, const GravityMap& map);
/// One line on what a calibration saw of its motors warming (MapMetadata::thermal_drift).
std::string describeThermalDrift(const ThermalDrift& drift);

/// For a servo loop on hardware: raises the calling thread, which is about to run the loop, to
/// real-time priority where the system permits (enterRealTimePriority) and says on stderr what to
/// do when it does not. None for a simulation, whose loop keeps simulated time.
std::optional<RealTimePriority> enterServoPriority(const DeviceHandle& device);
/// The stderr line for a servo thread that was refused real-time priority; nothing otherwise.
void warnIfNormalPriority(const RealTimePriority& priority);
/// servo_real_time_priority and servo_priority, when the loop ran on hardware.
void addServoPriorityJson(nlohmann::json& report, const std::optional<RealTimePriority>& priority);

}  // namespace autograv::cli
