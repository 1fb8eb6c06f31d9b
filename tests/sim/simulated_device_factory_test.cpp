#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/sim/actuators.h"
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

TEST(SimulatedDeviceFactoryTest, EveryTestDeviceBuildsAtEveryFrictionLevelAndUnit) {
  const auto names = testDeviceNames();
  ASSERT_NE(std::find(names.begin(), names.end(), "sim:falcon-can"), names.end());
  for (const auto& name : names) {
    for (const FrictionLevel friction : {FrictionLevel::kNone, FrictionLevel::kLow,
                                         FrictionLevel::kTypical, FrictionLevel::kHigh}) {
      for (const SimulatedUnit& unit : {SimulatedUnit{1, ActuatorTolerance::kIdeal},
                                        SimulatedUnit{2, ActuatorTolerance::kHigh}}) {
        auto device = makeSimulatedDevice(name, 5, friction, unit);
        ASSERT_NE(device, nullptr);
        EXPECT_EQ(device->specifications().model_name, name);
        EXPECT_NO_THROW(validateSpecifications(device->specifications()));
        EXPECT_TRUE(device->open());
        EXPECT_TRUE(device->calibrate());
        EXPECT_TRUE(device->isReachable(device->workspaceCenter_m())) << name;
      }
    }
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
