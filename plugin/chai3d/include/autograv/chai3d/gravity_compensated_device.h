#pragma once

#include <memory>
#include <string>

#include "autograv/chai3d/device_adapter.h"
#include "autograv/chai3d/vendor_gravity_compensation.h"
#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/maintenance/map_check.h"
#include "chai3d.h"

namespace autograv::chai3d {

/// A CHAI3D device that adds autograv's gravity compensation to every force: a CHAI3D application
/// swaps it in for the device it got from cHapticDeviceHandler and changes nothing else.
///
///   chai3d::cGenericHapticDevicePtr raw;
///   handler->getDevice(raw, 0);
///   auto device = autograv::chai3d::cGravityCompensatedDevice::create(raw);
///   device->open();                          // then copies m_specifications, see below
///   device->loadAndPublishMap("omega.json"); // checked against the device's model name
///   tool->setHapticDevice(device);           // or call device->setForce(...) yourself
///
/// CHAI3D's setForce and setForceAndTorque are non-virtual and funnel into the virtual
/// setForceAndTorqueAndGripperForce, which this class overrides: every way of commanding a force
/// is compensated. getSpecifications() is non-virtual and returns the member m_specifications, so
/// a successful open() copies the wrapped device's into it (not the constructor: before open()
/// CHAI3D 3.3 leaves their m_model uninitialised); before open() it reports CHAI3D's placeholder.
/// Every other virtual method is forwarded to the wrapped device (CHAI3D's base class would
/// otherwise answer with quiet defaults).
///
/// The compensation itself is autograv::GravityCompensatedDevice (ramps, clamping to
/// m_maxLinearForce, faults, lock-free map swaps): reach it with compensation(). The linear force
/// is zero only when the position cannot be trusted (failed read, NaN/Inf, frozen driver);
/// outside the map the application's force passes and compensation continues with the map
/// extended from its boundary (compensation().outsideMap() says so). The torque and gripper force
/// always pass unchanged, since they do not depend on the position. Ramps and windows are in
/// seconds of a steady clock, so they last as long on a free-running haptic loop at any rate.
class cGravityCompensatedDevice final : public ::chai3d::cGenericHapticDevice {
 public:
  /// Throws autograv::Error for a null device or unusable options. Not real-time safe.
  explicit cGravityCompensatedDevice(
      ::chai3d::cGenericHapticDevicePtr device, const CompensationOptions& options = {},
      VendorGravityCompensation vendor = VendorGravityCompensation::kDisable);
  ~cGravityCompensatedDevice() override;

  /// Shared allocator, as CHAI3D's devices have. Not real-time safe.
  static std::shared_ptr<cGravityCompensatedDevice> create(
      ::chai3d::cGenericHapticDevicePtr device, const CompensationOptions& options = {},
      VendorGravityCompensation vendor = VendorGravityCompensation::kDisable) {
    return std::make_shared<cGravityCompensatedDevice>(std::move(device), options, vendor);
  }

