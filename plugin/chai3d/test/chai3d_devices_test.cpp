// The chai3d: device names end to end against the stand-in: its handler "finds" simulated CHAI3D
// devices (AUTOGRAV_STANDIN_DEVICES), which the registry opens through Chai3dDeviceAdapter, and the
// real `autograv wizard --device chai3d:0 --auto-hand` calibrates one exactly as a sim: device.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "autograv/chai3d/device_adapter.h"
#include "autograv/chai3d/gravity_compensated_device.h"
#include "autograv/devices/device_registry.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "autograv/map/measurement_plan.h"
#include "chai3d.h"
#include "run_command.h"
#include "scaled_map.h"
#include "simulated_haptic_device.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;

nlohmann::json readJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

class Chai3dDevicesTest : public ::testing::Test {
 protected:
  void SetUp() override { ::setenv("AUTOGRAV_STANDIN_DEVICES", "sim:omni,sim:omega", 1); }
  void TearDown() override { ::unsetenv("AUTOGRAV_STANDIN_DEVICES"); }
};

TEST_F(Chai3dDevicesTest, TheHandlerFindsTheStandInDevicesAndTheRegistryListsThem) {
  ::chai3d::cHapticDeviceHandler handler;
  ASSERT_EQ(handler.getNumDevices(), 2u);
  ::chai3d::cHapticDeviceInfo info;
  ASSERT_TRUE(handler.getDeviceSpecifications(info, 1));
  EXPECT_EQ(info.m_modelName, "sim:omega");
  EXPECT_FALSE(handler.getDeviceSpecifications(info, 2));

  ASSERT_TRUE(chai3dDevicesAvailable());
  const std::vector<DeviceListing> devices = listDevices();
  const auto listed = [&devices](const std::string& name) {
    return std::find_if(devices.begin(), devices.end(),
                        [&name](const DeviceListing& device) { return device.name == name; });
  };
  const auto first = listed("chai3d:0");
  ASSERT_NE(first, devices.end());
  EXPECT_EQ(first->specifications.model_name, "sim:omni");
  EXPECT_DOUBLE_EQ(first->specifications.max_linear_force_n, 3.3);
  EXPECT_TRUE(first->specifications.serial_number.empty());  // CHAI3D reports none
  EXPECT_NE(listed("chai3d:1"), devices.end());
  EXPECT_EQ(listed("chai3d:2"), devices.end());
}

TEST_F(Chai3dDevicesTest, AChai3dNameOpensTheAdapterAndExposesTheSimulationBehindIt) {
  const DeviceHandle handle = openDevice("chai3d:1");
  auto* adapter = dynamic_cast<chai3d::Chai3dDeviceAdapter*>(handle.device.get());
  ASSERT_NE(adapter, nullptr);
  ASSERT_NE(handle.simulation, nullptr);
  EXPECT_EQ(adapter->simulation(), handle.simulation);
  EXPECT_EQ(handle.device->specifications().model_name, "sim:omega");
  // Forces and positions go through CHAI3D's API to the simulation and back.
  const Eigen::Vector3d force_n(0.1, -0.2, 0.3);
  ASSERT_TRUE(handle.device->setForce(force_n));
  handle.simulation->advance(2e-3);  // the driver's transport delay is one servo period
  // (the force DAC quantizes it)
  EXPECT_LT((handle.simulation->appliedForce_n() - force_n).norm(), 0.02)
      << handle.simulation->appliedForce_n().transpose();
  Eigen::Vector3d through_adapter_m, direct_m;
  ASSERT_TRUE(handle.device->getPosition(through_adapter_m));
  ASSERT_TRUE(handle.simulation->getPosition(direct_m));
  EXPECT_EQ(through_adapter_m, direct_m);
  handle.simulation->setUserSwitch(0, true);
  bool pressed = false;
  ASSERT_TRUE(handle.device->getUserSwitch(0, pressed));
  EXPECT_TRUE(pressed);
}

