#include "autograv/device/forwarding_device.h"

#include <cstdint>
#include <memory>
#include <utility>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "forwarding_checks.h"
#include "recording_device.h"

namespace autograv {
namespace {

using testing::RecordingDevice;

/// A decorator that changes setForce only (halves the force) and inherits every other call.
class HalvingForces final : public ForwardingDevice {
 public:
  explicit HalvingForces(std::shared_ptr<HapticDevice> inner)
      : ForwardingDevice(std::move(inner)) {}
  bool setForce(const Eigen::Vector3d& force_n) override {
    return ForwardingDevice::setForce(0.5 * force_n);
  }
};

/// A decorator that overrides nothing: the base's own setForce.
class PassThrough final : public ForwardingDevice {
 public:
  explicit PassThrough(std::shared_ptr<HapticDevice> inner) : ForwardingDevice(std::move(inner)) {}
};

/// The wrapper seen as the application sees it: through the interface.
struct Fixture {
  std::shared_ptr<RecordingDevice> fake = std::make_shared<RecordingDevice>();
  HalvingForces wrapper{fake};
  HapticDevice& device = wrapper;
};

TEST(ForwardingDeviceTest, RefusesANullInnerDevice) { EXPECT_THROW(PassThrough(nullptr), Error); }

TEST(ForwardingDeviceTest, ForwardsOpen) {
  Fixture f;
  testing::expectForwardsOpen(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, ForwardsClose) {
  Fixture f;
  testing::expectForwardsClose(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, ForwardsCalibrateAndItsFlag) {
  Fixture f;
  testing::expectForwardsCalibrateAndItsFlag(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, ForwardsGetPosition) {
  Fixture f;
  testing::expectForwardsGetPosition(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, ForwardsGetLinearVelocity) {
  Fixture f;
  testing::expectForwardsGetLinearVelocity(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, ForwardsGetUserSwitch) {
  Fixture f;
  testing::expectForwardsGetUserSwitch(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, ForwardsSpecifications) {
  Fixture f;
  testing::expectForwardsSpecifications(f.device, *f.fake);
}

TEST(ForwardingDeviceTest, TheOverriddenSetForceIsTheOneCalled) {
  Fixture f;
  EXPECT_TRUE(f.device.setForce(Eigen::Vector3d(1.0, -2.0, 4.0)));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d(0.5, -1.0, 2.0));
  f.fake->set_force_result = false;
  EXPECT_FALSE(f.device.setForce(Eigen::Vector3d::Zero()));
  EXPECT_EQ(f.fake->set_force_calls, 2u);
}

TEST(ForwardingDeviceTest, ForwardsSetForceUnchangedWhenNotOverridden) {
  auto fake = std::make_shared<RecordingDevice>();
  PassThrough wrapper(fake);
  HapticDevice& device = wrapper;
  const Eigen::Vector3d force_n(0.5, -1.25, 2.0);
  EXPECT_TRUE(device.setForce(force_n));
  EXPECT_EQ(fake->last_force, force_n);
  fake->set_force_result = false;
  EXPECT_FALSE(device.setForce(force_n));
  EXPECT_EQ(fake->set_force_calls, 2u);
}

TEST(ForwardingDeviceTest, ForwardingAllocatesNothing) {
  Fixture f;
  constexpr int kTicks = 10000;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();
  bool pressed = false;
  double force_limit_sum_n = 0.0;
  {
    testing::AllocationCounter counter;
    f.device.open();
    f.device.calibrate();
    for (int i = 0; i < kTicks; ++i) {
      f.device.getPosition(position_m);
      f.device.getLinearVelocity(velocity_m_per_s);
      f.device.getUserSwitch(0, pressed);
      force_limit_sum_n += f.device.specifications().max_linear_force_n;
      f.device.setForce(Eigen::Vector3d(0.0, 0.0, 2.0 * i));
    }
    f.device.close();
    EXPECT_EQ(counter.count(), 0u);
  }
  EXPECT_EQ(f.fake->get_position_calls, static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(f.fake->get_velocity_calls, static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(f.fake->get_switch_calls, static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(f.fake->set_force_calls, static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(f.fake->last_force, Eigen::Vector3d(0.0, 0.0, kTicks - 1.0));
  EXPECT_EQ(force_limit_sum_n, 8.0 * kTicks);
}

}  // namespace
}  // namespace autograv