  // --- cGenericHapticDevice: all forwarded; open/close/calibrate are not real-time safe, the
  // rest are real-time safe when the wrapped driver's are.
  /// Opens the wrapped device and the decorator (compensation ramps in from zero). Not real-time
  /// safe.
  bool open() override;
  /// Closes the wrapped device (zero force first). Not real-time safe.
  bool close() override;
  /// Homes the wrapped device (its calibrate). Not real-time safe.
  bool calibrate(bool a_forceCalibration = false) override;
  /// Forwards to the wrapped CHAI3D device's getPosition. Unit: [m]
  bool getPosition(::chai3d::cVector3d& a_position) override;
  /// Forwards to the wrapped CHAI3D device's getLinearVelocity. Unit: [m/s]
  bool getLinearVelocity(::chai3d::cVector3d& a_linearVelocity) override;
  /// Forwards to the wrapped CHAI3D device's getRotation.
  bool getRotation(::chai3d::cMatrix3d& a_rotation) override;
  /// Forwards to the wrapped CHAI3D device's getJointAnglesRad. Unit: [rad]
  bool getJointAnglesRad(double a_jointAnglesRad[::chai3d::C_MAX_DOF]) override;
  /// Forwards to the wrapped CHAI3D device's getAngularVelocity. Unit: [rad/s]
  bool getAngularVelocity(::chai3d::cVector3d& a_angularVelocity) override;
  /// Forwards to the wrapped CHAI3D device's getTransform.
  bool getTransform(::chai3d::cTransform& a_transform) override;
  /// Forwards to the wrapped CHAI3D device's getGripperAngleRad. Unit: [rad]
  bool getGripperAngleRad(double& a_angle) override;
  /// Forwards to the wrapped CHAI3D device's getGripperAngularVelocity. Unit: [rad/s]
  bool getGripperAngularVelocity(double& a_gripperAngularVelocity) override;
  /// The force last sent to the wrapped device, compensation included.
  bool getForce(::chai3d::cVector3d& a_force) override;
  /// The torque last sent to the wrapped device. Unit: [N m]
  bool getTorque(::chai3d::cVector3d& a_torque) override;
  /// The gripper force last sent to the wrapped device. Unit: [N]
  bool getGripperForce(double& a_gripperForce) override;
  /// Forwards to the wrapped CHAI3D device's getUserSwitch.
  bool getUserSwitch(int a_switchIndex, bool& a_status) override;
  /// Forwards to the wrapped CHAI3D device's getUserSwitches.
  bool getUserSwitches(unsigned int& a_userSwitches) override;
  /// Forwards to the wrapped CHAI3D device's setEnableGripperUserSwitch.
  void setEnableGripperUserSwitch(const bool a_status) override;
  /// Forwards to the wrapped CHAI3D device's getEnableGripperUserSwitch.
  bool getEnableGripperUserSwitch() const override;
  /// Sends a_force + G_hat(X) (see the class comment). Real-time safe when the driver's is.
  bool setForceAndTorqueAndGripperForce(const ::chai3d::cVector3d& a_force,
                                        const ::chai3d::cVector3d& a_torque,
                                        double a_gripperForce) override;
  /// Forwards to the wrapped CHAI3D device's enableForces.
  bool enableForces(bool a_value) override;

  // --- autograv side --------------------------------------------------------------------------
  /// Publish maps, switch compensation, read faults and counters. Any thread, see
  /// GravityCompensatedDevice.
  GravityCompensatedDevice& compensation() noexcept { return *compensated_; }
  /// Loads a map file and publishes it; the first map fades in like every later one. Call after
  /// open(). Throws autograv::Error (unreadable file, device not open, a map made for another
  /// device model unless `allow_model_mismatch`); the previous map stays in use on failure.
  /// Not real-time safe.
  void loadAndPublishMap(const std::string& path, bool allow_model_mismatch = false);
  /// Loads this device's map from the map library (autograv::loadMapForDevice: by model and
  /// serial; `maps_dir` empty: $XDG_DATA_HOME/autograv/maps) and publishes it. Call after open().
  /// Throws autograv::Error naming the folder and the maps it holds when none fits.
  /// Not real-time safe.
  void loadAndPublishMapForDevice(const std::string& maps_dir = {});
  /// Opt-in start-up health check (what `autograv check` does): for about ten seconds the device
  /// holds itself at a few vertices of the published map, hands off, and the result says whether
  /// the map still fits or should be re-tared or made again. Run it after open() and before the
  /// application's servo loop; it drives the device itself with the map's own estimation
  /// parameters (options.measurement.parameters is ignored), paced by `ticks` (null: the wall
  /// clock at the map's servo period), and leaves the published map as it was. Throws
  /// autograv::Error when no map is published. Not real-time safe.
  MapCheckResult checkPublishedMap(const MapCheckOptions& options = {},
                                   TickSource* ticks = nullptr);
  /// Why the last open() failed (empty when it did not). Not real-time safe.
  const std::string& lastError() const { return adapter_->lastError(); }
  /// The wrapped CHAI3D device.
  const ::chai3d::cGenericHapticDevicePtr& wrappedDevice() const { return device_; }

 private:
  void copyAvailability();

  ::chai3d::cGenericHapticDevicePtr device_;
  std::shared_ptr<Chai3dDeviceAdapter> adapter_;
  std::unique_ptr<GravityCompensatedDevice> compensated_;
};

}  // namespace autograv::chai3d
