// A minimal stand-in for CHAI3D 3.3's "chai3d.h", written from our reading of CHAI3D's
// documented API (src/devices/CGenericHapticDevice.h, CGenericDevice.h, math/CVector3d.h): only
// the declarations the autograv bridge uses, with the same names, signatures, virtual/non-virtual
// split and quiet defaults. It lets the bridge compile and be tested where CHAI3D is not
// installed. It checks our code against OUR READING of the 3.3 API, not against CHAI3D itself:
// build against a real CHAI3D (-DAUTOGRAV_CHAI3D_DIR=<its build folder>) before relying on it.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace chai3d {

// CHAI3D's success/error convention for bool results.
const bool C_SUCCESS = true;
const bool C_ERROR = false;
const int C_MAX_DOF = 16;

struct cVector3d {
  cVector3d() {}
  cVector3d(const double a_x, const double a_y, const double a_z) { set(a_x, a_y, a_z); }
  double& operator()(int i) { return m_data[i]; }
  double operator()(int i) const { return m_data[i]; }
  double x() const { return m_data[0]; }
  double y() const { return m_data[1]; }
  double z() const { return m_data[2]; }
  void x(const double a_value) { m_data[0] = a_value; }
  void y(const double a_value) { m_data[1] = a_value; }
  void z(const double a_value) { m_data[2] = a_value; }
  void zero() { set(0.0, 0.0, 0.0); }
  void set(const double& a_x, const double& a_y, const double& a_z) {
    m_data[0] = a_x;
    m_data[1] = a_y;
    m_data[2] = a_z;
  }

 private:
  double m_data[3] = {0.0, 0.0, 0.0};
};

struct cMatrix3d {
  void identity() {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) m_data[r][c] = r == c ? 1.0 : 0.0;
  }
  double& operator()(int r, int c) { return m_data[r][c]; }
  double operator()(int r, int c) const { return m_data[r][c]; }

 private:
  // Left uninitialised by the default constructor, as in CHAI3D 3.3: code that reads a
  // default-constructed matrix is caught here (-Wuninitialized) as against the real headers.
  double m_data[3][3];
};

// CHAI3D's cTransform keeps a 4x4 matrix; the bridge only needs set() and the two getters.
class cTransform {
 public:
  cTransform() {
    m_position = cVector3d(0.0, 0.0, 0.0);
    m_rotation.identity();  // as CHAI3D's constructor does
  }
  void set(const cVector3d& a_position, const cMatrix3d& a_rotation) {
    m_position = a_position;
    m_rotation = a_rotation;
  }
  cVector3d getLocalPos() const { return m_position; }
  cMatrix3d getLocalRot() const { return m_rotation; }

 private:
  cVector3d m_position;
  cMatrix3d m_rotation;
};

// The device list of CHAI3D 3.3 (3.2 had OMEGA_6, OMEGA_7, SIGMA_6P, SIGMA_7, XTH_1, ...).
enum cHapticDeviceModel {
  C_HAPTIC_DEVICE_VIRTUAL,
  C_HAPTIC_DEVICE_DELTA_3,
  C_HAPTIC_DEVICE_DELTA_6,
  C_HAPTIC_DEVICE_OMEGA_3,
  C_HAPTIC_DEVICE_OMEGA_6L,
  C_HAPTIC_DEVICE_OMEGA_6R,
  C_HAPTIC_DEVICE_OMEGA_7L,
  C_HAPTIC_DEVICE_OMEGA_7R,
  C_HAPTIC_DEVICE_SIGMA_6L,
  C_HAPTIC_DEVICE_SIGMA_6R,
  C_HAPTIC_DEVICE_SIGMA_7L,
  C_HAPTIC_DEVICE_SIGMA_7R,
  C_HAPTIC_DEVICE_LAMBDA_7L,
  C_HAPTIC_DEVICE_LAMBDA_7R,
  C_HAPTIC_DEVICE_FALCON,
  C_HAPTIC_DEVICE_MPR,
  C_HAPTIC_DEVICE_PHANTOM_TOUCH,
  C_HAPTIC_DEVICE_PHANTOM_OMNI,
  C_HAPTIC_DEVICE_PHANTOM_DESKTOP,
  C_HAPTIC_DEVICE_PHANTOM_15_6DOF,
  C_HAPTIC_DEVICE_PHANTOM_30_6DOF,
  C_HAPTIC_DEVICE_PHANTOM_OTHER,
  C_TRACKER_DEVICE_SIXENSE,
  C_TRACKER_DEVICE_LEAP,
  C_HAPTIC_DEVICE_CUSTOM
};

