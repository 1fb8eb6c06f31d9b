#include "autograv/sim/motor_thermal.h"

#include <cmath>
#include <string>

#include "autograv/error.h"
#include "autograv/sim/simulated_driver.h"
#include "sim/unit_seed.h"

namespace autograv::sim {

namespace {

/// The model whose motors a test device carries (as actuators.cpp's actuatorModel).
std::string motorModel(const std::string& model) {
  if (model == "sim:falcon-can") return "sim:falcon";
  if (model == "sim:swirl-cube" || model == "sim:swirl-ellipsoid") return "sim:omega";
  return model;
}

[[noreturn]] void refuseModel(const std::string& model, const char* what) {
  throw Error(std::string("no ") + what + " for '" + model +
              "'; known models: sim:omega, sim:omni, sim:falcon");
}

bool finitePositive(double value) noexcept { return std::isfinite(value) && value > 0.0; }

}  // namespace

const char* toString(MotorDrive drive) noexcept {
  return drive == MotorDrive::kVoltage ? "voltage" : "current";
}

MotorThermalParameters motorThermalParameters(const std::string& model) {
  const std::string motors = motorModel(model);
  if (motors == "sim:omni" || motors == "sim:omega") {
    // A 25 mm precision coreless DC motor with NdFeB magnets, the class of both devices' motors:
    // maxon's RE 25 catalogue page (graphite brushes, 20 W), thermal data: 3.1 K/W winding to
    // housing, 14 K/W housing to ambient, 12.5 s winding and 612 s motor time constants, +125 C
    // largest winding temperature, which its nominal current reaches at 25 C ambient (a 100 K
    // rise). The Omega's motors are larger: their slower heating is left out, which makes the
    // simulator harder, not easier. Magnets: NdFeB remanence -0.12 %/K (sintered NdFeB grades'
    // reversible coefficient, -0.11 to -0.13 %/K). Both amplifiers drive a current (ASSUMED:
    // precision devices close a current loop, as the omega's published electronics and the
    // Omni's PCI/FireWire amplifiers do; neither publishes its schematic).
    // K/W winding-housing and housing-ambient, s winding and motor, K rise, 1/K magnet and
    // copper, drive: the fields in MotorThermalParameters' order.
    return {3.1, 14.0, 12.5, 612.0, 100.0, -0.0012, 0.00393, MotorDrive::kCurrent};
  }
  if (motors == "sim:falcon") {
    // A low-cost iron-core brushed motor with ferrite magnets. Published for that class (Philips/
    // Airpax 4 W DC motor 9904 120 524xx, product specification, thermal data): EMF (torque
    // constant) -0.2 %/K, resistance +0.4 %/K, 30 K/W winding to housing, 30 min motor time
    // constant. ASSUMED: 45 K/W housing to ambient (1.5 times the winding's, as the RE 25's
    // ratio of housing to winding resistance is larger still: a conservative split), a 60 s
    // winding time constant (an iron-core rotor holds more heat than a coreless winding), an 80 K
    // largest rise (insulation class E, 120 C, at 40 C ambient), and a voltage drive: a low-cost
    // H-bridge without current sensing, so the rising resistance lowers the current too.
    return {30.0, 45.0, 60.0, 1800.0, 80.0, -0.002, 0.004, MotorDrive::kVoltage};
  }
  refuseModel(model, "motor thermal figures");
}

MotorThermalModel::MotorThermalModel(const MotorThermalParameters& motor,
                                     const Eigen::Vector3d& rated_command,
                                     const ThermalConditions& conditions)
    : motor_(motor), ambient_c_(conditions.ambient_c), reference_c_(conditions.reference_c) {
  if (!finitePositive(motor.winding_to_housing_k_per_w) ||
      !finitePositive(motor.housing_to_ambient_k_per_w) ||
      !finitePositive(motor.winding_time_constant_s) ||
      !finitePositive(motor.housing_time_constant_s) ||
      !finitePositive(motor.rated_winding_rise_k)) {
    throw Error(
        "motor thermal model: thermal resistances, time constants and the rated rise "
        "must be finite and > 0");
  }
  if (!std::isfinite(motor.magnet_coefficient_per_k) ||
      !std::isfinite(motor.resistance_coefficient_per_k) ||
      std::abs(motor.magnet_coefficient_per_k) > 0.01 ||
      std::abs(motor.resistance_coefficient_per_k) > 0.01) {
    throw Error("motor thermal model: temperature coefficients must lie within +/-1 %/K");
  }
  if (!rated_command.allFinite() || (rated_command.array() <= 0.0).any()) {
    throw Error("motor thermal model: the rated command must be finite and > 0 on every motor");
  }
  for (const double temperature_c :
       {conditions.ambient_c, conditions.start_c, conditions.reference_c}) {
    if (!std::isfinite(temperature_c) || temperature_c < -40.0 || temperature_c > 100.0) {
      throw Error("motor thermal model: temperatures must lie in [-40, 100] C, got " +
                  std::to_string(temperature_c));
    }
  }
  const double total_k_per_w = motor.winding_to_housing_k_per_w + motor.housing_to_ambient_k_per_w;
  // The heat at the rated command, with the resistance at the rated rise: a current drive's
  // I^2 R grows with R, a voltage drive's V^2 / R falls with it.
  const double rise_k = motor.rated_winding_rise_k;
  const double resistance_ratio = 1.0 + motor.resistance_coefficient_per_k * rise_k;
  const double rated_heat_w = rise_k / total_k_per_w;
  const double heat_at_reference_w = motor.drive == MotorDrive::kCurrent
                                         ? rated_heat_w / resistance_ratio
                                         : rated_heat_w * resistance_ratio;
  heat_per_command2_ = (rated_command.cwiseProduct(rated_command))
                           .cwiseInverse()
                           .cwiseProduct(Eigen::Vector3d::Constant(heat_at_reference_w));
  winding_capacity_j_per_k_ = motor.winding_time_constant_s / motor.winding_to_housing_k_per_w;
  housing_capacity_j_per_k_ = motor.housing_time_constant_s / motor.housing_to_ambient_k_per_w;
  setTemperature_c(conditions.start_c);
}

void MotorThermalModel::setTemperature_c(double temperature_c) noexcept {
  winding_c_.setConstant(temperature_c);
  housing_c_.setConstant(temperature_c);
  updateGain();
}

void MotorThermalModel::step(double dt_s, const Eigen::Vector3d& motor_command) noexcept {
  if (!(dt_s > 0.0)) return;
  for (int motor = 0; motor < 3; ++motor) {
    const double resistance_ratio =
        1.0 + motor_.resistance_coefficient_per_k * (winding_c_[motor] - reference_c_);
    const double command2 = motor_command[motor] * motor_command[motor];
    const double heat_w =
        heat_per_command2_[motor] * command2 *
        (motor_.drive == MotorDrive::kCurrent ? resistance_ratio : 1.0 / resistance_ratio);
    const double to_housing_w =
        (winding_c_[motor] - housing_c_[motor]) / motor_.winding_to_housing_k_per_w;
    const double to_air_w = (housing_c_[motor] - ambient_c_) / motor_.housing_to_ambient_k_per_w;
    winding_c_[motor] += dt_s * (heat_w - to_housing_w) / winding_capacity_j_per_k_;
    housing_c_[motor] += dt_s * (to_housing_w - to_air_w) / housing_capacity_j_per_k_;
    heat_w_[motor] = heat_w;
  }
  updateGain();
}

void MotorThermalModel::updateGain() noexcept {
  for (int motor = 0; motor < 3; ++motor) {
    const double magnet =
        1.0 + motor_.magnet_coefficient_per_k * (housing_c_[motor] - reference_c_);
    const double resistance_ratio =
        1.0 + motor_.resistance_coefficient_per_k * (winding_c_[motor] - reference_c_);
    gain_factor_[motor] = motor_.drive == MotorDrive::kCurrent ? magnet : magnet / resistance_ratio;
  }
}

double homingRepeatabilityCounts(const std::string& model) {
  const std::string motors = motorModel(model);
  // ASSUMED, none is published. The Omni homes in its inkwell: the stylus seats in a cup with
  // about a millimetre of play, +/-8 counts of its 15,360 per joint turn (about +/-0.4 mm at the
  // tip per joint). The Falcon homes its arms against their limits: +/-6 counts of its 9,881
  // (about +/-0.4 mm at the grip). The omega.3 is calibrated against a mechanical reference
  // pose: +/-10 counts of 10 um (+/-0.1 mm).
  if (motors == "sim:omni") return 8.0;
  if (motors == "sim:falcon") return 6.0;
  if (motors == "sim:omega") return 10.0;
  refuseModel(model, "homing repeatability");
}

Eigen::Vector3d homingOffsetCounts(const std::string& model, int unit_number, int session) {
  const double bound = homingRepeatabilityCounts(model);
  if (unit_number < 1 || session < 1) {
    throw Error("homing offset: units and sessions are numbered from 1 (unit " +
                std::to_string(unit_number) + ", session " + std::to_string(session) + ")");
  }
  if (session == 1) return Eigen::Vector3d::Zero();
  // "homing" mixed in: not the actuator gains' stream of the same unit.
  Random random(unitSeed(motorModel(model), {unit_number, session}) ^ 0x686f6d696e67ULL);
  Eigen::Vector3d offset;
  for (int joint = 0; joint < 3; ++joint) offset[joint] = bound * (2.0 * random.uniform() - 1.0);
  return offset;
}

}  // namespace autograv::sim
