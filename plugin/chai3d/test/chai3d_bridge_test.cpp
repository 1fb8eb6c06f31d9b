// The CHAI3D bridge, against the stand-in of CHAI3D 3.3's API (test_mock/chai3d.h, where
// AUTOGRAV_CHAI3D_STAND_IN is defined) or against a real CHAI3D build: a cGenericHapticDevice
// subclass below stands for the hardware either way. The tests of Force Dimension's SDK call need
// the stand-in's recording dhdc.h and run only against it.

#include <cmath>
#include <filesystem>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/chai3d/device_adapter.h"
#include "autograv/chai3d/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#ifdef AUTOGRAV_CHAI3D_STAND_IN
#include "dhdc.h"
#endif

namespace {

using autograv::chai3d::cGravityCompensatedDevice;
using autograv::chai3d::Chai3dDeviceAdapter;
using autograv::chai3d::VendorGravityCompensation;
using chai3d::cVector3d;

/// A CHAI3D driver that answers what the test sets and records what it is sent.
class ScriptedDevice : public chai3d::cGenericHapticDevice {
 public:
  explicit ScriptedDevice(const std::string& manufacturer = "Example Haptics") {
    m_specifications.m_model = chai3d::C_HAPTIC_DEVICE_CUSTOM;
    m_specifications.m_modelName = "example.3";
    m_specifications.m_manufacturerName = manufacturer;
    m_specifications.m_maxLinearForce = 6.0;
    m_specifications.m_maxLinearStiffness = 2500.0;
    m_specifications.m_maxLinearDamping = 15.0;
    m_specifications.m_workspaceRadius = 0.08;
    m_deviceAvailable = true;
  }
  bool open() override {
    ++opens;
    m_deviceReady = open_result;
    return open_result;
  }
  bool close() override {
    ++closes;
    m_deviceReady = false;
    return true;
  }
  bool calibrate(bool a_forceCalibration) override {
    last_calibrate_force = a_forceCalibration;
    return true;
  }
  bool getPosition(cVector3d& a_position) override {
    ++position_reads;
    a_position = position;
    return true;
  }
  bool getLinearVelocity(cVector3d& a_linearVelocity) override {
    a_linearVelocity = cVector3d(0.1, 0.2, 0.3);
    return true;
  }
  bool getRotation(chai3d::cMatrix3d& a_rotation) override {
    a_rotation.identity();
    a_rotation(0, 1) = 0.5;
    return true;
  }
  bool getJointAnglesRad(double a_jointAnglesRad[chai3d::C_MAX_DOF]) override {
    a_jointAnglesRad[0] = 0.25;
    return true;
  }
  bool getAngularVelocity(cVector3d& a_angularVelocity) override {
    a_angularVelocity = cVector3d(1.0, 2.0, 3.0);
    return true;
  }
  bool getTransform(chai3d::cTransform& a_transform) override {
    chai3d::cMatrix3d rotation;  // CHAI3D's default constructor leaves it uninitialised
    rotation.identity();
    a_transform.set(cVector3d(7.0, 8.0, 9.0), rotation);
    return true;
  }
  bool getGripperAngleRad(double& a_angle) override {
    a_angle = 0.4;
    return true;
  }
  bool getGripperAngularVelocity(double& a_gripperAngularVelocity) override {
    a_gripperAngularVelocity = 0.6;
    return true;
  }
  bool getForce(cVector3d& a_force) override {
    a_force = m_prevForce;
    return true;
  }
  bool getTorque(cVector3d& a_torque) override {
    a_torque = m_prevTorque;
    return true;
  }
  bool getGripperForce(double& a_gripperForce) override {
    a_gripperForce = m_prevGripperForce;
    return true;
  }
  bool getUserSwitch(int a_switchIndex, bool& a_status) override {
    last_switch_index = a_switchIndex;
    a_status = true;
    return true;
  }
  bool getUserSwitches(unsigned int& a_userSwitches) override {
    a_userSwitches = 0x5;
    return true;
  }
  void setEnableGripperUserSwitch(const bool a_status) override { gripper_switch = a_status; }
  bool getEnableGripperUserSwitch() const override { return gripper_switch; }
  bool setForceAndTorqueAndGripperForce(const cVector3d& a_force, const cVector3d& a_torque,
                                        double a_gripperForce) override {
    ++writes;
    m_prevForce = a_force;
    m_prevTorque = a_torque;
    m_prevGripperForce = a_gripperForce;
    sent_force = a_force;
    sent_torque = a_torque;
    sent_gripper_force = a_gripperForce;
    return true;
  }
  bool enableForces(bool a_value) override {
    forces_enabled = a_value;
    return true;
  }