struct cHapticDeviceInfo {
  // CHAI3D 3.3 leaves m_model uninitialised until a driver's open() (or its constructor) sets
  // it, so copying the specifications of a device that is not open yet loads an indeterminate
  // enum. A stand-in cannot hold an indeterminate value; it counts such copies instead (see
  // cGenericHapticDevice::getSpecifications below).
  cHapticDeviceModel m_model = C_HAPTIC_DEVICE_VIRTUAL;
  std::string m_modelName;
  std::string m_manufacturerName;
  double m_maxLinearForce = 0.0;
  double m_maxAngularTorque = 0.0;
  double m_maxGripperForce = 0.0;
  double m_maxLinearStiffness = 0.0;
  double m_maxAngularStiffness = 0.0;
  double m_maxGripperLinearStiffness = 0.0;
  double m_maxLinearDamping = 0.0;
  double m_maxAngularDamping = 0.0;
  double m_maxGripperAngularDamping = 0.0;
  double m_workspaceRadius = 0.0;
  double m_gripperMaxAngleRad = 0.0;
  bool m_sensedPosition = false;
  bool m_sensedRotation = false;
  bool m_sensedGripper = false;
  bool m_actuatedPosition = false;
  bool m_actuatedRotation = false;
  bool m_actuatedGripper = false;
  bool m_leftHand = false;
  bool m_rightHand = false;
};

class cGenericDevice {
 public:
  cGenericDevice(unsigned int a_deviceNumber = 0)
      : m_deviceAvailable(false),
        m_deviceReady(false),
        m_deviceNumber(static_cast<int>(a_deviceNumber)) {}
  virtual ~cGenericDevice() {}
  virtual bool open() { return C_ERROR; }
  virtual bool close() { return C_ERROR; }
  bool isDeviceAvailable() { return m_deviceAvailable; }
  bool isDeviceReady() { return m_deviceReady; }

 protected:
  bool m_deviceAvailable;
  bool m_deviceReady;
  int m_deviceNumber;
};

class cGenericHapticDevice;
typedef std::shared_ptr<cGenericHapticDevice> cGenericHapticDevicePtr;

// Quiet defaults, as in CHAI3D: a subclass that forgets an override silently gets these.
class cGenericHapticDevice : public cGenericDevice {
 public:
  cGenericHapticDevice(unsigned int a_deviceNumber = 0)
      : cGenericDevice(a_deviceNumber),
        m_prevGripperForce(0.0),
        m_gripperAngularVelocity(0.0),
        m_gripperUserSwitchEnabled(false) {
    // CHAI3D's constructor fills in a placeholder device: a subclass that forgets to set its
    // specifications reports these.
    m_specifications.m_manufacturerName = "CHAI3D";
    m_specifications.m_modelName = "no device";
    m_specifications.m_maxLinearForce = 0.1;
    m_specifications.m_maxLinearStiffness = 0.1;
    m_specifications.m_workspaceRadius = 0.1;
  }
  virtual ~cGenericHapticDevice() {}