TEST_F(Chai3dDevicesTest, HardwareHasNoSimulationAndAMissingIndexSaysHowManyThereAre) {
  auto plain = std::make_shared<::chai3d::cGenericHapticDevice>();
  EXPECT_EQ(chai3d::Chai3dDeviceAdapter(plain).simulation(), nullptr);
  try {
    makeDevice("chai3d:2");
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("CHAI3D sees 2 device(s)"), std::string::npos)
        << error.what();
  }
}

TEST_F(Chai3dDevicesTest, TheTerminalWizardCalibratesAChai3dDeviceWithTheSimulatedHand) {
  const std::string binary = AUTOGRAV_BINARY_DIR "/demo/autograv";
  if (!fs::exists(binary)) GTEST_SKIP() << binary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  const fs::path dir =
      fs::temp_directory_path() / ("autograv_chai3d_wizard_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string map_path = (dir / "omni.json").string();
  const auto devices =
      testing::runCommand("AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary + " devices");
  ASSERT_EQ(devices.exit_code, 0) << devices.output;
  EXPECT_NE(devices.output.find("chai3d:0   sim:omni"), std::string::npos) << devices.output;
  // The stand-in's device is sim:omni with seed 1: the wizard must make the very same map
  // through CHAI3D's API as on the simulation directly.
  const std::string options = " --auto-hand --grid 2 --side-mm 40 --seed 1 --out ";
  const auto wizard = testing::runCommand("AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
                                          " wizard --device chai3d:0" + options + map_path);
  ASSERT_EQ(wizard.exit_code, 0) << wizard.output;
  const std::string direct_path = (dir / "direct.json").string();
  const auto direct =
      testing::runCommand(binary + " wizard --device sim:omni" + options + direct_path);
  ASSERT_EQ(direct.exit_code, 0) << direct.output;
  const GravityMap map = loadMap(map_path);
  EXPECT_EQ(map.metadata().device_model, "sim:omni");
  EXPECT_EQ(map.convergedCount(), 8);
  const GravityMap direct_map = loadMap(direct_path);
  for (std::size_t i = 0; i < map.vertices().size(); ++i) {
    EXPECT_EQ(map.vertices()[i].gravity_n, direct_map.vertices()[i].gravity_n) << i;
  }
  // The map fits the device it was made on, through the same CHAI3D path.
  const auto check = testing::runCommand("AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
                                         " check --device chai3d:0 --map " + map_path);
  EXPECT_EQ(check.exit_code, 0) << check.output;
  fs::remove_all(dir);
}

// verify needs no hand: on chai3d:0 the device carries itself to every point through CHAI3D's
// API, from the driver's data alone, gently (no clamp, nothing near the force limit).
TEST_F(Chai3dDevicesTest, VerifyRunsOnAChai3dDeviceWithNoHand) {
  const std::string binary = AUTOGRAV_BINARY_DIR "/demo/autograv";
  if (!fs::exists(binary)) GTEST_SKIP() << binary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  const fs::path dir =
      fs::temp_directory_path() / ("autograv_chai3d_verify_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string map_path = (dir / "omni.json").string();
  // The stand-in's device is sim:omni: a map of sim:omni, its workspace explored, fits it.
  const auto calibrate =
      testing::runCommand(binary + " calibrate --device sim:omni --seed 1 --out " + map_path);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.output;
  // Ten points: at one of them (the second) friction holds the probe still, which leaves too
  // few probes to judge from with three points, and nine of ten to judge from here.
  const std::string verify_command = "AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
                                     " verify --device chai3d:0 --points 10 --no-uncompensated ";
  const auto verify = testing::runCommand(verify_command + map_path);
  // The map was made on this very device: PASS, and the device got to every point by itself,
  // gently.
  EXPECT_EQ(verify.exit_code, 0) << verify.output;
  EXPECT_NE(verify.output.find("\nPASS\n"), std::string::npos) << verify.output;
  EXPECT_NE(verify.output.find("carries itself there (no hand)"), std::string::npos)
      << verify.output;
  EXPECT_NE(verify.output.find("10 of 10 reached"), std::string::npos) << verify.output;
  EXPECT_NE(verify.output.find(", 0 clamps"), std::string::npos) << verify.output;
  EXPECT_NE(verify.output.find("0 ticks at the limit"), std::string::npos) << verify.output;
  // The same map 5 % too strong: FAIL, with a non-zero exit.
  const std::string off_path = (dir / "off.json").string();
  saveMap(testing::scaledMap(loadMap(map_path), 1.05), off_path);
  const auto off = testing::runCommand(verify_command + off_path);
  EXPECT_EQ(off.exit_code, 1) << off.output;
  EXPECT_NE(off.output.find("\nFAIL\n"), std::string::npos) << off.output;
  fs::remove_all(dir);
}

TEST_F(Chai3dDevicesTest, TheTerminalWizardExploresTheWorkspaceOfAChai3dDeviceAndSavesIt) {
  const std::string binary = AUTOGRAV_BINARY_DIR "/demo/autograv";
  if (!fs::exists(binary)) GTEST_SKIP() << binary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  const fs::path dir =
      fs::temp_directory_path() / ("autograv_chai3d_explore_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string map_path = (dir / "omni.json").string();
  const std::string report_path = (dir / "report.json").string();
  // The default grid: the box around the workspace the wizard explores, through CHAI3D's API
  // (a 3x3x3 grid keeps the run short).
  const auto wizard = testing::runCommand(
      "AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
      " wizard --device chai3d:0 --auto-hand --grid 3 --verify-points 1 --seed 1 --out " +
      map_path + " --report " + report_path);
  ASSERT_EQ(wizard.exit_code, 0) << wizard.output;
  EXPECT_NE(wizard.output.find("[4/8] Explore the workspace"), std::string::npos) << wizard.output;
  EXPECT_NE(wizard.output.find("workspace exploration"), std::string::npos) << wizard.output;
  const GravityMap map = loadMap(map_path);
  EXPECT_EQ(map.metadata().device_model, "sim:omni");
  const ExploredWorkspace& workspace = map.metadata().workspace;
  ASSERT_EQ(workspace.directions().size(), 26u);
  EXPECT_TRUE(map.grid().sameGeometry(gridAroundWorkspace(workspace, Eigen::Vector3i::Constant(3))))
      << map.grid().describe();
  // Through CHAI3D's API exactly what the wizard finds on the simulation directly.
  const std::string direct_path = (dir / "direct.json").string();
  const auto direct = testing::runCommand(binary +
                                          " wizard --device sim:omni --auto-hand --grid 3 "
                                          "--verify-points 1 --seed 1 --out " +
                                          direct_path);
  ASSERT_EQ(direct.exit_code, 0) << direct.output;
  const GravityMap direct_map = loadMap(direct_path);
  EXPECT_EQ(workspace.radii_m(), direct_map.metadata().workspace.radii_m());
  ASSERT_EQ(map.vertices().size(), direct_map.vertices().size());
  for (std::size_t i = 0; i < map.vertices().size(); ++i) {
    EXPECT_EQ(map.vertices()[i].gravity_n, direct_map.vertices()[i].gravity_n) << i;
  }
  int measured_off_vertex = 0;
  for (const VertexEstimate& vertex : map.vertices()) {
    measured_off_vertex +=
        vertex.outcome == VertexOutcome::kConverged && vertex.measuredOffVertex();
  }
  EXPECT_GT(measured_off_vertex, 0);
  EXPECT_GE(map.convergedCount(), 15);
  // The map fits the device it was made on, through the same CHAI3D path, and `verify` runs
  // on it with no hand: the device carries itself to each point.
  const auto check = testing::runCommand("AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
                                         " check --device chai3d:0 --map " + map_path);
  EXPECT_EQ(check.exit_code, 0) << check.output;
  const auto verify = testing::runCommand("AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
                                          " verify --device chai3d:0 --points 4 " + map_path);
  EXPECT_NE(verify.output.find("4 of 4 reached, 4 held at full compensation"), std::string::npos)
      << verify.output;
  fs::remove_all(dir);
}

TEST_F(Chai3dDevicesTest, TheBridgeFindsItsMapInTheLibraryAndChecksItAtStartUp) {
  const std::string binary = AUTOGRAV_BINARY_DIR "/demo/autograv";
  if (!fs::exists(binary)) GTEST_SKIP() << binary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  const fs::path maps =
      fs::temp_directory_path() / ("autograv_chai3d_maps_" + std::to_string(::getpid()));
  fs::remove_all(maps);
  // The wizard files the map of chai3d:0 in the library (no --out).
  const auto wizard = testing::runCommand("AUTOGRAV_STANDIN_DEVICES=sim:omni " + binary +
                                          " wizard --device chai3d:0 --auto-hand --grid 2 "
                                          "--side-mm 40 --seed 3 --verify-points 0 --maps " +
                                          maps.string());
  ASSERT_EQ(wizard.exit_code, 0) << wizard.output;

  ::chai3d::cHapticDeviceHandler handler;
  ::chai3d::cGenericHapticDevicePtr raw;
  ASSERT_TRUE(handler.getDevice(raw, 0));
  auto device = chai3d::cGravityCompensatedDevice::create(raw);
  ASSERT_TRUE(device->open());
  EXPECT_THROW(device->checkPublishedMap(), Error);  // nothing published yet
  device->loadAndPublishMapForDevice(maps.string());
  ASSERT_NE(device->compensation().publishedMap(), nullptr);
  const auto simulation = dynamic_cast<chai3d::SimulatedChai3dDevice&>(*raw).simulation();
  sim::SimulatedTickSource ticks(*simulation, 1e-3,
                                 sim::SimulatedTickSource::Mode::kAsFastAsPossible);
  EXPECT_EQ(device->checkPublishedMap({}, &ticks).fit, MapFit::kFits);
  simulation->setPayload_kg(0.025);
  const MapCheckResult heavier = device->checkPublishedMap({}, &ticks);
  EXPECT_EQ(heavier.fit, MapFit::kRetare) << heavier.reason;
  EXPECT_NEAR(heavier.payload_kg, 0.025, 0.002);

  // Another model has no map there: the error names the folder and what it holds.
  ::chai3d::cGenericHapticDevicePtr omega =
      std::make_shared<chai3d::cSimulatedHapticDevice>(sim::makeSimulatedDevice("sim:omega", 1));
  auto other = chai3d::cGravityCompensatedDevice::create(omega);
  ASSERT_TRUE(other->open());
  try {
    other->loadAndPublishMapForDevice(maps.string());
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("sim_omni.json"), std::string::npos) << error.what();
  }
  fs::remove_all(maps);
}

// --- A device with no simulator behind it -------------------------------------------------
// "hardware:sim:omni" is a plain CHAI3D device that runs a simulation of the Omni inside itself on
// the wall clock (test_mock/hardware_stand_in_device.h): the registry finds no simulation, so the
// commands take their branches for real hardware, which no simulated device reaches.

class HardwareStandInTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(binary_)) GTEST_SKIP() << binary_ << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);  // keep the files of a failed test
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
  /// `arguments` run on the stand-in for hardware, as chai3d:0.
  testing::CommandResult onHardware(const std::string& arguments) const {
    return testing::runCommand("AUTOGRAV_STANDIN_DEVICES=hardware:sim:omni " + binary_ + " " +
                               arguments);
  }
  /// A map of the Omni the stand-in simulates (seed 1): it fits the device.
  std::string omniMap() const {
    const std::string path = file("omni.json");
    const auto calibrate =
        testing::runCommand(binary_ + " calibrate --device sim:omni --seed 1 --out " + path);
    EXPECT_EQ(calibrate.exit_code, 0) << calibrate.output;
    return path;
  }

  const std::string binary_ = AUTOGRAV_BINARY_DIR "/demo/autograv";
  const fs::path dir_ =
      fs::temp_directory_path() / ("autograv_chai3d_hardware_" + std::to_string(::getpid()));
};

