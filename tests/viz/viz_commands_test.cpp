// The viz commands as a user runs them: `autograv render`, `render --compare`, `plot`, `export`
// and `compare`, on the Omega fixture map, checked by their exit codes and the files they write.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "autograv/viz/image.h"
#include "viz_test_support.h"

namespace autograv::viz {
namespace {

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";
const std::string kMap = AUTOGRAV_SOURCE_DIR "/tests/visual/golden/omega_map.json";

struct CommandRun {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

/// Runs `autograv <arguments>` through the shell and captures what it printed.
CommandRun autograv(const std::string& arguments) {
  CommandRun run;
  const std::string command = kBinary + " " + arguments + " 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) run.output += buffer;
  const int status = ::pclose(pipe);
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

std::string readText(const std::string& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

class VizCommandsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The demo programs are built with the tests (tests/CMakeLists.txt); a build without them
    // (AUTOGRAV_BUILD_DEMO=OFF) has nothing to run.
    if (!std::filesystem::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built";
    AUTOGRAV_REQUIRE_DISPLAY();
    folder_ = std::filesystem::temp_directory_path() /
              ("autograv_viz_commands_" + std::to_string(::getpid()) + "_" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(folder_);
    std::filesystem::create_directories(folder_);
  }
  void TearDown() override {
    std::error_code ignored;
    if (!HasFailure()) std::filesystem::remove_all(folder_, ignored);
  }
  std::string file(const std::string& name) const { return (folder_ / name).string(); }

 private:
  std::filesystem::path folder_;
};

TEST_F(VizCommandsTest, RenderWritesThePictureAndCompareCatchesAnotherCamera) {
  const CommandRun render =
      autograv("render " + kMap + " -o " + file("iso.png") + " --view iso --size 640x480");
  ASSERT_EQ(render.exit_code, 0) << render.output;
  const RgbImage picture = readPng(file("iso.png"));
  EXPECT_EQ(picture.width_px, 640);
  EXPECT_EQ(picture.height_px, 480);

  // The same render against itself passes; the top view against it fails with a diff picture.
  const CommandRun same = autograv("render " + kMap + " -o " + file("again.png") +
                                   " --view iso --size 640x480 --compare " + file("iso.png"));
  EXPECT_EQ(same.exit_code, 0) << same.output;
  const CommandRun moved = autograv("render " + kMap + " -o " + file("top.png") +
                                    " --view top --size 640x480 --compare " + file("iso.png") +
                                    " --diff " + file("diff.png"));
  EXPECT_NE(moved.exit_code, 0) << moved.output;
  EXPECT_TRUE(std::filesystem::exists(file("diff.png")));

  // The stand-alone comparison says the same.
  EXPECT_EQ(autograv("compare " + file("again.png") + " " + file("iso.png")).exit_code, 0);
  EXPECT_NE(autograv("compare " + file("top.png") + " " + file("iso.png")).exit_code, 0);
}

TEST_F(VizCommandsTest, PlotDrawsAVertexAndTheSummary) {
  const CommandRun vertex = autograv("plot " + kMap + " --vertex 0 -o " + file("vertex.png"));
  ASSERT_EQ(vertex.exit_code, 0) << vertex.output;
  EXPECT_GT(readPng(file("vertex.png")).width_px, 0);
  const CommandRun summary = autograv("plot " + kMap + " --summary -o " + file("summary.png"));
  ASSERT_EQ(summary.exit_code, 0) << summary.output;
  EXPECT_GT(readPng(file("summary.png")).width_px, 0);
  // A vertex the grid does not have is refused with the valid range.
  const CommandRun bad = autograv("plot " + kMap + " --vertex 100000 -o " + file("bad.png"));
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_FALSE(std::filesystem::exists(file("bad.png")));
}

TEST_F(VizCommandsTest, ExportWritesTheVectorsWithTheirUnit) {
  const CommandRun vti = autograv("export " + kMap + " -o " + file("map.vti"));
  ASSERT_EQ(vti.exit_code, 0) << vti.output;
  const std::string text = readText(file("map.vti"));
  EXPECT_NE(text.find("<VTKFile type=\"ImageData\""), std::string::npos);
  EXPECT_NE(text.find("Name=\"gravity_N\" NumberOfComponents=\"3\""), std::string::npos)
      << "the vector array, named with its unit";
  const CommandRun vtu = autograv("export " + kMap + " -o " + file("map.vtu"));
  ASSERT_EQ(vtu.exit_code, 0) << vtu.output;
  EXPECT_NE(readText(file("map.vtu")).find("<VTKFile type=\"UnstructuredGrid\""),
            std::string::npos);
}

TEST_F(VizCommandsTest, AMissingOrBrokenMapIsNamedAndNothingIsWritten) {
  const CommandRun missing = autograv("render " + file("nowhere.json") + " -o " + file("x.png"));
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("nowhere.json"), std::string::npos) << missing.output;
  std::ofstream(file("broken.json")) << "{\"format\": \"autograv-gravity-map\", ";
  const CommandRun broken = autograv("render " + file("broken.json") + " -o " + file("y.png"));
  EXPECT_NE(broken.exit_code, 0);
  EXPECT_NE(broken.output.find("broken.json"), std::string::npos) << broken.output;
  EXPECT_FALSE(std::filesystem::exists(file("x.png")));
  EXPECT_FALSE(std::filesystem::exists(file("y.png")));
}

}  // namespace
}  // namespace autograv::viz
