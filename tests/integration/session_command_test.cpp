// `autograv session` scores a map in use minute by minute: on motors that warm the field error
// grows while the same unit that never warms stays where the map left it, and the report holds
// every row it printed.
#include <filesystem>
#include <fstream>
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

TEST(SessionCommandTest, OnMotorsThatWarmTheErrorGrowsBesideTheUnitThatNeverWarms) {
  if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  testing::ScratchFolder folder("session-command");
  const std::string map = folder.file("omega.json");
  const auto calibrate =
      runCommand(kBinary + " calibrate --device sim:omega --grid 3 --out " + map);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.output;
  const std::string report = folder.file("session.json");
  const auto session =
      runCommand(kBinary + " session --device sim:omega --map " + map +
                 " --thermal on --minutes 3 --field-samples 2000 --report " + report);
  ASSERT_EQ(session.exit_code, 0) << session.output;
  EXPECT_NE(session.output.find("warming: sim:omega, thermal on"), std::string::npos)
      << session.output;
  EXPECT_NE(session.output.find("never warming, session 1: sim:omega, thermal off"),
            std::string::npos)
      << session.output;

  std::ifstream in(report);
  const nlohmann::json json = nlohmann::json::parse(in);
  ASSERT_EQ(json.at("sessions").size(), 2u);
  const nlohmann::json& warming = json["sessions"][0];
  const nlohmann::json& never = json["sessions"][1];
  EXPECT_TRUE(warming.at("thermal").get<bool>());
  EXPECT_FALSE(never.at("thermal").get<bool>());
  ASSERT_EQ(warming.at("samples").size(), 4u);  // minutes 0 to 3
  const nlohmann::json& first = warming["samples"][0];
  const nlohmann::json& last = warming["samples"][3];
  EXPECT_GT(last.at("field_error_p90_rel").get<double>(),
            first.at("field_error_p90_rel").get<double>());
  EXPECT_EQ(never["samples"][3].at("field_error_p90_rel"),
            never["samples"][0].at("field_error_p90_rel"));
  // The warmer motors deliver less: the map needs a factor above 1, and the decorator saw load.
  EXPECT_GT(last.at("best_scale").get<double>(), 1.0);
  EXPECT_GT(last.at("thermal_load").get<double>(), 0.0);
  EXPECT_LT(last.at("rescaled_field_error_p90_rel").get<double>(),
            last.at("field_error_p90_rel").get<double>());
  EXPECT_GT(last.at("hottest_winding_c").get<double>(), 22.0);
}

TEST(SessionCommandTest, RoomAndMotorTemperaturesNeedTheThermalModel) {
  if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  const auto refused =
      runCommand(kBinary + " session --device sim:omega --map any.json --ambient-c 27");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("--thermal"), std::string::npos) << refused.output;
}

}  // namespace
}  // namespace autograv
