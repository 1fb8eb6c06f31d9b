#pragma once

// A scripted HapticDevice for decorator tests: returns what the test sets and records every call.
// Records only fixed-size data, so it allocates nothing and can sit under an AllocationCounter.

#include <cstdint>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"

namespace autograv::testing {

class RecordingDevice : public HapticDevice {
 public:
  RecordingDevice() {
    specs.model_name = "fake:recording";
    specs.manufacturer = "autograv tests";
    specs.max_linear_force_n = 8.0;
    specs.max_linear_stiffness_n_per_m = 2000.0;
    specs.max_linear_damping_n_s_per_m = 20.0;
    specs.workspace_radius_m = 0.1;
  }

  bool open() override {
    ++open_calls;
    return open_result;
  }
  bool close() override {
    ++close_calls;
    return close_result;
  }
  bool calibrate(bool force) override {
    ++calibrate_calls;
    last_calibrate_force = force;
    return calibrate_result;
  }
  bool getPosition(Eigen::Vector3d& position_m) override {
    ++get_position_calls;
    position_m = position;
    return position_result;
  }
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override {
    ++get_velocity_calls;
    velocity_m_per_s = velocity;
    return velocity_result;
  }
  bool getUserSwitch(int index, bool& pressed) override {
    ++get_switch_calls;
    last_switch_index = index;
    pressed = switch_pressed;
    return switch_result;
  }
  bool setForce(const Eigen::Vector3d& force_n) override {
    ++set_force_calls;
    last_force = force_n;
    return set_force_result;
  }
  const DeviceSpecifications& specifications() const override { return specs; }

  // Scripted answers.
  DeviceSpecifications specs;
  Eigen::Vector3d position = Eigen::Vector3d(0.001, -0.002, 0.003);
  Eigen::Vector3d velocity = Eigen::Vector3d(0.1, 0.2, -0.3);
  bool switch_pressed = true;
  bool open_result = true;
  bool close_result = true;
  bool calibrate_result = true;
  bool position_result = true;
  bool velocity_result = true;
  bool switch_result = true;
  bool set_force_result = true;

  // Recorded calls.
  int open_calls = 0;
  int close_calls = 0;
  int calibrate_calls = 0;
  bool last_calibrate_force = false;
  std::uint64_t get_position_calls = 0;
  std::uint64_t get_velocity_calls = 0;
  std::uint64_t get_switch_calls = 0;
  int last_switch_index = -1;
  std::uint64_t set_force_calls = 0;
  Eigen::Vector3d last_force = Eigen::Vector3d::Constant(-999.0);
};

}  // namespace autograv::testing
