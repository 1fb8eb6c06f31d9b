// Stand-in only: a CHAI3D device that is an autograv simulation, so that the chai3d: path (the
// handler, Chai3dDeviceAdapter, the commands) runs end to end where no device is connected.
// Everything goes through cGenericHapticDevice's virtual API, as for a real driver; the
// simulation is reachable through SimulatedChai3dDevice for stepping and the simulated hand.
#pragma once

#include <memory>
#include <utility>

#include <Eigen/Core>

#include "autograv/chai3d/simulated_chai3d_device.h"
#include "autograv/sim/simulated_device.h"
#include "chai3d.h"
#include "simulated_switches.h"

namespace autograv::chai3d {

class cSimulatedHapticDevice final : public ::chai3d::cGenericHapticDevice,
                                     public SimulatedChai3dDevice {
 public:
  explicit cSimulatedHapticDevice(std::shared_ptr<sim::SimulatedDevice> simulation)
      : simulation_(std::move(simulation)) {
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

  std::shared_ptr<sim::SimulatedDevice> simulation() const override { return simulation_; }

  bool open() override {
    m_deviceReady = simulation_->open();
    return m_deviceReady;
  }
  bool close() override {
    m_deviceReady = false;
    return simulation_->close();
  }
  bool calibrate(bool a_forceCalibration = false) override {
    return simulation_->calibrate(a_forceCalibration);
  }
  bool getPosition(::chai3d::cVector3d& a_position) override {
    Eigen::Vector3d position_m;
    const bool ok = simulation_->getPosition(position_m);
    a_position.set(position_m.x(), position_m.y(), position_m.z());
    return ok;
  }
  bool getLinearVelocity(::chai3d::cVector3d& a_linearVelocity) override {
    Eigen::Vector3d velocity_m_per_s;
    const bool ok = simulation_->getLinearVelocity(velocity_m_per_s);
    a_linearVelocity.set(velocity_m_per_s.x(), velocity_m_per_s.y(), velocity_m_per_s.z());
    return ok;
  }
  bool getUserSwitches(unsigned int& a_userSwitches) override {
    return chai3d_mock::readSwitchBits(*simulation_, a_userSwitches);
  }
  bool setForceAndTorqueAndGripperForce(const ::chai3d::cVector3d& a_force,
                                        const ::chai3d::cVector3d& a_torque,
                                        double a_gripperForce) override {
    (void)a_torque;
    (void)a_gripperForce;
    m_prevForce = a_force;
    return simulation_->setForce(Eigen::Vector3d(a_force.x(), a_force.y(), a_force.z()));
  }

 private:
  std::shared_ptr<sim::SimulatedDevice> simulation_;
};

}  // namespace autograv::chai3d
