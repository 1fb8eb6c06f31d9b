// `autograv verify` gives a verdict a user can act on: PASS (exit 0) on a good map, FAIL with a
// non-zero exit on a map that is off by a few percent, on the default device of every command.
#include <filesystem>
#include <fstream>
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

class VerifyCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  }
  std::string file(const std::string& name) const { return folder_.file(name); }
  static nlohmann::json readJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }

  testing::ScratchFolder folder_{"verify-command"};
};

TEST_F(VerifyCommandTest, PassesAGoodMapAndFailsItScaledByFivePercent) {
  // No --device anywhere: calibrate and verify have the same default device.
  const std::string good = file("good.json");
  const auto calibrate = runCommand(kBinary + " calibrate --grid 4 --out " + good);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.output;

  const std::string verify = kBinary + " verify --points 20 --no-uncompensated ";
  const auto passed = runCommand(verify + good + " --report " + file("good.report.json"));
  EXPECT_EQ(passed.exit_code, 0) << passed.output;
  EXPECT_NE(passed.output.find("\nPASS\n"), std::string::npos) << passed.output;
  EXPECT_TRUE(readJson(file("good.report.json")).at("pass").get<bool>());

  const std::string off = file("off.json");
  saveMap(testing::scaledMap(loadMap(good), 1.05), off);
  const auto failed = runCommand(verify + off + " --report " + file("off.report.json"));
  EXPECT_EQ(failed.exit_code, 1) << failed.output;
  EXPECT_NE(failed.output.find("\nFAIL\n"), std::string::npos) << failed.output;
  EXPECT_NE(failed.output.find("TOO HIGH"), std::string::npos) << failed.output;
  const nlohmann::json report = readJson(file("off.report.json"));
  EXPECT_FALSE(report.at("pass").get<bool>());
  EXPECT_FALSE(report.at("residual_ok").get<bool>());
  // The probe reads the 5 % the map adds, give or take the good map's own error.
  EXPECT_NEAR(report.at("residual_force_median_rel").get<double>(), 0.05, 0.015) << report.dump(2);
}

}  // namespace
}  // namespace autograv
