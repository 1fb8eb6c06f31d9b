#pragma once

#include <string>

namespace autograv {

/// What a device says about itself, mirroring CHAI3D's cHapticDeviceInfo. SI units throughout.
struct DeviceSpecifications {
  std::string model_name;           ///< e.g. "sim:omega"; map files are tied to it.
  std::string manufacturer;         ///< e.g. "Force Dimension"
  std::string serial_number;        ///< Empty when the driver does not know it.
  double max_linear_force_n = 0.0;  ///< Actuator limit (peak force). Unit: [N]
  /// Force the actuators may hold indefinitely without overheating; 0 when the driver does not
  /// say (continuousForceRating_n then uses a datasheet or a conservative fraction of the peak).
  /// Unit: [N]
  double max_continuous_force_n = 0.0;
  double max_linear_stiffness_n_per_m = 0.0;  ///< Largest stable stiffness. Unit: [N/m]
  double max_linear_damping_n_s_per_m = 0.0;  ///< Largest stable damping. Unit: [N s/m]
  double workspace_radius_m = 0.0;            ///< Radius of the reachable sphere. Unit: [m]
};

/// Fraction of the peak force taken as the continuous rating of a device whose datasheet we do
/// not know: below the Phantom Omni's 0.88 N of 3.3 N (0.27), the lowest ratio we know.
inline constexpr double kDefaultContinuousForceFraction = 0.25;

/// Thermal time constant of a small DC motor of the class these devices use (maxon RE 25
/// catalogue: 612 s, winding and housing together), over which the thermal load of the forces
/// sent is averaged (GravityCompensatedDevice::thermalLoad, the calibration's drift check).
/// Unit: [s]
inline constexpr double kDefaultMotorTimeConstant_s = 612.0;

/// The force a calibration may hold for long: max_continuous_force_n when the driver gives it;
/// else the datasheet figure of a model we know by name (Phantom Omni and Touch: 0.88 N
/// continuous, 3.3 N peak, SensAble's Phantom Omni datasheet); else
/// kDefaultContinuousForceFraction of the peak. Never above the peak. Unit: [N].
/// Not real-time safe (reads the model name).
double continuousForceRating_n(const DeviceSpecifications& specifications);

/// Throws autograv::Error naming the first field that is not finite and positive (or, for
/// max_continuous_force_n, not zero, finite and at most the peak). Not real-time safe.
void validateSpecifications(const DeviceSpecifications& specifications);

}  // namespace autograv