  cVector3d position{0.01, -0.02, 0.005};
  cVector3d sent_force{-99.0, -99.0, -99.0};
  cVector3d sent_torque;
  double sent_gripper_force = -99.0;
  bool open_result = true;
  int opens = 0;
  int closes = 0;
  int writes = 0;
  int position_reads = 0;
  bool last_calibrate_force = false;
  int last_switch_index = -1;
  bool gripper_switch = false;
  bool forces_enabled = false;
};

std::shared_ptr<const autograv::GravityMap> constantMap(const Eigen::Vector3d& gravity_n,
                                                        const std::string& model = "example.3") {
  const autograv::WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 3);
  std::vector<autograv::VertexEstimate> vertices(27);
  for (auto& vertex : vertices) {
    vertex.gravity_n = gravity_n;
    vertex.outcome = autograv::VertexOutcome::kConverged;
  }
  autograv::MapMetadata metadata;
  metadata.device_model = model;
  metadata.created_utc = "2026-11-23T13:25:00Z";
  return std::make_shared<const autograv::GravityMap>(grid, std::move(vertices), metadata);
}

autograv::CompensationOptions noRamp() {
  autograv::CompensationOptions options;
  options.ramp_duration_s = 0.0;
  return options;
}

void expectNear(const cVector3d& a, const Eigen::Vector3d& b) {
  EXPECT_NEAR(a.x(), b.x(), 1e-12);
  EXPECT_NEAR(a.y(), b.y(), 1e-12);
  EXPECT_NEAR(a.z(), b.z(), 1e-12);
}

// --- cGravityCompensatedDevice ----------------------------------------------------------------

TEST(Chai3dBridgeTest, OpenCopiesTheSpecificationsForTheNonVirtualGetter) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  // Before open(): CHAI3D's placeholder, not the wrapped device's (whose m_model CHAI3D 3.3
  // leaves uninitialised until open()).
  EXPECT_EQ(device->getSpecifications().m_modelName, "no device");
  EXPECT_EQ(device->getSpecifications().m_model, chai3d::C_HAPTIC_DEVICE_VIRTUAL);
  raw->m_specifications.m_modelName = "example.3b";  // a driver that learns more in open()
  EXPECT_FALSE(device->isDeviceReady());
  ASSERT_TRUE(device->open());
  EXPECT_EQ(raw->opens, 1);
  EXPECT_TRUE(device->isDeviceReady());
  EXPECT_TRUE(device->isDeviceAvailable());
  EXPECT_EQ(device->getSpecifications().m_modelName, "example.3b");
  EXPECT_EQ(device->getSpecifications().m_model, chai3d::C_HAPTIC_DEVICE_CUSTOM);
  EXPECT_EQ(device->getSpecifications().m_maxLinearForce, 6.0);
  EXPECT_EQ(device->compensation().specifications().model_name, "example.3b");
  EXPECT_TRUE(device->close());
  EXPECT_EQ(raw->closes, 1);
  EXPECT_FALSE(device->isDeviceReady());
  EXPECT_EQ(device->getSpecifications().m_modelName, "example.3b");  // those last opened
}

#ifdef AUTOGRAV_CHAI3D_STAND_IN
TEST(Chai3dBridgeTest, TheWrappedDevicesSpecificationsAreNeverCopiedBeforeOpen) {
  int& copies = chai3d::cGenericHapticDevice::mockSpecificationCopiesBeforeOpen();
  copies = 0;
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  Chai3dDeviceAdapter adapter(raw);
  EXPECT_THROW(device->loadAndPublishMap("unused.json"), autograv::Error);
  ASSERT_TRUE(device->open());
  ASSERT_TRUE(device->calibrate(false));
  EXPECT_EQ(copies, 0);
}
#endif

