// Stand-in only: the devices the stand-in's cHapticDeviceHandler finds, named in
// AUTOGRAV_STANDIN_DEVICES, e.g. "sim:omni,hardware:sim:omega": a name alone is a simulated CHAI3D
// device (its simulation exposed, stepped by the commands); "hardware:" before it makes a device
// that hides its simulation and runs it on the wall clock (hardware_stand_in_device.h), with a
// person at it when AUTOGRAV_STANDIN_PERSON=1.
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "chai3d.h"
#include "hardware_stand_in_device.h"
#include "simulated_haptic_device.h"

namespace chai3d {

std::vector<cGenericHapticDevicePtr> standInConnectedDevices() {
  std::vector<cGenericHapticDevicePtr> devices;
  const char* names = std::getenv("AUTOGRAV_STANDIN_DEVICES");
  if (names == nullptr) return devices;
  const std::string list = names;
  const char* person = std::getenv("AUTOGRAV_STANDIN_PERSON");
  const bool with_person = person != nullptr && std::string(person) == "1";
  const std::string hardware = "hardware:";
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    if (name.compare(0, hardware.size(), hardware) == 0) {
      devices.push_back(std::make_shared<autograv::chai3d::cHardwareStandInDevice>(
          autograv::sim::makeSimulatedDevice(name.substr(hardware.size()), 1), with_person));
    } else if (!name.empty()) {
      // Seed 1, as the sim: devices of the command line: the same device either way.
      devices.push_back(std::make_shared<autograv::chai3d::cSimulatedHapticDevice>(
          autograv::sim::makeSimulatedDevice(name, 1)));
    }
    begin = end + 1;
  }
  return devices;
}

}  // namespace chai3d
