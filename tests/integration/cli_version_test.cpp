// One version everywhere: `autograv --version` and autograv/version.h say what
// project(autograv VERSION ...) in CMakeLists.txt says (tests/CMakeLists.txt passes it in).
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "autograv/version.h"
#include "run_command.h"

namespace autograv {
namespace {

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";

TEST(CliVersionTest, VersionFlagPrintsTheCMakeProjectVersion) {
  if (!std::filesystem::exists(kBinary))
    GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  const auto result = testing::runCommand(kBinary + " --version");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("autograv " AUTOGRAV_CMAKE_PROJECT_VERSION), std::string::npos)
      << result.output;
}

TEST(CliVersionTest, VersionHeaderMatchesTheCMakeProjectVersion) {
  EXPECT_STREQ(AUTOGRAV_VERSION_STRING, AUTOGRAV_CMAKE_PROJECT_VERSION);
  EXPECT_EQ(std::to_string(AUTOGRAV_VERSION_MAJOR) + "." + std::to_string(AUTOGRAV_VERSION_MINOR) +
                "." + std::to_string(AUTOGRAV_VERSION_PATCH),
            AUTOGRAV_CMAKE_PROJECT_VERSION);
  EXPECT_EQ(AUTOGRAV_VERSION / 10000, AUTOGRAV_VERSION_MAJOR);
}

}  // namespace
}  // namespace autograv