TEST(Chai3dBridgeTest, OutsideTheMapTheApplicationsForcePasses) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  device->compensation().publishMap(constantMap(Eigen::Vector3d(0.0, 0.0, 0.8)));
  raw->position = cVector3d(0.08, 0.0, 0.0);  // 30 mm beyond the map's +x face
  for (int k = 0; k < 10; ++k) {
    ASSERT_TRUE(device->setForce(cVector3d(-1.5, 0.0, 0.0))) << k;
    expectNear(raw->sent_force, Eigen::Vector3d(-1.5, 0.0, 0.8));
  }
  EXPECT_TRUE(device->compensation().outsideMap());
  EXPECT_EQ(device->compensation().faultCount(), 0u);
}

TEST(Chai3dBridgeTest, TheNonVirtualSetForceIsCompensated) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  const Eigen::Vector3d gravity(0.0, 0.0, 1.5);
  device->compensation().publishMap(constantMap(gravity));
  // A CHAI3D application holds a cGenericHapticDevicePtr and calls the non-virtual setForce.
  chai3d::cGenericHapticDevicePtr as_chai3d = device;
  ASSERT_TRUE(as_chai3d->setForce(cVector3d(0.5, 0.0, 0.0)));
  expectNear(raw->sent_force, Eigen::Vector3d(0.5, 0.0, 1.5));
  ASSERT_TRUE(as_chai3d->setForceAndTorque(cVector3d(0.0, 0.1, 0.0), cVector3d(0.0, 0.0, 0.02)));
  expectNear(raw->sent_force, Eigen::Vector3d(0.0, 0.1, 1.5));
  expectNear(raw->sent_torque, Eigen::Vector3d(0.0, 0.0, 0.02));
  ASSERT_TRUE(
      as_chai3d->setForceAndTorqueAndGripperForce(cVector3d(0, 0, 0), cVector3d(0, 0, 0), 0.75));
  EXPECT_EQ(raw->sent_gripper_force, 0.75);
  EXPECT_EQ(raw->writes, 3);
  cVector3d sent;
  ASSERT_TRUE(as_chai3d->getForce(sent));  // what reached the device, compensation included
  expectNear(sent, gravity);
}

TEST(Chai3dBridgeTest, TheForceIsClampedToTheDevicesMaximum) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  device->compensation().publishMap(constantMap(Eigen::Vector3d(0.0, 0.0, 2.0)));
  device->setForce(cVector3d(0.0, 0.0, 10.0));
  expectNear(raw->sent_force, Eigen::Vector3d(0.0, 0.0, 6.0));
  EXPECT_EQ(device->compensation().clampCount(), 1u);
}

TEST(Chai3dBridgeTest, AReadingThroughTheBridgeIsTheOneCompensated) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  device->compensation().publishMap(constantMap(Eigen::Vector3d(0.0, 0.0, 1.0)));
  device->setForce(cVector3d(0, 0, 0));  // this thread becomes the servo thread
  const int reads = raw->position_reads;
  cVector3d position;
  ASSERT_TRUE(device->getPosition(position));
  EXPECT_EQ(position.y(), -0.02);
  device->setForce(cVector3d(0, 0, 0));
  EXPECT_EQ(raw->position_reads, reads + 1);  // one driver read per servo tick
}

TEST(Chai3dBridgeTest, ABadPositionSendsZeroForce) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  device->compensation().publishMap(constantMap(Eigen::Vector3d(0.0, 0.0, 1.0)));
  raw->position = cVector3d(NAN, 0.0, 0.0);
  EXPECT_FALSE(device->setForce(cVector3d(1.0, 0.0, 0.0)));
  expectNear(raw->sent_force, Eigen::Vector3d::Zero());
  EXPECT_EQ(device->compensation().activeFault(), autograv::ServoFault::kNonFinitePosition);
}

