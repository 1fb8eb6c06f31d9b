#pragma once

// Checks that a decorator passes a HapticDevice call through to a RecordingDevice underneath it:
// arguments reach the inner device, results come back. Shared by every decorator's tests, one
// check per method, because a missed override forwards nothing and fails quietly.
// setForce is left to each decorator's own test: that is the call decorators change.

#include <gtest/gtest.h>

#include "autograv/device/haptic_device.h"
#include "recording_device.h"

namespace autograv::testing {

inline void expectForwardsOpen(HapticDevice& device, RecordingDevice& inner) {
  EXPECT_TRUE(device.open());
  inner.open_result = false;
  EXPECT_FALSE(device.open());
  EXPECT_EQ(inner.open_calls, 2);
}

inline void expectForwardsClose(HapticDevice& device, RecordingDevice& inner) {
  EXPECT_TRUE(device.close());
  inner.close_result = false;
  EXPECT_FALSE(device.close());
  EXPECT_EQ(inner.close_calls, 2);
}

inline void expectForwardsCalibrateAndItsFlag(HapticDevice& device, RecordingDevice& inner) {
  EXPECT_TRUE(device.calibrate(true));
  EXPECT_TRUE(inner.last_calibrate_force);
  inner.calibrate_result = false;
  EXPECT_FALSE(device.calibrate());
  EXPECT_FALSE(inner.last_calibrate_force);  // the default argument is false, as in CHAI3D
  EXPECT_EQ(inner.calibrate_calls, 2);
}

inline void expectForwardsGetPosition(HapticDevice& device, RecordingDevice& inner) {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();
  EXPECT_TRUE(device.getPosition(position_m));
  EXPECT_EQ(position_m, inner.position);
  inner.position_result = false;
  inner.position = Eigen::Vector3d(0.02, 0.0, -0.01);
  EXPECT_FALSE(device.getPosition(position_m));
  EXPECT_EQ(position_m, Eigen::Vector3d(0.02, 0.0, -0.01));
  EXPECT_EQ(inner.get_position_calls, 2u);
}

inline void expectForwardsGetLinearVelocity(HapticDevice& device, RecordingDevice& inner) {
  Eigen::Vector3d velocity_m_per_s = Eigen::Vector3d::Zero();
  EXPECT_TRUE(device.getLinearVelocity(velocity_m_per_s));
  EXPECT_EQ(velocity_m_per_s, inner.velocity);
  inner.velocity_result = false;
  EXPECT_FALSE(device.getLinearVelocity(velocity_m_per_s));
  EXPECT_EQ(inner.get_velocity_calls, 2u);
}

inline void expectForwardsGetUserSwitch(HapticDevice& device, RecordingDevice& inner) {
  bool pressed = false;
  EXPECT_TRUE(device.getUserSwitch(3, pressed));
  EXPECT_TRUE(pressed);
  EXPECT_EQ(inner.last_switch_index, 3);
  inner.switch_result = false;
  inner.switch_pressed = false;
  EXPECT_FALSE(device.getUserSwitch(1, pressed));
  EXPECT_FALSE(pressed);
  EXPECT_EQ(inner.last_switch_index, 1);
}

inline void expectForwardsSpecifications(HapticDevice& device, RecordingDevice& inner) {
  EXPECT_EQ(&device.specifications(), &inner.specs);
  inner.specs.model_name = "renamed";
  EXPECT_EQ(device.specifications().model_name, "renamed");
}

}  // namespace autograv::testing
