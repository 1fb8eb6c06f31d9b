#pragma once

#include <string>

namespace autograv {

/// What a device says about itself, mirroring CHAI3D's cHapticDeviceInfo. SI units throughout.
struct DeviceSpecifications {
  std::string model_name;                     ///< e.g. "sim:omega"; map files are tied to it.
  std::string manufacturer;                   ///< e.g. "Force Dimension"
  std::string serial_number;                  ///< Empty when the driver does not know it.
  double max_linear_force_n = 0.0;            ///< Actuator limit. Unit: [N]
  double max_linear_stiffness_n_per_m = 0.0;  ///< Largest stable stiffness. Unit: [N/m]
  double max_linear_damping_n_s_per_m = 0.0;  ///< Largest stable damping. Unit: [N s/m]
  double workspace_radius_m = 0.0;            ///< Radius of the reachable sphere. Unit: [m]
};

/// Throws autograv::Error naming the first field that is not finite and positive.
/// Not real-time safe.
void validateSpecifications(const DeviceSpecifications& specifications);

}  // namespace autograv
