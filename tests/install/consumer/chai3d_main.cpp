// A CHAI3D application's build against an installed autograv: find_package(autograv COMPONENTS
// chai3d), link autograv::chai3d, wrap a device and send it a force.
#include <cstdio>
#include <memory>
#include <string>

#include <autograv/chai3d/gravity_compensated_device.h>

namespace {

// Stands for a driver: open, a position at the origin, and the last force kept.
class StillDevice final : public chai3d::cGenericHapticDevice {
 public:
  StillDevice() {
    m_specifications.m_modelName = "consumer.3";
    m_specifications.m_maxLinearForce = 5.0;
    m_deviceAvailable = true;
  }
  bool open() override {
    m_deviceReady = true;
    return true;
  }
  bool close() override {
    m_deviceReady = false;
    return true;
  }
  bool getPosition(chai3d::cVector3d& a_position) override {
    a_position.zero();
    return true;
  }
  bool setForceAndTorqueAndGripperForce(const chai3d::cVector3d& a_force,
                                        const chai3d::cVector3d& a_torque,
                                        double a_gripperForce) override {
    m_prevForce = a_force;
    m_prevTorque = a_torque;
    m_prevGripperForce = a_gripperForce;
    return true;
  }
  bool getForce(chai3d::cVector3d& a_force) override {
    a_force = m_prevForce;
    return true;
  }
};

}  // namespace

int main() {
  auto raw = std::make_shared<StillDevice>();
  auto device = autograv::chai3d::cGravityCompensatedDevice::create(raw);
  if (!device->open()) return 1;
  device->setForce(chai3d::cVector3d(0.5, 0.0, 0.0));  // no map yet: the force passes
  chai3d::cVector3d sent;
  raw->getForce(sent);
  const std::string model = device->getSpecifications().m_modelName;
  std::printf("%.3f %s\n", sent.x(), model.c_str());
  return sent.x() == 0.5 && model == "consumer.3" ? 0 : 1;
}
