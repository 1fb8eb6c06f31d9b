#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "autograv/device/device_specifications.h"
#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/sim/simulated_device.h"

namespace autograv {

/// One name for a device everywhere (command line, demo, tests):
///   "sim:<model>"  a simulated device (sim::simulatedDeviceNames()),
///   "chai3d:<N>"   the N-th device of CHAI3D's cHapticDeviceHandler, through
///                  chai3d::Chai3dDeviceAdapter (only when autograv is built with CHAI3D; otherwise
///                  naming one throws an error that says how to build it).
struct DeviceHandle {
  std::string name;                      ///< As given, e.g. "chai3d:0".
  std::shared_ptr<HapticDevice> device;  ///< Not yet opened.
  /// The simulation behind the device, when it is one (a sim: device, or a simulated CHAI3D
  /// device such as the stand-in's): its physics must be stepped (simulatedTickSource) and its
  /// hand can do the manual step. Null for hardware.
  std::shared_ptr<sim::SimulatedDevice> simulation;
};

/// What `autograv devices` lists.
struct DeviceListing {
  /// Registry name, e.g. "sim:omega" or "chai3d:0".
  std::string name;
  /// What the device says about itself.
  DeviceSpecifications specifications;
};

/// True when the chai3d: scheme is available in this build.
bool chai3dDevicesAvailable() noexcept;

/// Every device this build can open: the simulated ones, then the CHAI3D devices connected now.
/// Not real-time safe.
std::vector<DeviceListing> listDevices();

/// Makes the device named `name` (not opened). `seed`, `friction` and `unit` shape simulated
/// devices (sim:; a simulated CHAI3D device is made by its driver). Throws
/// autograv::Error for an unknown scheme or model, a CHAI3D index with no device, or a chai3d:
/// name in a build without CHAI3D. Not real-time safe.
DeviceHandle makeDevice(const std::string& name, std::uint64_t seed = 1,
                        sim::FrictionLevel friction = sim::FrictionLevel::kTypical,
                        const sim::SimulatedUnit& unit = {});

/// makeDevice, then open() and calibrate() (homing); throws autograv::Error saying which failed.
/// Not real-time safe.
DeviceHandle openDevice(const std::string& name, std::uint64_t seed = 1,
                        sim::FrictionLevel friction = sim::FrictionLevel::kTypical,
                        const sim::SimulatedUnit& unit = {});

/// The tick source a servo loop on this device needs: simulated time (as fast as possible, or
/// locked to the wall clock when `real_time`) for a simulation, the wall clock for hardware.
/// Not real-time safe. Unit: [s]
std::unique_ptr<TickSource> makeTickSource(const DeviceHandle& handle, double period_s,
                                           bool real_time);

}  // namespace autograv
