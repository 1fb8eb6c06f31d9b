#pragma once

// What `autograv calibrate` shows of a finished calibration: the summary lines and the JSON report.

#include <cstdint>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/device/device_specifications.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/friction.h"
#include "autograv/sim/friction_measurement.h"
#include "autograv/sim/procedures.h"
#include "cli_support.h"

namespace autograv::cli {

/// What a finished calibration on a simulated device was run with, and the figures scored on it.
struct CalibrationOutcome {
  std::string map_path;                                        ///< Where the map was saved.
  std::uint64_t seed = 1;                                      ///< The device's seed.
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;  ///< The device's friction level.
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;    ///< How the servo ticks arrived.
  DeviceSpecifications specs;                                  ///< The device's.
  EstimationParameters parameters;                             ///< The calibration's.
  double wall_s = 0.0;                                         ///< Wall time of the run. Unit: [s]
  double workspace_coverage = 0.0;             ///< Reachable workspace inside the grid (0..1).
  sim::AccuracyReport accuracy{};              ///< At the measured points and 1000 random ones.
  sim::FieldErrorReport field{};               ///< Over the reachable workspace.
  sim::FrictionMeasurement device_friction{};  ///< Measured on a fresh copy of the device.
  std::uint64_t servo_timing_seed = 1;         ///< The draw of the loop's late ticks.
  MapAgreement agreement{};                    ///< How the map's measurements agree.
  sim::SimulatedUnit unit{};                   ///< Which unit of the model, its actuators.
  /// Each motor's delivered per commanded torque on that unit (ground truth, for the report).
  Eigen::Vector3d actuator_gains = Eigen::Vector3d::Ones();
  /// With motors that warm (unit.thermal): the hottest winding and housing when the map was
  /// saved, and the motors' lowest gain factor then (ground truth, for the report).
  /// Units: [degC], [degC], [-]
  std::optional<Eigen::Vector3d> motors_at_end = std::nullopt;
};

/// Prints the summary lines of the run `result` that made `map`, on standard output.
void printCalibrationOutcome(const CalibrationOutcome& outcome,
                             const sim::CalibrationRunResult& result, const GravityMap& map);

/// The JSON report of the same.
nlohmann::json calibrationReportJson(const CalibrationOutcome& outcome,
                                     const sim::CalibrationRunResult& result,
                                     const GravityMap& map);

}  // namespace autograv::cli