TEST_F(HardwareStandInTest, TheRegistryFindsNoSimulationBehindIt) {
  ::setenv("AUTOGRAV_STANDIN_DEVICES", "hardware:sim:omni", 1);
  const DeviceHandle handle = openDevice("chai3d:0");
  ::unsetenv("AUTOGRAV_STANDIN_DEVICES");
  EXPECT_EQ(handle.simulation, nullptr);
  EXPECT_EQ(handle.device->specifications().model_name, "sim:omni");
  // Its time passes on its own: left alone, the arm falls.
  Eigen::Vector3d before_m, after_m;
  ASSERT_TRUE(handle.device->getPosition(before_m));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  ASSERT_TRUE(handle.device->getPosition(after_m));
  EXPECT_GT((after_m - before_m).norm(), 1e-3);
}

// verify on hardware: the wall clock paces the loop, no ground truth is reported, and the verdict
// is the map's: FAIL, with exit status 1, on a map of this device made 5 % too strong (the probe
// reads the 5 %). One point: it takes about a minute and a half of the device's time, here real
// time; PASS on the map itself is VerifyRunsOnAChai3dDeviceWithNoHand's, through the same API.
TEST_F(HardwareStandInTest, VerifyFailsAMapFivePercentOffOnHardware) {
  const std::string off_path = file("off.json");
  saveMap(testing::scaledMap(loadMap(omniMap()), 1.05), off_path);
  const auto failed =
      onHardware("verify --device chai3d:0 --points 1 --no-uncompensated --duration-s 0.5 " +
                 off_path + " --report " + file("off.report.json"));
  EXPECT_EQ(failed.exit_code, 1) << failed.output;
  EXPECT_NE(failed.output.find("\nFAIL\n"), std::string::npos) << failed.output;
  EXPECT_NE(failed.output.find("on sim:omni (hardware)"), std::string::npos) << failed.output;
  EXPECT_EQ(failed.output.find("Simulation only"), std::string::npos) << failed.output;
  EXPECT_NE(failed.output.find("servo thread"), std::string::npos) << failed.output;
  EXPECT_NE(failed.output.find("1 of 1 reached, 1 held at full compensation"), std::string::npos)
      << failed.output;
  const nlohmann::json report = readJson(file("off.report.json"));
  EXPECT_NEAR(report.at("residual_force_median_rel").get<double>(), 0.05, 0.015) << failed.output;
  EXPECT_FALSE(report.at("simulated").get<bool>());
  EXPECT_FALSE(report.contains("truth_error_median_n")) << report.dump(2);
  EXPECT_FALSE(report.contains("servo_loop")) << report.dump(2);
  EXPECT_TRUE(report.contains("servo_real_time_priority")) << report.dump(2);
}

