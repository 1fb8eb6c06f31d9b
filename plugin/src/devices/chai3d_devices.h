#pragma once

// The chai3d: scheme of the device registry. Implemented by chai3d_devices.cpp when autograv is
// built with CHAI3D, and by no_chai3d_devices.cpp (which says how to get it) otherwise.

#include <vector>

#include "autograv/devices/device_registry.h"

namespace autograv::detail {

bool chai3dBuilt() noexcept;
/// The devices CHAI3D's handler sees now, named "chai3d:<index>".
std::vector<DeviceListing> listChai3dDevices();
/// The index-th device of CHAI3D's handler behind a Chai3dDeviceAdapter.
DeviceHandle makeChai3dDevice(const std::string& name, int index);

}  // namespace autograv::detail
