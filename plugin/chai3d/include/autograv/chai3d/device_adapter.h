#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "autograv/chai3d/simulated_chai3d_device.h"
#include "autograv/chai3d/vendor_gravity_compensation.h"
#include "autograv/device/haptic_device.h"
#include "chai3d.h"

namespace autograv::chai3d {

/// Presents any CHAI3D device as an autograv::HapticDevice, so that the calibrator, the wizard and
/// GravityCompensatedDevice run on every device CHAI3D supports. Same frame and units (CHAI3D's are
/// SI, x toward the operator, z up); cVector3d is converted to Eigen component by component.
///
/// specifications() is the copy of the device's m_specifications taken at construction and again
/// in open() (CHAI3D's getSpecifications() is non-virtual and copies strings: never in the servo
/// path). serial_number stays empty: CHAI3D does not report one.
class Chai3dDeviceAdapter final : public HapticDevice {
 public:
  /// Throws autograv::Error for a null device. Not real-time safe.
  explicit Chai3dDeviceAdapter(
      ::chai3d::cGenericHapticDevicePtr device,
      VendorGravityCompensation vendor = VendorGravityCompensation::kDisable);

  /// Opens the device, copies its specifications and applies the vendor policy; false (see
  /// lastError()) when either fails. Not real-time safe.
  bool open() override;
  /// Not real-time safe.
  bool close() override;
  /// Not real-time safe.
  bool calibrate(bool force = false) override;
  /// Real-time safe when the CHAI3D driver's is. Unit: [m]
  bool getPosition(Eigen::Vector3d& position_m) override;
  /// Real-time safe when the CHAI3D driver's is. Unit: [m/s]
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override;
  /// Real-time safe when the CHAI3D driver's is.
  bool getUserSwitch(int index, bool& pressed) override;
  /// Sends the force with the torque and gripper force set by setTorqueAndGripperForce (zero
  /// unless set). Real-time safe when the CHAI3D driver's is. Unit: [N]
  bool setForce(const Eigen::Vector3d& force_n) override;
  /// Real-time safe.
  const DeviceSpecifications& specifications() const override { return specifications_; }

  /// Torque and gripper force that the following setForce calls send along with the force, for
  /// 6/7-DoF devices driven through this adapter. Real-time safe. Units: [N m], [N]
  void setTorqueAndGripperForce(const ::chai3d::cVector3d& torque_n_m, double gripper_force_n) {
    torque_n_m_ = torque_n_m;
    gripper_force_n_ = gripper_force_n;
  }

  /// Why the last open() failed (empty when it did not). Not real-time safe.
  const std::string& lastError() const { return last_error_; }
  /// The wrapped CHAI3D device.
  const ::chai3d::cGenericHapticDevicePtr& device() const { return device_; }
  /// The simulation behind the CHAI3D device when it is a SimulatedChai3dDevice (the stand-in's
  /// are), null for hardware. Not real-time safe.
  std::shared_ptr<sim::SimulatedDevice> simulation() const;

  /// CHAI3D's description of a device in autograv's terms. Not real-time safe.
  static DeviceSpecifications toSpecifications(const ::chai3d::cHapticDeviceInfo& info);

 private:
  ::chai3d::cGenericHapticDevicePtr device_;
  VendorGravityCompensation vendor_;
  DeviceSpecifications specifications_;
  ::chai3d::cVector3d torque_n_m_{0.0, 0.0, 0.0};
  double gripper_force_n_ = 0.0;
  std::string last_error_;
};

}  // namespace autograv::chai3d