// check and retare on hardware: the wall clock paces them, no truth is scored, and what only a
// simulation can do (load the end-effector) is refused with the reason.
TEST_F(HardwareStandInTest, CheckAndRetareRunOnHardware) {
  const std::string map_path = omniMap();
  const auto check =
      onHardware("check --device chai3d:0 --map " + map_path + " --report " + file("check.json"));
  EXPECT_EQ(check.exit_code, 0) << check.output;
  EXPECT_NE(check.output.find("the map fits"), std::string::npos) << check.output;
  EXPECT_TRUE(readJson(file("check.json")).contains("servo_real_time_priority"));

  const auto loaded = onHardware("check --device chai3d:0 --payload-g 30 --map " + map_path);
  EXPECT_NE(loaded.exit_code, 0);
  EXPECT_NE(loaded.output.find("is real hardware"), std::string::npos) << loaded.output;

  const auto retare = onHardware("retare " + map_path + " --device chai3d:0 --vertices 1 --out " +
                                 file("retared.json") + " --report " + file("retare.json"));
  ASSERT_EQ(retare.exit_code, 0) << retare.output;
  EXPECT_EQ(retare.output.find("against the simulation's truth"), std::string::npos)
      << retare.output;
  const nlohmann::json report = readJson(file("retare.json"));
  EXPECT_NEAR(report.at("payload_estimate_g").get<double>(), 0.0, 2.0) << report.dump(2);
  EXPECT_FALSE(report.contains("max_error_rel")) << report.dump(2);
  EXPECT_TRUE(report.contains("servo_real_time_priority")) << report.dump(2);
  EXPECT_TRUE(fs::exists(file("retared.json")));
}

