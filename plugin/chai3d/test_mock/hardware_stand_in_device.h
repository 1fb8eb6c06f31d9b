// Stand-in only: a CHAI3D device that behaves, for everything above CHAI3D's API, as hardware
// does. It is a plain cGenericHapticDevice (not a SimulatedChai3dDevice), so the registry finds
// no simulation behind it: the commands take their branches for real hardware (a wall-clock servo
// loop, no ground truth, no simulated hand, real-time priority asked for). Inside, a simulation
// of the named model is advanced to the wall clock at every call, so the device moves on its own
// time whether or not anybody polls it, as a real one does.
//
// A person may stand at it (`person`): from open() on, a hand carries the end-effector to the
// origin (where CHAI3D centres positions, the wizard's centre on hardware), holds it still and
// presses the stylus button, once a second, until a force field comes on; a second after that it
// lets go and keeps its hands off. That is the wizard's manual step (Centre, Release) done from
// what a person at the device sees, with no access to the wizard.
#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <utility>

#include <Eigen/Core>

#include "autograv/sim/simulated_device.h"
#include "chai3d.h"
#include "simulated_switches.h"

namespace autograv::chai3d {

class cHardwareStandInDevice final : public ::chai3d::cGenericHapticDevice {
 public:
  cHardwareStandInDevice(std::unique_ptr<sim::SimulatedDevice> simulation, bool person)
      : simulation_(std::move(simulation)), person_(person), last_(Clock::now()) {
    const DeviceSpecifications& specifications = simulation_->specifications();
    m_specifications.m_model = ::chai3d::C_HAPTIC_DEVICE_CUSTOM;
    m_specifications.m_modelName = specifications.model_name;
    m_specifications.m_manufacturerName = specifications.manufacturer;
    m_specifications.m_maxLinearForce = specifications.max_linear_force_n;
    m_specifications.m_maxLinearStiffness = specifications.max_linear_stiffness_n_per_m;
    m_specifications.m_maxLinearDamping = specifications.max_linear_damping_n_s_per_m;
    m_specifications.m_workspaceRadius = specifications.workspace_radius_m;
    m_specifications.m_sensedPosition = true;
    m_specifications.m_actuatedPosition = true;
    m_deviceAvailable = true;
  }

  bool open() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    m_deviceReady = simulation_->open();
    return m_deviceReady;
  }
  bool close() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    m_deviceReady = false;
    return simulation_->close();
  }
  bool calibrate(bool a_forceCalibration = false) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    return simulation_->calibrate(a_forceCalibration);
  }
  bool getPosition(::chai3d::cVector3d& a_position) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    Eigen::Vector3d position_m;
    const bool ok = simulation_->getPosition(position_m);
    a_position.set(position_m.x(), position_m.y(), position_m.z());
    return ok;
  }
  bool getLinearVelocity(::chai3d::cVector3d& a_linearVelocity) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    Eigen::Vector3d velocity_m_per_s;
    const bool ok = simulation_->getLinearVelocity(velocity_m_per_s);
    a_linearVelocity.set(velocity_m_per_s.x(), velocity_m_per_s.y(), velocity_m_per_s.z());
    return ok;
  }
  bool getUserSwitches(unsigned int& a_userSwitches) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    return chai3d_mock::readSwitchBits(*simulation_, a_userSwitches);
  }
  bool setForceAndTorqueAndGripperForce(const ::chai3d::cVector3d& a_force,
                                        const ::chai3d::cVector3d& a_torque,
                                        double a_gripperForce) override {
    (void)a_torque;
    (void)a_gripperForce;
    const std::lock_guard<std::mutex> lock(mutex_);
    catchUp();
    m_prevForce = a_force;
    last_force_n_ = Eigen::Vector3d(a_force.x(), a_force.y(), a_force.z());
    return simulation_->setForce(last_force_n_);
  }

 private:
  using Clock = std::chrono::steady_clock;
  // How long the person holds still before pressing, how long a press lasts, how often it is
  // repeated, and how long after the field comes on the person lets go. Unit: [s]
  static constexpr double kHoldStill_s = 0.5;
  static constexpr double kPress_s = 0.05;
  static constexpr double kPressEvery_s = 1.0;
  static constexpr double kLetGoAfter_s = 1.0;
  // A commanded force above this is the field (the wizard commands none while the user carries
  // the end-effector). Unit: [N]
  static constexpr double kFieldForce_n = 1e-3;

  enum class Person { kAway, kCarrying, kWaitingForField, kLettingGo, kHandsOff };

  // The simulation up to now, then what the person does (called with the mutex held).
  void catchUp() {
    const Clock::time_point now = Clock::now();
    const double elapsed_s = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    if (elapsed_s > 0.0) simulation_->advance(elapsed_s);
    if (person_) actAsPerson();
  }

  void actAsPerson() {
    sim::SimulatedHand& hand = simulation_->hand();
    const double now_s = simulation_->time_s();
    if (switch_down_ && now_s - pressed_at_s_ >= kPress_s) {
      simulation_->setUserSwitch(0, false);
      switch_down_ = false;
    }
    switch (state_) {
      case Person::kAway:
        if (!m_deviceReady) return;
        hand.grab(simulation_->truePosition_m());
        hand.moveTo(Eigen::Vector3d::Zero(), 0.05);
        still_since_s_ = now_s;
        state_ = Person::kCarrying;
        return;
      case Person::kCarrying:
        if (!hand.atGoal() || simulation_->trueVelocity_m_per_s().norm() > 1e-3) {
          still_since_s_ = now_s;
        } else if (now_s - still_since_s_ >= kHoldStill_s && now_s >= next_press_s_) {
          simulation_->setUserSwitch(0, true);
          switch_down_ = true;
          pressed_at_s_ = now_s;
          next_press_s_ = now_s + kPressEvery_s;
          state_ = Person::kWaitingForField;
        }
        return;
      case Person::kWaitingForField:
        if (last_force_n_.norm() > kFieldForce_n) {
          field_on_s_ = now_s;
          state_ = Person::kLettingGo;
        } else if (now_s >= next_press_s_) {
          state_ = Person::kCarrying;  // the press was not taken: hold still and press again
        }
        return;
      case Person::kLettingGo:
        if (now_s - field_on_s_ >= kLetGoAfter_s) {
          hand.release();
          state_ = Person::kHandsOff;
        }
        return;
      case Person::kHandsOff:
        return;
    }
  }

  std::mutex mutex_;
  std::unique_ptr<sim::SimulatedDevice> simulation_;
  bool person_;
  Clock::time_point last_;
  Eigen::Vector3d last_force_n_ = Eigen::Vector3d::Zero();
  Person state_ = Person::kAway;
  bool switch_down_ = false;
  double pressed_at_s_ = 0.0;
  double next_press_s_ = 0.0;
  double still_since_s_ = 0.0;
  double field_on_s_ = 0.0;
};

}  // namespace autograv::chai3d
