#include <memory>
#include <string>

#include "autograv/chai3d/device_adapter.h"
#include "autograv/error.h"
#include "chai3d.h"
#include "devices/chai3d_devices.h"

namespace autograv::detail {

bool chai3dBuilt() noexcept { return true; }

std::vector<DeviceListing> listChai3dDevices() {
  ::chai3d::cHapticDeviceHandler handler;
  std::vector<DeviceListing> listings;
  for (unsigned int index = 0; index < handler.getNumDevices(); ++index) {
    ::chai3d::cHapticDeviceInfo info;
    if (!handler.getDeviceSpecifications(info, index)) continue;
    listings.push_back(
        {"chai3d:" + std::to_string(index), chai3d::Chai3dDeviceAdapter::toSpecifications(info)});
  }
  return listings;
}

DeviceHandle makeChai3dDevice(const std::string& name, int index) {
  ::chai3d::cHapticDeviceHandler handler;
  const unsigned int count = handler.getNumDevices();
  ::chai3d::cGenericHapticDevicePtr device;
  if (index < 0 || static_cast<unsigned int>(index) >= count ||
      !handler.getDevice(device, static_cast<unsigned int>(index)) || !device) {
    throw Error("device '" + name + "': CHAI3D sees " + std::to_string(count) +
                " device(s) (chai3d:0 to chai3d:N-1; `autograv devices` lists them); is it "
                "connected and its driver installed?");
  }
  auto adapter = std::make_shared<chai3d::Chai3dDeviceAdapter>(device);
  DeviceHandle handle;
  handle.name = name;
  handle.simulation = adapter->simulation();
  handle.device = std::move(adapter);
  return handle;
}

}  // namespace autograv::detail