TEST_F(HardwareStandInTest, TheWizardRefusesWhatOnlyASimulationCanDo) {
  const auto auto_hand = onHardware("wizard --device chai3d:0 --auto-hand --out " + file("m.json"));
  EXPECT_NE(auto_hand.exit_code, 0);
  EXPECT_NE(auto_hand.output.find("--auto-hand needs a simulated device"), std::string::npos)
      << auto_hand.output;
  EXPECT_FALSE(fs::exists(file("m.json")));
  const auto calibrate = onHardware("calibrate --device chai3d:0 --out " + file("m.json"));
  EXPECT_NE(calibrate.exit_code, 0);
  EXPECT_NE(calibrate.output.find("autograv wizard"), std::string::npos) << calibrate.output;
}

// The wizard on hardware, in a terminal: its servo loop on its own thread at the wall clock's
// pace, a person's hand (the stand-in's, from what a person at the device sees) doing the manual
// step, the prompts answered with --yes.
TEST_F(HardwareStandInTest, TheTerminalWizardCalibratesHardwareWithAPersonAtIt) {
  const std::string map_path = file("omni.json");
  const std::string report_path = file("report.json");
  const std::string exit_path = file("exit");
  const std::string script = file("run.sh");
  std::ofstream(script) << "AUTOGRAV_STANDIN_DEVICES=hardware:sim:omni AUTOGRAV_STANDIN_PERSON=1 "
                        << binary_
                        << " wizard --device chai3d:0 --yes --grid 2 --side-mm 40 "
                           "--verify-points 1 --out "
                        << map_path << " --report " << report_path << "\necho $? > " << exit_path
                        << ".tmp && mv " << exit_path << ".tmp " << exit_path << "\nsleep 60\n";
  const std::string socket = "autograv_chai3d_hardware_" + std::to_string(::getpid());
  ASSERT_EQ(std::system(
                ("tmux -L " + socket + " new-session -d -s wizard -x 100 -y 40 'sh " + script + "'")
                    .c_str()),
            0);
  // A safeguard against a hung run, not a measurement: the run takes about a minute of wall
  // time (the exploration and eight vertices, on the device's own clock).
  const auto end = std::chrono::steady_clock::now() + std::chrono::minutes(8);
  while (!fs::exists(exit_path) && std::chrono::steady_clock::now() < end) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  const std::string screen =
      testing::runCommand("tmux -L " + socket + " capture-pane -p -t wizard").output;
  std::system(("tmux -L " + socket + " kill-server 2>/dev/null").c_str());
  ASSERT_TRUE(fs::exists(exit_path)) << screen;
  std::ifstream exit_file(exit_path);
  int exit_code = -1;
  exit_file >> exit_code;
  ASSERT_EQ(exit_code, 0) << screen;

  const GravityMap map = loadMap(map_path);
  EXPECT_EQ(map.metadata().device_model, "sim:omni");
  EXPECT_EQ(map.convergedCount(), 8) << screen;
  const nlohmann::json report = readJson(report_path);
  EXPECT_EQ(report.at("outcome").get<std::string>(), "done") << report.dump(2);
  EXPECT_TRUE(report.at("explored").get<bool>());
  EXPECT_TRUE(report.contains("servo_real_time_priority")) << report.dump(2);
  EXPECT_FALSE(report.contains("field_error_p99_rel")) << report.dump(2);  // no truth on hardware
  EXPECT_EQ(report.at("verify").size(), 1u) << report.dump(2);
  // The forces on the device, from what the wizard sent: known on hardware too.
  EXPECT_GT(report.at("peak_force_n").get<double>(), 0.3) << report.dump(2);
  EXPECT_LT(report.at("peak_force_n").get<double>(), 3.3) << report.dump(2);
  EXPECT_EQ(report.at("force_limit_ticks").get<int>(), 0) << report.dump(2);
  EXPECT_GE(report.at("seconds_above_continuous_force").get<double>(), 0.0) << report.dump(2);
}

}  // namespace
}  // namespace autograv
