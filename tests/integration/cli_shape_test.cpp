// The shape of the `autograv` command line: each user command's --help shows what a user needs;
// the research and simulation options are declared once, listed by --help-advanced and refused by
// a command that does not take them; every command has the same default device; every flag with
// a unit names it, and the old spellings still work, with a note.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "run_command.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using testing::runCommand;

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";

const std::vector<std::string> kUserCommands = {"devices", "calibrate", "inspect", "verify",
                                                "retare",  "check",     "wizard",  "render",
                                                "plot",    "export",    "compare"};
const std::vector<std::string> kResearchCommands = {"sim", "paper-experiment", "bench"};

/// The research and simulation options: none of them belongs in a command's own --help.
const std::vector<std::string> kAdvanced = {"--seed",
                                            "--friction",
                                            "--unit",
                                            "--actuators",
                                            "--session",
                                            "--thermal",
                                            "--motor-start-c",
                                            "--ambient-c",
                                            "--payload-g",
                                            "--tilt-deg",
                                            "--servo-timing",
                                            "--servo-timing-seed",
                                            "--method",
                                            "--alpha-per-s",
                                            "--beta-per-s2",
                                            "--k0-n-per-mm",
                                            "--n-s",
                                            "--eps-s-mm-per-s",
                                            "--n-g",
                                            "--eps-g-gf",
                                            "--max-iterations",
                                            "--dither-mn",
                                            "--dither-hz",
                                            "--copy-initial-estimate",
                                            "--redo-failed",
                                            "--boundary-probes",
                                            "--field-model",
                                            "--auto-hand",
                                            "--speed",
                                            "--frame-ms",
                                            "--uncalibrated"};

class CliShapeTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  }
  // Made by the first test that writes a file: most only read --help.
  std::string file(const std::string& name) {
    if (!folder_) folder_.emplace("cli-shape");
    return folder_->file(name);
  }
  static std::string help(const std::string& arguments) {
    const auto run = runCommand(kBinary + " " + arguments);
    EXPECT_EQ(run.exit_code, 0) << arguments << "\n" << run.output;
    return run.output;
  }
  static nlohmann::json readJson(const std::string& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
  }

  std::optional<testing::ScratchFolder> folder_;
};

/// The option names of a --help text, one per option line ("  -o,--out TEXT ...": "--out").
std::vector<std::string> optionNames(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream lines(help);
  std::string line;
  const std::regex option(R"(^\s+(?:-[a-zA-Z],)?(--[a-z0-9-]+))");
  std::smatch match;
  while (std::getline(lines, line)) {
    if (std::regex_search(line, match, option)) names.push_back(match[1]);
  }
  return names;
}

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

TEST_F(CliShapeTest, CalibrateHelpListsAtMostTwentyOptionsAndPointsToTheAdvancedOnes) {
  const std::string text = help("calibrate --help");
  const std::vector<std::string> names = optionNames(text);
  EXPECT_LE(names.size(), 20u) << text;
  for (const char* needed :
       {"--device", "--out", "--grid", "--box-mm", "--side-mm", "--report", "--resume"}) {
    EXPECT_TRUE(contains(names, needed)) << needed << "\n" << text;
  }
  EXPECT_NE(text.find("autograv calibrate --help-advanced"), std::string::npos) << text;
}

TEST_F(CliShapeTest, NoCommandsHelpRepeatsAResearchOrSimulationOption) {
  std::vector<std::string> commands = kUserCommands;
  commands.insert(commands.end(), kResearchCommands.begin(), kResearchCommands.end());
  for (const std::string& command : commands) {
    const std::string text = help(command + " --help");
    const std::vector<std::string> names = optionNames(text);
    EXPECT_LE(names.size(), 20u) << command << "\n" << text;
    for (const std::string& advanced : kAdvanced) {
      EXPECT_FALSE(contains(names, advanced)) << command << " lists " << advanced << "\n" << text;
    }
  }
}

