// Stand-in only: the devices the stand-in's cHapticDeviceHandler finds.
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "chai3d.h"
#include "simulated_haptic_device.h"

namespace chai3d {

std::vector<cGenericHapticDevicePtr> standInConnectedDevices() {
  std::vector<cGenericHapticDevicePtr> devices;
  const char* names = std::getenv("AUTOGRAV_STANDIN_DEVICES");
  if (names == nullptr) return devices;
  const std::string list = names;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    if (!name.empty()) {
      // Seed 1, as the sim: devices of the command line: the same device either way.
      devices.push_back(std::make_shared<autograv::chai3d::cSimulatedHapticDevice>(
          autograv::sim::makeSimulatedDevice(name, 1)));
    }
    begin = end + 1;
  }
  return devices;
}

}  // namespace chai3d