TEST(Chai3dBridgeTest, EveryOtherVirtualMethodIsForwarded) {
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  EXPECT_TRUE(device->calibrate(true));
  EXPECT_TRUE(raw->last_calibrate_force);
  cVector3d v;
  ASSERT_TRUE(device->getLinearVelocity(v));
  EXPECT_EQ(v.z(), 0.3);
  chai3d::cMatrix3d rotation;
  ASSERT_TRUE(device->getRotation(rotation));
  EXPECT_EQ(rotation(0, 1), 0.5);
  double joints[chai3d::C_MAX_DOF] = {};
  ASSERT_TRUE(device->getJointAnglesRad(joints));
  EXPECT_EQ(joints[0], 0.25);
  ASSERT_TRUE(device->getAngularVelocity(v));
  EXPECT_EQ(v.y(), 2.0);
  chai3d::cTransform transform;
  ASSERT_TRUE(device->getTransform(transform));
  EXPECT_EQ(transform.getLocalPos().x(), 7.0);
  double value = 0.0;
  ASSERT_TRUE(device->getGripperAngleRad(value));
  EXPECT_EQ(value, 0.4);
  ASSERT_TRUE(device->getGripperAngularVelocity(value));
  EXPECT_EQ(value, 0.6);
  device->setForceAndTorqueAndGripperForce(cVector3d(0, 0, 0), cVector3d(0.0, 0.03, 0.0), 1.25);
  ASSERT_TRUE(device->getTorque(v));
  EXPECT_EQ(v.y(), 0.03);
  ASSERT_TRUE(device->getGripperForce(value));
  EXPECT_EQ(value, 1.25);
  bool pressed = false;
  ASSERT_TRUE(device->getUserSwitch(2, pressed));
  EXPECT_TRUE(pressed);
  EXPECT_EQ(raw->last_switch_index, 2);
  unsigned int switches = 0;
  ASSERT_TRUE(device->getUserSwitches(switches));
  EXPECT_EQ(switches, 0x5u);
  device->setEnableGripperUserSwitch(true);
  EXPECT_TRUE(raw->gripper_switch);
  EXPECT_TRUE(device->getEnableGripperUserSwitch());
  EXPECT_TRUE(device->enableForces(true));
  EXPECT_TRUE(raw->forces_enabled);
}

TEST(Chai3dBridgeTest, LoadAndPublishMapChecksTheModel) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() / "autograv-chai3d-bridge-test";
  std::filesystem::create_directories(folder);
  const std::string good = (folder / "example.json").string();
  const std::string other = (folder / "other.json").string();
  autograv::saveMap(*constantMap(Eigen::Vector3d(0.0, 0.0, 0.8)), good);
  autograv::saveMap(*constantMap(Eigen::Vector3d(0.0, 0.0, 0.9), "omega.3"), other);
  auto raw = std::make_shared<ScriptedDevice>();
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  device->loadAndPublishMap(good);
  try {
    device->loadAndPublishMap(other);
    ADD_FAILURE() << "a map for another model was published";
  } catch (const autograv::Error& error) {
    // Worded for the API's user: what to call, not a command-line flag.
    const std::string message = error.what();
    EXPECT_NE(message.find("allow_model_mismatch"), std::string::npos) << message;
    EXPECT_EQ(message.find("--"), std::string::npos) << message;
  }
  device->setForce(cVector3d(0, 0, 0));
  expectNear(raw->sent_force, Eigen::Vector3d(0.0, 0.0, 0.8));  // the good map stayed
  std::filesystem::remove_all(folder);
}

// --- Force Dimension's own gravity compensation -----------------------------------------------

#ifdef AUTOGRAV_CHAI3D_STAND_IN

TEST(Chai3dBridgeTest, ForceDimensionCompensationIsSwitchedOffOnOpen) {
  mockDhdState() = MockDhdState{};
  auto raw = std::make_shared<ScriptedDevice>("Force Dimension");
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  ASSERT_TRUE(device->open());
  EXPECT_EQ(mockDhdState().calls, 1);
  EXPECT_EQ(mockDhdState().last_value, DHD_OFF);
  EXPECT_EQ(mockDhdState().last_id, -1);
}

