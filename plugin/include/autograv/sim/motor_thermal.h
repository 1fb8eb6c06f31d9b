#pragma once

// Motors that warm: what holding gravity does to a simulated device over minutes and hours.

#include <cstdint>
#include <string>

#include <Eigen/Core>

namespace autograv::sim {

/// How a motor's amplifier drives it. A current loop sets the winding's current from the
/// command, so only the magnet's weakening changes the torque per command; a voltage drive (PWM
/// with no current sense) sets the voltage, so the winding's rising resistance lowers the current
/// as well.
enum class MotorDrive : std::uint8_t { kCurrent, kVoltage };

/// "current" or "voltage". Real-time safe.
const char* toString(MotorDrive drive) noexcept;

/// The thermal figures of one motor of a model: two nodes, the winding and the housing (with the
/// magnet), each a heat capacity behind a thermal resistance, as motor catalogues give them.
struct MotorThermalParameters {
  /// Thermal resistance from the winding to the housing. Unit: [K/W]
  double winding_to_housing_k_per_w = 3.1;
  /// Thermal resistance from the housing to the ambient air. Unit: [K/W]
  double housing_to_ambient_k_per_w = 14.0;
  /// The winding's own time constant (its heat capacity times winding_to_housing). Unit: [s]
  double winding_time_constant_s = 12.5;
  /// The whole motor's time constant (the housing's heat capacity times housing_to_ambient).
  /// Unit: [s]
  double housing_time_constant_s = 612.0;
  /// Winding temperature rise at the device's continuous force rating, in steady state: the
  /// rating is by definition the force at which the motors reach their largest allowed rise.
  /// Unit: [K]
  double rated_winding_rise_k = 100.0;
  /// Relative change of the torque constant per kelvin of the magnet (at the housing's
  /// temperature): NdFeB about -0.0012, ferrite about -0.002. Unit: [1/K]
  double magnet_coefficient_per_k = -0.0012;
  /// Relative change of the winding's resistance per kelvin: copper, +0.00393 (IEC 60028).
  /// Unit: [1/K]
  double resistance_coefficient_per_k = 0.00393;
  /// Current or voltage drive.
  MotorDrive drive = MotorDrive::kCurrent;
};

/// The thermal figures of the motors of `model` ("sim:omni", "sim:falcon", "sim:omega"; the test
/// devices take those of the model whose motors they carry). The source of each figure is beside
/// it in the .cpp and in docs/simulator-sources.md. Throws autograv::Error for an unknown model.
MotorThermalParameters motorThermalParameters(const std::string& model);

/// Where a simulated device's motors start and the air around them.
struct ThermalConditions {
  /// Whether the motors warm at all. Off: every motor delivers its unit's gain at every moment,
  /// the devices of autograv 0.3 bit for bit.
  bool enabled = false;
  /// The air around the device. Unit: [degC]
  double ambient_c = 22.0;
  /// Windings and housings at the start (a device that was just used starts warm). Unit: [degC]
  double start_c = 22.0;
  /// The temperature at which the unit's actuator gains hold (the factory's, and the room of
  /// every published figure): at another one the torque per command differs. Unit: [degC]
  double reference_c = 22.0;
};

/// The default ambient and reference temperature. Unit: [degC]
inline constexpr double kReferenceAmbient_c = 22.0;

/// Three motors' winding and housing temperatures, heated by each motor's own I^2 R and cooled to
/// the ambient air, and what the temperatures make of each motor's torque per command. Stepped
/// by the simulated driver at its internal rate. Allocation-free: real-time safe.
class MotorThermalModel {
 public:
  /// A model that never warms (gain factors all 1).
  MotorThermalModel() = default;
  /// Motors of `motor` in `conditions`, whose heat at `rated_command` (each motor's command at
  /// the device's continuous force rating, in actuator units) reaches the rated rise in steady
  /// state. Throws autograv::Error for non-finite or non-positive figures.
  MotorThermalModel(const MotorThermalParameters& motor, const Eigen::Vector3d& rated_command,
                    const ThermalConditions& conditions);

  /// Advances the temperatures by `dt_s` under the motor commands `motor_command` (actuator
  /// units, held over the step). Real-time safe. Unit: [s]
  void step(double dt_s, const Eigen::Vector3d& motor_command) noexcept;

  /// Each motor's torque per command against the reference temperature (1 when it is there).
  /// Real-time safe.
  const Eigen::Vector3d& gainFactor() const noexcept { return gain_factor_; }
  /// Winding temperatures. Real-time safe. Unit: [degC]
  const Eigen::Vector3d& winding_c() const noexcept { return winding_c_; }
  /// Housing (and magnet) temperatures. Real-time safe. Unit: [degC]
  const Eigen::Vector3d& housing_c() const noexcept { return housing_c_; }
  /// Heat each winding makes now. Real-time safe. Unit: [W]
  const Eigen::Vector3d& heat_w() const noexcept { return heat_w_; }
  /// Sets windings and housings to `temperature_c` (a device left to cool, or one warmed by an
  /// earlier session). Real-time safe. Unit: [degC]
  void setTemperature_c(double temperature_c) noexcept;
  /// The ambient air from now on. Real-time safe. Unit: [degC]
  void setAmbient_c(double ambient_c) noexcept { ambient_c_ = ambient_c; }
  /// The ambient air. Unit: [degC]
  double ambient_c() const noexcept { return ambient_c_; }

 private:
  void updateGain() noexcept;

  MotorThermalParameters motor_;
  double ambient_c_ = kReferenceAmbient_c;
  double reference_c_ = kReferenceAmbient_c;
  /// Heat per squared command at the reference temperature, per motor. Unit: [W per unit^2]
  Eigen::Vector3d heat_per_command2_ = Eigen::Vector3d::Zero();
  double winding_capacity_j_per_k_ = 1.0;
  double housing_capacity_j_per_k_ = 1.0;
  Eigen::Vector3d winding_c_ = Eigen::Vector3d::Constant(kReferenceAmbient_c);
  Eigen::Vector3d housing_c_ = Eigen::Vector3d::Constant(kReferenceAmbient_c);
  Eigen::Vector3d heat_w_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d gain_factor_ = Eigen::Vector3d::Ones();
};

/// Homing repeatability of `model`'s encoders: how far (in encoder counts of each joint or axis,
/// a uniform bound) a new session's homing may land from the last. Throws autograv::Error for an
/// unknown model. Sources in the .cpp and docs/simulator-sources.md.
double homingRepeatabilityCounts(const std::string& model);

/// The encoder offset of session `session` of unit `unit_number` of `model`, against session 1
/// (the homing every published map was made in: zero there). Drawn from the model, the unit and
/// the session alone, uniform within homingRepeatabilityCounts. Throws autograv::Error for an
/// unknown model or a session or unit below 1. Unit: [encoder counts]
Eigen::Vector3d homingOffsetCounts(const std::string& model, int unit_number, int session);

}  // namespace autograv::sim
