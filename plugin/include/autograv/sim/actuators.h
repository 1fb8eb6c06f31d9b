#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/sim/motor_thermal.h"

namespace autograv::sim {

/// How far a simulated unit's actuators stray from nominal. A motor delivers its command times a
/// gain: its torque constant, its amplifier's gain and its transmission ratio, each off nominal
/// by the manufacturer's tolerance. kIdeal delivers exactly the command (every gain 1); kTypical
/// draws each gain within the published tolerances of its class of motor, amplifier and
/// transmission (actuatorGainBound); kHigh within twice them (a worn or hot unit, a substituted
/// part).
enum class ActuatorTolerance : std::uint8_t { kIdeal, kTypical, kHigh };

/// "ideal", "typical" or "high". Real-time safe.
const char* toString(ActuatorTolerance tolerance) noexcept;
/// Every tolerance's name, from ideal to high.
std::vector<std::string> actuatorToleranceNames();
/// Inverse of toString. Throws autograv::Error listing the valid names for any other text.
ActuatorTolerance parseActuatorTolerance(const std::string& name);

/// The unit a simulated device stands for (its number and how far its actuators stray), and the
/// session and room it is used in. The same unit has the same actuators, and the same session the
/// same homing, whatever seed draws its sensor noise and its servo loop's timing.
struct SimulatedUnit {
  /// Which physical unit of the model (1, 2, ...). Unit 1 is the one every published figure is
  /// measured on.
  int number = 1;
  /// How far its actuators stray from nominal.
  ActuatorTolerance actuators = ActuatorTolerance::kTypical;
  /// The session (1, 2, ...): each one homes the unit again, within its model's repeatability
  /// (homingOffsetCounts); session 1 is the homing every published map was made in.
  int session = 1;
  /// Whether its motors warm as they hold forces, the room, and where the motors start
  /// (MotorThermalModel). Off by default: the devices of autograv 0.3, bit for bit.
  ThermalConditions thermal = {};
};

/// Largest relative gain error of one actuator chain of `model` ("sim:omni", "sim:falcon",
/// "sim:omega") at `tolerance`: the bound within which actuatorGains draws (0 for kIdeal). Throws
/// autograv::Error for an unknown model. The sources of each figure are beside it in the .cpp.
double actuatorGainBound(const std::string& model, ActuatorTolerance tolerance);

/// Each motor's delivered torque (or force) per commanded one for `unit` of `model`: 1 +/- at
/// most actuatorGainBound, drawn from the model's name and the unit's number alone (never from a
/// noise seed), so the same unit is the same hardware in every run. All ones at kIdeal. A test
/// device built on a model's mechanism and motors ("sim:falcon-can" on "sim:falcon") draws as
/// that model does: its unit N has the model's unit N's gains. Throws autograv::Error for an
/// unknown model or a unit number below 1.
Eigen::Vector3d actuatorGains(const std::string& model, const SimulatedUnit& unit);

}  // namespace autograv::sim
