#include "autograv/chai3d/gravity_compensated_device.h"

#include <utility>

#include "autograv/device/wall_clock_tick_source.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"

namespace autograv::chai3d {

cGravityCompensatedDevice::cGravityCompensatedDevice(::chai3d::cGenericHapticDevicePtr device,
                                                     const CompensationOptions& options,
                                                     VendorGravityCompensation vendor)
    : ::chai3d::cGenericHapticDevice(0), device_(std::move(device)) {
  if (!device_) throw Error("cGravityCompensatedDevice: the CHAI3D device is null");
  adapter_ = std::make_shared<Chai3dDeviceAdapter>(device_, vendor);
  compensated_ = std::make_unique<GravityCompensatedDevice>(adapter_, options);
  // Our own placeholder specifications are CHAI3D's, whose constructor leaves m_model
  // uninitialised: give it a value, so that reading ours before open() is defined.
  m_specifications.m_model = ::chai3d::C_HAPTIC_DEVICE_VIRTUAL;
  copyAvailability();
}

cGravityCompensatedDevice::~cGravityCompensatedDevice() = default;

void cGravityCompensatedDevice::copyAvailability() {
  // isDeviceAvailable() and isDeviceReady() are non-virtual readers of these members: keep them
  // equal to the wrapped device's.
  m_deviceAvailable = device_->isDeviceAvailable();
  m_deviceReady = device_->isDeviceReady();
}

bool cGravityCompensatedDevice::open() {
  const bool ok = compensated_->open();  // adapter: device open, specifications, vendor policy
  // getSpecifications() is a non-virtual reader of m_specifications: copy the wrapped device's
  // once they are valid, after a successful open() (CHAI3D 3.3 leaves m_model uninitialised
  // before it).
  if (ok) m_specifications = device_->getSpecifications();
  copyAvailability();
  return ok;
}

bool cGravityCompensatedDevice::close() {
  const bool ok = compensated_->close();
  copyAvailability();  // the specifications stay those of the device last opened
  return ok;
}

bool cGravityCompensatedDevice::calibrate(bool a_forceCalibration) {
  return compensated_->calibrate(a_forceCalibration);
}

bool cGravityCompensatedDevice::getPosition(::chai3d::cVector3d& a_position) {
  // Through the decorator, so that setForce uses this very reading (no second driver read).
  Eigen::Vector3d position_m;
  const bool ok = compensated_->getPosition(position_m);
  a_position.set(position_m.x(), position_m.y(), position_m.z());
  return ok;
}

bool cGravityCompensatedDevice::getLinearVelocity(::chai3d::cVector3d& a_linearVelocity) {
  return device_->getLinearVelocity(a_linearVelocity);
}

bool cGravityCompensatedDevice::getRotation(::chai3d::cMatrix3d& a_rotation) {
  return device_->getRotation(a_rotation);
}

bool cGravityCompensatedDevice::getJointAnglesRad(double a_jointAnglesRad[::chai3d::C_MAX_DOF]) {
  return device_->getJointAnglesRad(a_jointAnglesRad);
}

bool cGravityCompensatedDevice::getAngularVelocity(::chai3d::cVector3d& a_angularVelocity) {
  return device_->getAngularVelocity(a_angularVelocity);
}

bool cGravityCompensatedDevice::getTransform(::chai3d::cTransform& a_transform) {
  return device_->getTransform(a_transform);
}

bool cGravityCompensatedDevice::getGripperAngleRad(double& a_angle) {
  return device_->getGripperAngleRad(a_angle);
}

bool cGravityCompensatedDevice::getGripperAngularVelocity(double& a_gripperAngularVelocity) {
  return device_->getGripperAngularVelocity(a_gripperAngularVelocity);
}

bool cGravityCompensatedDevice::getForce(::chai3d::cVector3d& a_force) {
  return device_->getForce(a_force);
}

bool cGravityCompensatedDevice::getTorque(::chai3d::cVector3d& a_torque) {
  return device_->getTorque(a_torque);
}

bool cGravityCompensatedDevice::getGripperForce(double& a_gripperForce) {
  return device_->getGripperForce(a_gripperForce);
}

bool cGravityCompensatedDevice::getUserSwitch(int a_switchIndex, bool& a_status) {
  return device_->getUserSwitch(a_switchIndex, a_status);
}

bool cGravityCompensatedDevice::getUserSwitches(unsigned int& a_userSwitches) {
  return device_->getUserSwitches(a_userSwitches);
}

void cGravityCompensatedDevice::setEnableGripperUserSwitch(const bool a_status) {
  device_->setEnableGripperUserSwitch(a_status);
}

bool cGravityCompensatedDevice::getEnableGripperUserSwitch() const {
  return device_->getEnableGripperUserSwitch();
}

bool cGravityCompensatedDevice::setForceAndTorqueAndGripperForce(
    const ::chai3d::cVector3d& a_force, const ::chai3d::cVector3d& a_torque,
    double a_gripperForce) {
  adapter_->setTorqueAndGripperForce(a_torque, a_gripperForce);
  m_prevForce = a_force;  // what the application asked for; getForce() reports what was sent
  m_prevTorque = a_torque;
  m_prevGripperForce = a_gripperForce;
  return compensated_->setForce(Eigen::Vector3d(a_force.x(), a_force.y(), a_force.z()));
}

bool cGravityCompensatedDevice::enableForces(bool a_value) {
  return device_->enableForces(a_value);
}

void cGravityCompensatedDevice::loadAndPublishMap(const std::string& path,
                                                  bool allow_model_mismatch) {
  const std::string& device_model = adapter_->specifications().model_name;
  if (device_model.empty()) {
    throw Error(
        "cGravityCompensatedDevice::loadAndPublishMap: the device is not open, so the map '" +
        path + "' cannot be checked against its model; call open() first");
  }
  // The model is checked here rather than by loadMap, so that the message speaks of this API.
  auto map = std::make_shared<const GravityMap>(loadMap(path));
  const std::string& map_model = map->metadata().device_model;
  if (map_model != device_model && !allow_model_mismatch) {
    throw Error("cGravityCompensatedDevice::loadAndPublishMap: the map '" + path +
                "' was calibrated on a '" + map_model + "' but this device is a '" + device_model +
                "'; calibrate this device, or pass allow_model_mismatch = true if both are the "
                "same hardware");
  }
  compensated_->publishMap(std::move(map), allow_model_mismatch);
}

void cGravityCompensatedDevice::loadAndPublishMapForDevice(const std::string& maps_dir) {
  compensated_->publishMap(
      std::make_shared<const GravityMap>(loadMapForDevice(adapter_->specifications(), maps_dir)));
}

MapCheckResult cGravityCompensatedDevice::checkPublishedMap(const MapCheckOptions& options,
                                                            TickSource* ticks) {
  const std::shared_ptr<const GravityMap> map = compensated_->publishedMap();
  if (!map) throw Error("checkPublishedMap: publish a map first (loadAndPublishMapForDevice)");
  MapCheckOptions check = options;
  // Measure as the map was made (same method, gains and thresholds).
  check.measurement.parameters = map->metadata().parameters;
  std::unique_ptr<WallClockTickSource> wall_clock;
  if (ticks == nullptr) {
    wall_clock = std::make_unique<WallClockTickSource>(check.measurement.parameters.servo_period_s);
    ticks = wall_clock.get();
  }
  // The raw device: the measurement adds the map's G_hat itself.
  return checkMap(*adapter_, *ticks, *map, check);
}

}  // namespace autograv::chai3d