TEST(Chai3dBridgeTest, ACalibrationSwitchesItOffAgain) {
  // The SDK re-initialises a Force Dimension device when it calibrates.
  mockDhdState() = MockDhdState{};
  auto device = cGravityCompensatedDevice::create(
      std::make_shared<ScriptedDevice>("Force Dimension"), noRamp());
  ASSERT_TRUE(device->open());
  ASSERT_TRUE(device->calibrate(true));
  EXPECT_EQ(mockDhdState().calls, 2);
  EXPECT_EQ(mockDhdState().last_value, DHD_OFF);
  mockDhdState().result = -1;  // and a failure there fails the calibration, with the reason
  EXPECT_FALSE(device->calibrate(true));
  EXPECT_NE(device->lastError().find("dhdSetGravityCompensation"), std::string::npos);
}

TEST(Chai3dBridgeTest, OtherDevicesAndLeaveAsIsTouchNothing) {
  mockDhdState() = MockDhdState{};
  auto device = cGravityCompensatedDevice::create(std::make_shared<ScriptedDevice>(), noRamp());
  ASSERT_TRUE(device->open());
  auto fd = cGravityCompensatedDevice::create(std::make_shared<ScriptedDevice>("Force Dimension"),
                                              noRamp(), VendorGravityCompensation::kLeaveAsIs);
  ASSERT_TRUE(fd->open());
  EXPECT_EQ(mockDhdState().calls, 0);
}

TEST(Chai3dBridgeTest, AFailureToSwitchItOffFailsOpenWithAReason) {
  mockDhdState() = MockDhdState{};
  mockDhdState().result = -1;
  auto raw = std::make_shared<ScriptedDevice>("Force Dimension");
  auto device = cGravityCompensatedDevice::create(raw, noRamp());
  EXPECT_FALSE(device->open());
  EXPECT_NE(device->lastError().find("dhdSetGravityCompensation"), std::string::npos)
      << device->lastError();
  EXPECT_EQ(raw->closes, 1);  // not left open with two compensations
  EXPECT_FALSE(device->isDeviceReady());
  mockDhdState() = MockDhdState{};
}
#endif  // AUTOGRAV_CHAI3D_STAND_IN

// --- Chai3dDeviceAdapter ----------------------------------------------------------------------

TEST(Chai3dBridgeTest, TheAdapterPresentsAChai3dDeviceAsAnAutogravDevice) {
  auto raw = std::make_shared<ScriptedDevice>();
  Chai3dDeviceAdapter adapter(raw);
  EXPECT_EQ(adapter.specifications().model_name, "");  // read in open(), not before
  ASSERT_TRUE(adapter.open());
  const autograv::DeviceSpecifications& specs = adapter.specifications();
  EXPECT_EQ(specs.model_name, "example.3");
  EXPECT_EQ(specs.manufacturer, "Example Haptics");
  EXPECT_EQ(specs.max_linear_force_n, 6.0);
  EXPECT_EQ(specs.max_linear_stiffness_n_per_m, 2500.0);
  EXPECT_EQ(specs.max_linear_damping_n_s_per_m, 15.0);
  EXPECT_EQ(specs.workspace_radius_m, 0.08);
  EXPECT_NO_THROW(autograv::validateSpecifications(specs));
  Eigen::Vector3d v;
  ASSERT_TRUE(adapter.getPosition(v));
  EXPECT_EQ(v, Eigen::Vector3d(0.01, -0.02, 0.005));
  ASSERT_TRUE(adapter.getLinearVelocity(v));
  EXPECT_EQ(v, Eigen::Vector3d(0.1, 0.2, 0.3));
  bool pressed = false;
  ASSERT_TRUE(adapter.getUserSwitch(1, pressed));
  EXPECT_TRUE(pressed);
  ASSERT_TRUE(adapter.setForce(Eigen::Vector3d(0.1, 0.2, 0.3)));
  expectNear(raw->sent_force, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_TRUE(adapter.calibrate(true));
  EXPECT_TRUE(raw->last_calibrate_force);
  EXPECT_TRUE(adapter.close());
  raw->open_result = false;
  EXPECT_FALSE(adapter.open());
  EXPECT_FALSE(adapter.lastError().empty());
  EXPECT_THROW(Chai3dDeviceAdapter(nullptr), autograv::Error);
}

}  // namespace
