#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "autograv/error.h"
#include "autograv/sim/actuators.h"
#include "autograv/sim/delta_device.h"
#include "autograv/sim/motor_thermal.h"
#include "autograv/sim/point_mass_device.h"
#include "autograv/sim/serial_arm_device.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

std::vector<std::string> simulatedDeviceNames() { return {"sim:omega", "sim:omni", "sim:falcon"}; }

std::vector<std::string> testDeviceNames() {
  return {"sim:swirl-cube", "sim:swirl-ellipsoid", "sim:falcon-can"};
}

namespace {

/// `parameters` with the actuators of `unit` of the model `name`, and its serial number: the
/// model's "...-0001" ends in the unit's number, so that each unit files its own map.
template <typename Parameters>
Parameters ofUnit(Parameters parameters, const std::string& name, const SimulatedUnit& unit) {
  parameters.driver.actuator_gain = actuatorGains(name, unit);
  parameters.driver.homing_offset_counts = homingOffsetCounts(name, unit.number, unit.session);
  parameters.driver.thermal = unit.thermal;
  if (unit.thermal.enabled) parameters.driver.motor_thermal = motorThermalParameters(name);
  std::string& serial = parameters.specifications.serial_number;
  const std::size_t dash = serial.rfind('-');
  if (dash != std::string::npos) {
    char number[16];
    std::snprintf(number, sizeof number, "%04d", unit.number);
    serial = serial.substr(0, dash + 1) + number;
  }
  return parameters;
}

}  // namespace

std::unique_ptr<SimulatedDevice> makeSimulatedDevice(const std::string& name, std::uint64_t seed,
                                                     FrictionLevel friction,
                                                     const SimulatedUnit& unit) {
  if (name == "sim:omega") {
    return std::make_unique<PointMassDevice>(ofUnit(omegaParameters(friction), name, unit), seed);
  }
  if (name == "sim:omni") {
    return std::make_unique<SerialArmDevice>(ofUnit(omniParameters(friction), name, unit), seed);
  }
  if (name == "sim:falcon") {
    return std::make_unique<DeltaDevice>(ofUnit(falconParameters(friction), name, unit), seed);
  }
  if (name == "sim:swirl-cube") {
    return std::make_unique<PointMassDevice>(ofUnit(swirlCubeParameters(friction), name, unit),
                                             seed);
  }
  if (name == "sim:swirl-ellipsoid") {
    return std::make_unique<PointMassDevice>(ofUnit(swirlEllipsoidParameters(friction), name, unit),
                                             seed);
  }
  if (name == "sim:falcon-can") {
    return std::make_unique<DeltaDevice>(ofUnit(falconCanParameters(friction), name, unit), seed);
  }
  std::string valid;
  for (const auto& known : simulatedDeviceNames()) valid += (valid.empty() ? "" : ", ") + known;
  for (const auto& known : testDeviceNames()) valid += ", " + known;
  throw Error("unknown simulated device '" + name + "'; valid names: " + valid);
}

}  // namespace autograv::sim