  virtual bool open() { return C_ERROR; }
  virtual bool close() { return C_ERROR; }
  virtual bool calibrate(bool a_forceCalibration = false) {
    (void)a_forceCalibration;
    return m_deviceReady;
  }
  virtual bool getPosition(cVector3d& a_position) {
    a_position.zero();
    return m_deviceReady;
  }
  virtual bool getLinearVelocity(cVector3d& a_linearVelocity) {
    a_linearVelocity = m_linearVelocity;
    return m_deviceReady;
  }
  virtual bool getRotation(cMatrix3d& a_rotation) {
    a_rotation.identity();
    return m_deviceReady;
  }
  virtual bool getJointAnglesRad(double a_jointAnglesRad[C_MAX_DOF]) {
    (void)a_jointAnglesRad;
    return C_ERROR;
  }
  virtual bool getAngularVelocity(cVector3d& a_angularVelocity) {
    a_angularVelocity = m_angularVelocity;
    return m_deviceReady;
  }
  virtual bool getTransform(cTransform& a_transform) {
    cVector3d position;
    cMatrix3d rotation;
    const bool position_ok = getPosition(position);
    const bool rotation_ok = getRotation(rotation);
    a_transform.set(position, rotation);
    return position_ok || rotation_ok;  // CHAI3D: either reading counts as success
  }
  virtual bool getGripperAngleRad(double& a_angle) {
    a_angle = 0.0;
    return m_deviceReady;
  }
  virtual bool getGripperAngularVelocity(double& a_gripperAngularVelocity) {
    a_gripperAngularVelocity = m_gripperAngularVelocity;
    return m_deviceReady;
  }
  virtual bool getForce(cVector3d& a_force) {
    a_force = m_prevForce;
    return m_deviceReady;
  }
  virtual bool getTorque(cVector3d& a_torque) {
    a_torque = m_prevTorque;
    return m_deviceReady;
  }
  virtual bool getGripperForce(double& a_gripperForce) {
    a_gripperForce = m_prevGripperForce;
    return m_deviceReady;
  }
  virtual bool getUserSwitch(int a_switchIndex, bool& a_status) {
    unsigned int switches = 0;
    if (!getUserSwitches(switches)) {
      a_status = false;
      return C_ERROR;
    }
    a_status = (switches >> a_switchIndex) & 1u;
    return C_SUCCESS;
  }
  virtual bool getUserSwitches(unsigned int& a_userSwitches) {
    a_userSwitches = 0;
    return m_deviceReady;
  }
  // Non-virtual, returns a copy of the public member: a wrapper must copy m_specifications.
  cHapticDeviceInfo getSpecifications() {
    if (!m_deviceReady) ++mockSpecificationCopiesBeforeOpen();
    return m_specifications;
  }
  /// Stand-in only: copies of the specifications taken while the device was not open, each of
  /// which reads CHAI3D 3.3's uninitialised m_model.
  static int& mockSpecificationCopiesBeforeOpen() {
    static int copies = 0;
    return copies;
  }
  virtual void setEnableGripperUserSwitch(const bool a_status) {
    m_gripperUserSwitchEnabled = a_status;
  }
  virtual bool getEnableGripperUserSwitch() const { return m_gripperUserSwitchEnabled; }
  // Non-virtual: both funnel into setForceAndTorqueAndGripperForce.
  bool setForce(const cVector3d& a_force) {
    return setForceAndTorqueAndGripperForce(a_force, cVector3d(0.0, 0.0, 0.0), 0.0);
  }
  bool setForceAndTorque(const cVector3d& a_force, const cVector3d& a_torque) {
    return setForceAndTorqueAndGripperForce(a_force, a_torque, 0.0);
  }
  virtual bool setForceAndTorqueAndGripperForce(const cVector3d& a_force, const cVector3d& a_torque,
                                                double a_gripperForce) {
    (void)a_force;
    (void)a_torque;
    (void)a_gripperForce;
    return m_deviceReady;
  }
  virtual bool enableForces(bool a_value) {
    (void)a_value;
    return true;
  }

  cHapticDeviceInfo m_specifications;

 protected:
  cVector3d m_prevForce;
  cVector3d m_prevTorque;
  double m_prevGripperForce;
  cVector3d m_linearVelocity;
  cVector3d m_angularVelocity;
  double m_gripperAngularVelocity;
  bool m_gripperUserSwitchEnabled;
};

// Stand-in only (not CHAI3D API): the devices "connected" to this machine, which the handler
// below enumerates. Defined by test_mock/stand_in_devices.cpp: simulated devices named by the
// environment variable AUTOGRAV_STANDIN_DEVICES (e.g. "sim:omni,sim:omega"; unset: none).
std::vector<cGenericHapticDevicePtr> standInConnectedDevices();

// CHAI3D 3.3's device handler: enumerates the connected devices when constructed.
class cHapticDeviceHandler {
 public:
  cHapticDeviceHandler() { update(); }
  virtual ~cHapticDeviceHandler() {}
  bool update() {
    m_devices = standInConnectedDevices();
    return C_SUCCESS;
  }
  unsigned int getNumDevices() { return static_cast<unsigned int>(m_devices.size()); }
  bool getDeviceSpecifications(cHapticDeviceInfo& a_deviceSpecifications,
                               unsigned int a_index = 0) {
    if (a_index >= m_devices.size()) return C_ERROR;
    a_deviceSpecifications = m_devices[a_index]->getSpecifications();
    return C_SUCCESS;
  }
  bool getDevice(cGenericHapticDevicePtr& a_hapticDevice, unsigned int a_index = 0) {
    if (a_index >= m_devices.size()) return C_ERROR;
    a_hapticDevice = m_devices[a_index];
    return C_SUCCESS;
  }

 private:
  std::vector<cGenericHapticDevicePtr> m_devices;
};

}  // namespace chai3d
