#include "autograv/devices/device_registry.h"

#include <algorithm>
#include <cctype>
#include <utility>

#include "autograv/device/wall_clock_tick_source.h"
#include "autograv/error.h"
#include "devices/chai3d_devices.h"

namespace autograv {

namespace {

constexpr const char* kChai3dScheme = "chai3d:";

bool startsWith(const std::string& text, const std::string& prefix) {
  return text.compare(0, prefix.size(), prefix) == 0;
}

std::string knownNames() {
  std::string names;
  for (const std::string& name : sim::simulatedDeviceNames()) names += name + ", ";
  for (const std::string& name : sim::testDeviceNames()) names += name + ", ";
  return names + "chai3d:N" + (detail::chai3dBuilt() ? "" : " (needs a build with CHAI3D)");
}

}  // namespace

bool chai3dDevicesAvailable() noexcept { return detail::chai3dBuilt(); }

std::vector<DeviceListing> listDevices() {
  std::vector<DeviceListing> listings;
  for (const std::string& name : sim::simulatedDeviceNames()) {
    listings.push_back({name, sim::makeSimulatedDevice(name)->specifications()});
  }
  for (DeviceListing& listing : detail::listChai3dDevices()) listings.push_back(std::move(listing));
  return listings;
}

DeviceHandle makeDevice(const std::string& name, std::uint64_t seed, sim::FrictionLevel friction,
                        const sim::SimulatedUnit& unit) {
  if (startsWith(name, "sim:")) {
    DeviceHandle handle;
    handle.name = name;
    handle.simulation = sim::makeSimulatedDevice(name, seed, friction, unit);
    handle.device = handle.simulation;
    return handle;
  }
  if (startsWith(name, kChai3dScheme)) {
    const std::string index = name.substr(std::char_traits<char>::length(kChai3dScheme));
    const bool digits =
        !index.empty() && index.size() <= 4 && std::all_of(index.begin(), index.end(), [](char c) {
          return std::isdigit(static_cast<unsigned char>(c));
        });
    if (!digits) {
      throw Error("device '" + name + "': a CHAI3D device is named chai3d:N, N = 0, 1, ...");
    }
    return detail::makeChai3dDevice(name, std::stoi(index));
  }
  throw Error("unknown device '" + name + "'; valid names: " + knownNames());
}

DeviceHandle openDevice(const std::string& name, std::uint64_t seed, sim::FrictionLevel friction,
                        const sim::SimulatedUnit& unit) {
  DeviceHandle handle = makeDevice(name, seed, friction, unit);
  if (!handle.device->open()) throw Error("device " + name + ": open() failed");
  if (!handle.device->calibrate()) {
    throw Error("device " + name +
                ": calibrate() (homing) failed; home the device as its manual "
                "says, then try again");
  }
  return handle;
}

std::unique_ptr<TickSource> makeTickSource(const DeviceHandle& handle, double period_s,
                                           bool real_time) {
  if (handle.simulation) {
    return std::make_unique<sim::SimulatedTickSource>(
        *handle.simulation, period_s,
        real_time ? sim::SimulatedTickSource::Mode::kRealTime
                  : sim::SimulatedTickSource::Mode::kAsFastAsPossible);
  }
  return std::make_unique<WallClockTickSource>(period_s);
}

}  // namespace autograv