TEST_F(CliShapeTest, HelpAdvancedListsEachOptionOnceAndACommandsOwn) {
  const std::string all = help("--help-advanced");
  const std::vector<std::string> names = optionNames(all);
  for (const std::string& advanced : kAdvanced) {
    EXPECT_EQ(std::count(names.begin(), names.end(), advanced), 1) << advanced << "\n" << all;
  }
  EXPECT_EQ(names.size(), kAdvanced.size()) << all;
  // The program's --help points there and lists the research commands apart.
  const std::string program = help("--help");
  EXPECT_NE(program.find("--help-advanced"), std::string::npos) << program;
  const auto research = program.find("Research and simulation commands:");
  ASSERT_NE(research, std::string::npos) << program;
  for (const std::string& command : kResearchCommands) {
    EXPECT_GT(program.find("  " + command + " "), research) << command << "\n" << program;
  }
  for (const std::string& command : kUserCommands) {
    EXPECT_LT(program.find("  " + command + " "), research) << command << "\n" << program;
  }

  const std::vector<std::string> calibrate = optionNames(help("calibrate --help-advanced"));
  EXPECT_TRUE(contains(calibrate, "--k0-n-per-mm"));
  EXPECT_TRUE(contains(calibrate, "--servo-timing-seed"));
  EXPECT_FALSE(contains(calibrate, "--auto-hand"));
  const std::vector<std::string> verify = optionNames(help("verify --help-advanced"));
  EXPECT_TRUE(contains(verify, "--servo-timing"));
  EXPECT_FALSE(contains(verify, "--method"));
  EXPECT_NE(help("inspect --help-advanced").find("takes no research or simulation options"),
            std::string::npos);
}

TEST_F(CliShapeTest, AnOptionACommandDoesNotTakeIsRefusedBeforeItStarts) {
  const auto inspect = runCommand(kBinary + " inspect missing.json --friction high");
  EXPECT_NE(inspect.exit_code, 0);
  EXPECT_NE(inspect.output.find("`autograv inspect` does not take --friction"), std::string::npos)
      << inspect.output;
  const auto verify =
      runCommand(kBinary + " verify missing.json --k0-n-per-mm 0.5 --report " + file("r.json"));
  EXPECT_NE(verify.exit_code, 0);
  EXPECT_NE(verify.output.find("does not take --k0-n-per-mm"), std::string::npos) << verify.output;
  EXPECT_FALSE(fs::exists(file("r.json")));
  // The old spelling is refused in its own name.
  const auto old = runCommand(kBinary + " sim --seconds 0.01 --alpha 40");
  EXPECT_NE(old.exit_code, 0);
}

TEST_F(CliShapeTest, EveryCommandWithADeviceHasTheSameDefault) {
  for (const char* command :
       {"calibrate", "wizard", "verify", "check", "retare", "sim", "paper-experiment"}) {
    const std::string text = help(std::string(command) + " --help");
    const std::regex device(R"(--device TEXT[^=\n]*=([^ \n]+))");
    std::smatch match;
    ASSERT_TRUE(std::regex_search(text, match, device)) << command << "\n" << text;
    EXPECT_EQ(match[1], "sim:omega") << command;
  }
}

// The estimation parameters in their units, through the new names and the old ones alike: the
// paper's experiment records what it ran with.
TEST_F(CliShapeTest, TheUnitsAreInTheNamesAndTheOldSpellingsStillWork) {
  const auto renamed = runCommand(kBinary +
                                  " paper-experiment --alpha-per-s 35 --beta-per-s2 650 "
                                  "--k0-n-per-mm 0.4 --eps-s-mm-per-s 0.2 --eps-g-gf 0.6 "
                                  "--report " +
                                  file("renamed.json"));
  ASSERT_EQ(renamed.exit_code, 0) << renamed.output;
  EXPECT_EQ(renamed.output.find("note:"), std::string::npos) << renamed.output;
  const auto old = runCommand(kBinary +
                              " paper-experiment --alpha 35 --beta 650 --k0 0.4 --eps-s 0.2 "
                              "--eps-g 0.6 --report " +
                              file("old.json"));
  ASSERT_EQ(old.exit_code, 0) << old.output;
  for (const char* note :
       {"--alpha is now --alpha-per-s", "--beta is now --beta-per-s2", "--k0 is now --k0-n-per-mm",
        "--eps-s is now --eps-s-mm-per-s", "--eps-g is now --eps-g-gf"}) {
    EXPECT_NE(old.output.find(note), std::string::npos) << note << "\n" << old.output;
  }
  const nlohmann::json parameters = readJson(file("renamed.json")).at("parameters");
  EXPECT_EQ(readJson(file("old.json")).at("parameters"), parameters);
  EXPECT_DOUBLE_EQ(parameters.at("alpha_per_s").get<double>(), 35.0);
  EXPECT_DOUBLE_EQ(parameters.at("beta_per_s2").get<double>(), 650.0);
  EXPECT_DOUBLE_EQ(parameters.at("k0_n_per_m").get<double>(), 400.0);
  EXPECT_DOUBLE_EQ(parameters.at("eps_s_m_per_s").get<double>(), 2e-4);
  EXPECT_NEAR(parameters.at("eps_g_n").get<double>(), 0.6e-3 * 9.81, 1e-12);
  EXPECT_EQ(parameters.at("method").get<std::string>(), "paper");
}

}  // namespace
}  // namespace autograv
