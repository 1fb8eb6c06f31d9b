#include "autograv/error.h"
#include "devices/chai3d_devices.h"

namespace autograv::detail {

bool chai3dBuilt() noexcept { return false; }

std::vector<DeviceListing> listChai3dDevices() { return {}; }

DeviceHandle makeChai3dDevice(const std::string& name, int /*index*/) {
  throw Error("device '" + name +
              "': this autograv was built without CHAI3D; reconfigure with "
              "-DAUTOGRAV_CHAI3D_DIR=<your CHAI3D 3.3 build> (see plugin/chai3d/README.md)");
}

}  // namespace autograv::detail
