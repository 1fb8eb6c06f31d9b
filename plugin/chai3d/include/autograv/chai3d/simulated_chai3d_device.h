#pragma once

#include <memory>

namespace autograv::sim {
class SimulatedDevice;
}

namespace autograv::chai3d {

/// Implemented, beside cGenericHapticDevice, by a CHAI3D device that is a simulation (the
/// stand-in's devices are): tools that find one behind a Chai3dDeviceAdapter step its physics and
/// let its simulated hand do the manual step, exactly as for a sim: device, while every position
/// and force still goes through CHAI3D's API. Hardware drivers do not implement it.
class SimulatedChai3dDevice {
 public:
  virtual ~SimulatedChai3dDevice() = default;
  /// The simulation this device drives. Not real-time safe.
  virtual std::shared_ptr<sim::SimulatedDevice> simulation() const = 0;
};

}  // namespace autograv::chai3d
