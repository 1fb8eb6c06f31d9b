// `autograv calibrate --like` and `wizard --like`, the real binary on sim:omega: unit 2 corrected
// from unit 1's whole calibration, the map library finding that prior by model, a prior refused
// before the device moves and one refused after it measured saving nothing, and options that cannot
// go with --like refused before anything runs.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "autograv/map/map_io.h"
#include "run_command.h"
#include "scaled_map.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using testing::runCommand;

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";

nlohmann::json readJson(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

class CalibrateLikeCommandTest : public ::testing::Test {
 protected:
  // One whole calibration of unit 1 into a map library of the suite's own.
  static void SetUpTestSuite() {
    if (!fs::exists(kBinary)) return;
    scratch_ = std::make_unique<testing::ScratchFolder>("like");
    dir_ = scratch_->path();
    fs::create_directories(dir_ / "maps");
    prior_ = (dir_ / "maps" / "sim_omega@SIM-OMEGA-0001.json").string();
    const auto run = runCommand(kBinary + " calibrate --device sim:omega --out " + prior_);
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  static void TearDownTestSuite() { scratch_.reset(); }
  void SetUp() override {
    if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  }

  static std::unique_ptr<testing::ScratchFolder> scratch_;
  static fs::path dir_;  // scratch_'s
  static std::string prior_;
};

std::unique_ptr<testing::ScratchFolder> CalibrateLikeCommandTest::scratch_;
fs::path CalibrateLikeCommandTest::dir_;
std::string CalibrateLikeCommandTest::prior_;

TEST_F(CalibrateLikeCommandTest, CorrectsAnotherUnitsMapAndReportsTheFieldAgainstTheTruth) {
  const fs::path out = dir_ / "unit2.json";
  const fs::path report = dir_ / "unit2.report.json";
  const auto run = runCommand(kBinary + " calibrate --device sim:omega --unit 2 --like " + prior_ +
                              " --out " + out.string() + " --report " + report.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("check (points not fitted)"), std::string::npos) << run.output;
  const nlohmann::json json = readJson(report);
  EXPECT_TRUE(json["accepted"].get<bool>());
  EXPECT_LE(json["simulated_seconds"].get<double>(), 45.0);
  EXPECT_LT(json["field_error_p90_rel"].get<double>(), 0.004);
  EXPECT_EQ(json["force_limit_ticks"].get<int>(), 0);
  const GravityMap map = loadMap(out.string());
  ASSERT_TRUE(map.metadata().prior.has_value());
  EXPECT_EQ(map.metadata().prior->source, prior_);
  EXPECT_EQ(map.metadata().device_serial, "SIM-OMEGA-0002");
  const auto inspect = runCommand(kBinary + " inspect " + out.string());
  EXPECT_NE(inspect.output.find("made from"), std::string::npos) << inspect.output;
}

TEST_F(CalibrateLikeCommandTest, TheWizardFindsTheModelsMapInTheLibrary) {
  const fs::path report = dir_ / "wizard.report.json";
  const auto run =
      runCommand(kBinary + " wizard --device sim:omega --unit 3 --auto-hand --like " +
                 "library --maps " + (dir_ / "maps").string() + " --report " + report.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // Saved under unit 3's own name in the library, made from unit 1's map.
  const fs::path saved = dir_ / "maps" / "sim_omega@SIM-OMEGA-0003.json";
  ASSERT_TRUE(fs::exists(saved)) << run.output;
  const GravityMap map = loadMap(saved.string());
  ASSERT_TRUE(map.metadata().prior.has_value());
  EXPECT_EQ(map.metadata().prior->device_serial, "SIM-OMEGA-0001");
  EXPECT_LT(readJson(report)["field_error_p90_rel"].get<double>(), 0.004);
}

TEST_F(CalibrateLikeCommandTest, AMapOfAnotherModelIsRefusedBeforeTheDeviceMovesAndNothingIsSaved) {
  const fs::path out = dir_ / "falcon.json";
  const auto run = runCommand(kBinary + " calibrate --device sim:falcon --like " + prior_ +
                              " --out " + out.string());
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.output.find("another model"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(CalibrateLikeCommandTest, ACorrectionRefusedAfterMeasuringSavesNothingAndReportsWhy) {
  // Unit 1's map with every value off by its own random 8 %: the device moves and measures,
  // and no smooth correction explains what it measured.
  const fs::path scrambled = dir_ / "scrambled.json";
  saveMap(testing::scrambledMap(loadMap(prior_), 0.08, 5), scrambled.string());
  const fs::path out = dir_ / "refused.json";
  const fs::path report = dir_ / "refused.report.json";
  const auto run =
      runCommand(kBinary + " calibrate --device sim:omega --unit 2 --like " + scrambled.string() +
                 " --out " + out.string() + " --report " + report.string());
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find("refused"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("whole calibration"), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(out));
  // The report is written all the same: what was measured, and why it was refused.
  ASSERT_TRUE(fs::exists(report)) << run.output;
  const nlohmann::json json = readJson(report);
  EXPECT_FALSE(json["accepted"].get<bool>());
  EXPECT_GT(json["points_converged"].get<int>(), 0);
  EXPECT_NE(json["refusal"].get<std::string>().find("more than a correction explains"),
            std::string::npos);
  EXPECT_FALSE(json.contains("field_error_p90_rel"));
}

TEST_F(CalibrateLikeCommandTest, OptionsThatCannotGoWithLikeAreRefused) {
  for (const std::string& extra : {std::string("--grid 4"), std::string("--resume")}) {
    const auto run = runCommand(kBinary + " calibrate --device sim:omega --like " + prior_ +
                                " --out " + (dir_ / "x.json").string() + " " + extra);
    EXPECT_NE(run.exit_code, 0) << extra;
    EXPECT_NE(run.output.find("excludes"), std::string::npos) << run.output;
  }
  const auto missing =
      runCommand(kBinary + " calibrate --device sim:omega --like " + (dir_ / "none.json").string() +
                 " --out " + (dir_ / "x.json").string());
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("no map file"), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace autograv
