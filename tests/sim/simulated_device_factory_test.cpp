#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {
namespace {

TEST(SimulatedDeviceFactoryTest, EveryListedNameBuildsADeviceThatSaysItsName) {
  const auto names = simulatedDeviceNames();
  ASSERT_FALSE(names.empty());
  for (const auto& name : names) {
    auto device = makeSimulatedDevice(name, 5);
    ASSERT_NE(device, nullptr);
    EXPECT_EQ(device->specifications().model_name, name);
    EXPECT_NO_THROW(validateSpecifications(device->specifications()));
    EXPECT_TRUE(device->open());
    EXPECT_TRUE(device->calibrate());
    Eigen::Vector3d position;
    EXPECT_TRUE(device->getPosition(position));
    EXPECT_LT((position - device->workspaceCenter_m()).norm(), 1e-3);
  }
}

TEST(SimulatedDeviceFactoryTest, UnknownNameThrowsWithTheValidNames) {
  try {
    makeSimulatedDevice("sim:phantom-premium", 1);
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("sim:phantom-premium"), std::string::npos);
    for (const auto& name : simulatedDeviceNames()) {
      EXPECT_NE(message.find(name), std::string::npos) << message;
    }
  }
}

}  // namespace
}  // namespace autograv::sim
