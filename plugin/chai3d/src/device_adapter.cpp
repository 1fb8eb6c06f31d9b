#include "autograv/chai3d/device_adapter.h"

#include <utility>

#include "autograv/error.h"

namespace autograv::chai3d {

namespace {

Eigen::Vector3d toEigen(const ::chai3d::cVector3d& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

Chai3dDeviceAdapter::Chai3dDeviceAdapter(::chai3d::cGenericHapticDevicePtr device,
                                         VendorGravityCompensation vendor)
    : device_(std::move(device)), vendor_(vendor) {
  if (!device_) throw Error("Chai3dDeviceAdapter: the CHAI3D device is null");
  // The specifications are read in open() only: before it CHAI3D 3.3 leaves
  // m_specifications.m_model uninitialised, and copying them reads it.
}

DeviceSpecifications Chai3dDeviceAdapter::toSpecifications(
    const ::chai3d::cHapticDeviceInfo& info) {
  DeviceSpecifications specifications;
  specifications.model_name = info.m_modelName;
  specifications.manufacturer = info.m_manufacturerName;
  specifications.max_linear_force_n = info.m_maxLinearForce;
  specifications.max_linear_stiffness_n_per_m = info.m_maxLinearStiffness;
  specifications.max_linear_damping_n_s_per_m = info.m_maxLinearDamping;
  specifications.workspace_radius_m = info.m_workspaceRadius;
  return specifications;
}

bool Chai3dDeviceAdapter::open() {
  last_error_.clear();
  if (!device_->open()) {
    last_error_ = "the CHAI3D device did not open (is it connected and its driver installed?)";
    return false;
  }
  const ::chai3d::cHapticDeviceInfo info = device_->getSpecifications();
  specifications_ = toSpecifications(info);
  if (!applyVendorGravityCompensation(info, vendor_, last_error_)) {
    device_->close();
    return false;
  }
  return true;
}

std::shared_ptr<sim::SimulatedDevice> Chai3dDeviceAdapter::simulation() const {
  const auto* simulated = dynamic_cast<const SimulatedChai3dDevice*>(device_.get());
  return simulated != nullptr ? simulated->simulation() : nullptr;
}

bool Chai3dDeviceAdapter::close() { return device_->close(); }

bool Chai3dDeviceAdapter::calibrate(bool force) {
  last_error_.clear();
  if (!device_->calibrate(force)) return false;
  // A Force Dimension calibration re-initialises the device through the SDK; apply the policy
  // again so that the vendor's compensation cannot come back on behind ours.
  return applyVendorGravityCompensation(device_->getSpecifications(), vendor_, last_error_);
}

bool Chai3dDeviceAdapter::getPosition(Eigen::Vector3d& position_m) {
  ::chai3d::cVector3d position;
  const bool ok = device_->getPosition(position);
  position_m = toEigen(position);
  return ok;
}

bool Chai3dDeviceAdapter::getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) {
  ::chai3d::cVector3d velocity;
  const bool ok = device_->getLinearVelocity(velocity);
  velocity_m_per_s = toEigen(velocity);
  return ok;
}

bool Chai3dDeviceAdapter::getUserSwitch(int index, bool& pressed) {
  return device_->getUserSwitch(index, pressed);
}

bool Chai3dDeviceAdapter::setForce(const Eigen::Vector3d& force_n) {
  return device_->setForceAndTorqueAndGripperForce(
      ::chai3d::cVector3d(force_n.x(), force_n.y(), force_n.z()), torque_n_m_, gripper_force_n_);
}

}  // namespace autograv::chai3d
