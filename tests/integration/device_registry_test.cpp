#include "autograv/devices/device_registry.h"

#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

std::string errorOf(const std::string& name) {
  try {
    makeDevice(name);
  } catch (const Error& error) {
    return error.what();
  }
  return {};
}

TEST(DeviceRegistryTest, SimulatedNamesGiveTheSimulationAsTheDevice) {
  for (const std::string& name : sim::simulatedDeviceNames()) {
    const DeviceHandle handle = makeDevice(name, 3);
    EXPECT_EQ(handle.name, name);
    ASSERT_NE(handle.simulation, nullptr);
    EXPECT_EQ(handle.device.get(), handle.simulation.get());
    EXPECT_EQ(handle.device->specifications().model_name, name);
  }
}

TEST(DeviceRegistryTest, ListsEverySimulatedDeviceWithModelSerialAndLimits) {
  const std::vector<DeviceListing> devices = listDevices();
  ASSERT_GE(devices.size(), sim::simulatedDeviceNames().size());
  for (std::size_t i = 0; i < sim::simulatedDeviceNames().size(); ++i) {
    EXPECT_EQ(devices[i].name, sim::simulatedDeviceNames()[i]);
    EXPECT_FALSE(devices[i].specifications.serial_number.empty());
    EXPECT_GT(devices[i].specifications.max_linear_force_n, 0.0);
    EXPECT_GT(devices[i].specifications.workspace_radius_m, 0.0);
  }
}

TEST(DeviceRegistryTest, BadNamesSayWhatIsValid) {
  EXPECT_NE(errorOf("sim:nothing").find("sim:omni"), std::string::npos);
  EXPECT_NE(errorOf("phantom").find("chai3d:N"), std::string::npos);
  EXPECT_NE(errorOf("chai3d:first").find("chai3d:N, N = 0, 1"), std::string::npos);
  // chai3d:0 says how to build with CHAI3D, or, in a build with it, how many devices it sees.
  const std::string expected =
      chai3dDevicesAvailable() ? "CHAI3D sees 0 device(s)" : "-DAUTOGRAV_CHAI3D_DIR";
  EXPECT_NE(errorOf("chai3d:0").find(expected), std::string::npos) << errorOf("chai3d:0");
}

TEST(DeviceRegistryTest, OpenDeviceOpensAndHomes) {
  const DeviceHandle handle = openDevice("sim:omni");
  Eigen::Vector3d position_m;
  EXPECT_TRUE(handle.device->getPosition(position_m));
  EXPECT_TRUE(handle.simulation->isCalibrated());
}

TEST(DeviceRegistryTest, ASimulationIsPacedBySimulatedTime) {
  const DeviceHandle handle = openDevice("sim:omega");
  const auto ticks = makeTickSource(handle, 1e-3, /*real_time=*/false);
  const double start_s = handle.simulation->time_s();
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(ticks->waitForNextTick());
  EXPECT_NEAR(handle.simulation->time_s() - start_s, 0.010, 1e-12);
}

}  // namespace
}  // namespace autograv
