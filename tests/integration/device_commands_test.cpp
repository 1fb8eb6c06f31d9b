// The device commands of the real `autograv` binary: devices, check (exit status 0 or 1 with the
// reason) and retare (its report), on the simulated Omni.
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_command.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using testing::runCommand;

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";

class DeviceCommandsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kBinary)) return;
    scratch_ = std::make_unique<testing::ScratchFolder>("device-commands");
    dir_ = scratch_->path().string();
    // A small map of the unloaded Omni, filed in a private map library.
    const auto result =
        runCommand(kBinary + " calibrate --device sim:omni --grid 3 --side-mm 60 --out " + dir_ +
                   "/omni.json");
    ASSERT_EQ(result.exit_code, 0) << result.output;
  }
  static void TearDownTestSuite() { scratch_.reset(); }
  void SetUp() override {
    if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  }
  static nlohmann::json readJson(const std::string& path) {
    std::ifstream file(path);
    return nlohmann::json::parse(file);
  }
  static std::unique_ptr<testing::ScratchFolder> scratch_;
  static std::string dir_;  // scratch_'s
};

std::unique_ptr<testing::ScratchFolder> DeviceCommandsTest::scratch_;
std::string DeviceCommandsTest::dir_;

TEST_F(DeviceCommandsTest, DevicesListsTheSimulatedOnesWithModelSerialAndLimits) {
  const auto result = runCommand(kBinary + " devices --report " + dir_ + "/devices.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("sim:omni"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("SIM-OMNI-0001"), std::string::npos) << result.output;
  const nlohmann::json report = readJson(dir_ + "/devices.json");
  bool omni = false;
  for (const auto& device : report.at("devices")) {
    if (device.at("name") != "sim:omni") continue;
    omni = true;
    EXPECT_DOUBLE_EQ(device.at("max_linear_force_n").get<double>(), 3.3);
    EXPECT_GT(device.at("workspace_radius_m").get<double>(), 0.0);
  }
  EXPECT_TRUE(omni);
}

TEST_F(DeviceCommandsTest, CheckExitsZeroWhenTheMapFitsAndOneWithTheReasonWhenNot) {
  const std::string check =
      kBinary + " check --device sim:omni --seed 5 --map " + dir_ + "/omni.json";
  const auto fits = runCommand(check);
  EXPECT_EQ(fits.exit_code, 0) << fits.output;
  EXPECT_NE(fits.output.find("the map fits"), std::string::npos) << fits.output;

  const auto payload = runCommand(check + " --payload-g 30");
  EXPECT_EQ(payload.exit_code, 1) << payload.output;
  EXPECT_NE(payload.output.find("run autograv retare"), std::string::npos) << payload.output;

  const auto tilted = runCommand(check + " --tilt-deg 10 --report " + dir_ + "/tilted.json");
  EXPECT_EQ(tilted.exit_code, 1) << tilted.output;
  EXPECT_NE(tilted.output.find("calibrate it again"), std::string::npos) << tilted.output;
  const nlohmann::json report = readJson(dir_ + "/tilted.json");
  EXPECT_EQ(report.at("fit"), "recalibrate");
  EXPECT_NEAR(report.at("tilt_estimate_deg").get<double>(), 10.0, 2.0);
}

TEST_F(DeviceCommandsTest, RetareReportsThePayloadTheTimeAndTheErrorAgainstTheTruth) {
  const auto result = runCommand(kBinary + " retare " + dir_ +
                                 "/omni.json --device sim:omni --payload-g 30 --out " + dir_ +
                                 "/omni30.json --report " + dir_ + "/retare.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const nlohmann::json report = readJson(dir_ + "/retare.json");
  EXPECT_NEAR(report.at("payload_estimate_g").get<double>(), 30.0, 1.5);
  EXPECT_LT(report.at("simulated_seconds").get<double>(), 15.0);
  EXPECT_LT(report.at("max_error_rel").get<double>(), 0.03);
  // The re-tared map now fits the loaded device.
  const auto check = runCommand(kBinary + " check --device sim:omni --payload-g 30 --map " + dir_ +
                                "/omni30.json");
  EXPECT_EQ(check.exit_code, 0) << check.output;
}

TEST_F(DeviceCommandsTest, CalibrateSaysARealDeviceNeedsTheWizard) {
  const auto result =
      runCommand(kBinary + " calibrate --device chai3d:0 --out " + dir_ + "/x.json");
  EXPECT_NE(result.exit_code, 0);
  EXPECT_NE(result.output.find("autograv wizard"), std::string::npos) << result.output;
}

// The same device on another draw of late ticks: --servo-timing-seed changes the loop and
// nothing else, and the report says which draw it was (the README's spread over clock seeds).
TEST_F(DeviceCommandsTest, CalibrateDrawsTheLoopsLatenessFromItsOwnSeed) {
  const std::string command = kBinary +
                              " calibrate --device sim:omega --grid 2 --side-mm 50 --seed 2 "
                              "--servo-timing desktop --out " +
                              dir_ + "/timed.json --report ";
  const auto same = runCommand(command + dir_ + "/same.report.json");
  ASSERT_EQ(same.exit_code, 0) << same.output;
  const auto other = runCommand(command + dir_ + "/other.report.json --servo-timing-seed 5");
  ASSERT_EQ(other.exit_code, 0) << other.output;
  const nlohmann::json same_report = readJson(dir_ + "/same.report.json");
  const nlohmann::json other_report = readJson(dir_ + "/other.report.json");
  EXPECT_EQ(same_report["seed"], 2);
  EXPECT_EQ(same_report["servo_timing_seed"], 2);  // by default, the device's seed
  EXPECT_EQ(other_report["seed"], 2);
  EXPECT_EQ(other_report["servo_timing_seed"], 5);
  EXPECT_NE(same_report["servo_loop"]["max_lateness_ms"],
            other_report["servo_loop"]["max_lateness_ms"]);
  // How the measurements agree with one another, for a map with no ground truth to compare.
  ASSERT_TRUE(same_report.contains("leave_one_out_max_rel")) << same_report.dump(2);
  EXPECT_GE(same_report["leave_one_out_max_rel"].get<double>(),
            same_report["leave_one_out_p90_rel"].get<double>());
  EXPECT_LT(same_report["leave_one_out_max_rel"].get<double>(), 0.05);
  EXPECT_TRUE(same_report["least_sure_vertices"].is_array());
}

// The report says which unit was calibrated, which field model the map chose and how each
// candidate scored, and where a released stylus would drift; --field-model forces a model.
TEST_F(DeviceCommandsTest, CalibrateReportsTheUnitTheFieldModelAndWhereAStylusDrifts) {
  const std::string command = kBinary +
                              " calibrate --device sim:falcon --grid 3 --side-mm 60 --unit 2 "
                              "--out " +
                              dir_ + "/unit2.json --report " + dir_ + "/unit2.report.json";
  const auto chosen = runCommand(command);
  ASSERT_EQ(chosen.exit_code, 0) << chosen.output;
  const nlohmann::json report = readJson(dir_ + "/unit2.report.json");
  EXPECT_EQ(report["unit"], 2);
  EXPECT_EQ(report["actuators"], "typical");
  ASSERT_EQ(report["actuator_gains"].size(), 3u);
  EXPECT_NE(report["actuator_gains"][0].get<double>(), 1.0);
  ASSERT_EQ(report["field_model_scores"].size(), 3u) << report.dump(2);
  EXPECT_EQ(report["field_model_scores"][0]["model"], "conservative");
  EXPECT_NE(report["field_model"], "thin_plate");
  EXPECT_GT(report["breakaway_force_n"].get<double>(), 0.0);
  EXPECT_GE(report["field_error_above_breakaway_fraction"].get<double>(), 0.0);
  EXPECT_LE(report["field_error_above_breakaway_fraction"].get<double>(), 1.0);
  EXPECT_GT(report["field_error_max_n"].get<double>(), 0.0);
  EXPECT_NE(chosen.output.find("field model"), std::string::npos) << chosen.output;
  EXPECT_NE(chosen.output.find("where a released stylus drifts"), std::string::npos)
      << chosen.output;
  // Forced: the same measurements, read through the model asked for, scored by nothing else.
  const auto forced = runCommand(command + " --field-model componentwise");
  ASSERT_EQ(forced.exit_code, 0) << forced.output;
  const nlohmann::json forced_report = readJson(dir_ + "/unit2.report.json");
  EXPECT_EQ(forced_report["field_model"], "componentwise");
  EXPECT_TRUE(forced_report["field_model_scores"].empty());
  EXPECT_NE(forced.output.find("given, not chosen"), std::string::npos) << forced.output;
}

// --dither-hz reaches the estimator and the map records it; a frequency the 1 kHz loop cannot
// carry is refused before the device moves.
TEST_F(DeviceCommandsTest, CalibrateDithersAtTheFrequencyItIsGiven) {
  const auto slower = runCommand(kBinary +
                                 " calibrate --device sim:omega --grid 2 --side-mm 50 "
                                 "--dither-hz 12.5 --out " +
                                 dir_ + "/slower.json");
  ASSERT_EQ(slower.exit_code, 0) << slower.output;
  const nlohmann::json map = readJson(dir_ + "/slower.json");
  EXPECT_DOUBLE_EQ(map.at("parameters").at("dither_frequency_hz").get<double>(), 12.5);
  // Each iteration reads at least three windows of one 80 ms dither period (two agreeing pairs);
  // at the default 20 Hz the shortest take 0.2 s.
  for (const auto& vertex : map.at("vertices")) {
    for (const auto& iteration : vertex.at("history")) {
      EXPECT_GE(iteration.at("duration_s").get<double>(), 3 * 0.08 - 1e-9) << vertex.dump();
    }
  }

  const auto inspect = runCommand(kBinary + " inspect " + dir_ + "/slower.json");
  ASSERT_EQ(inspect.exit_code, 0) << inspect.output;
  EXPECT_NE(inspect.output.find("method dither: 12.5 Hz, amplitude picked at each point"),
            std::string::npos)
      << inspect.output;

  const auto too_fast = runCommand(
      kBinary + " calibrate --device sim:omega --dither-hz 400 --out " + dir_ + "/too_fast.json");
  EXPECT_NE(too_fast.exit_code, 0);
  EXPECT_NE(too_fast.output.find("--dither-hz"), std::string::npos) << too_fast.output;
  EXPECT_EQ(too_fast.output.find("Exploring"), std::string::npos) << too_fast.output;
  EXPECT_FALSE(fs::exists(dir_ + "/too_fast.json"));
}

}  // namespace
}  // namespace autograv
