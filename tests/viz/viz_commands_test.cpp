// The viz commands as a user runs them: `autograv render`, `render --compare`, `plot`, `export`
// and `compare`, on the Omega fixture map, checked by their exit codes and the files they write.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/map/field_fit.h"
#include "autograv/map/map_io.h"
#include "autograv/viz/image.h"
#include "scratch_folder.h"
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
  }
  std::string file(const std::string& name) const { return folder_.file(name); }

 private:
  autograv::testing::ScratchFolder folder_{"viz-commands"};
};

TEST_F(VizCommandsTest, RenderWritesThePictureAndCompareCatchesAnotherCamera) {
  const CommandRun render =
      autograv("render " + kMap + " -o " + file("iso.png") + " --view iso --size-px 640x480");
  ASSERT_EQ(render.exit_code, 0) << render.output;
  const RgbImage picture = readPng(file("iso.png"));
  EXPECT_EQ(picture.width_px, 640);
  EXPECT_EQ(picture.height_px, 480);

  // The same render against itself passes; the top view against it fails with a diff picture.
  const CommandRun same = autograv("render " + kMap + " -o " + file("again.png") +
                                   " --view iso --size-px 640x480 --compare " + file("iso.png"));
  EXPECT_EQ(same.exit_code, 0) << same.output;
  const CommandRun moved = autograv("render " + kMap + " -o " + file("top.png") +
                                    " --view top --size-px 640x480 --compare " + file("iso.png") +
                                    " --diff " + file("diff.png"));
  EXPECT_NE(moved.exit_code, 0) << moved.output;
  EXPECT_TRUE(std::filesystem::exists(file("diff.png")));

  // The stand-alone comparison says the same.
  EXPECT_EQ(autograv("compare " + file("again.png") + " " + file("iso.png")).exit_code, 0);
  EXPECT_NE(autograv("compare " + file("top.png") + " " + file("iso.png")).exit_code, 0);
}

TEST_F(VizCommandsTest, InspectShowsTheWorkspaceAndEachKindOfValue) {
  // An ellipsoidal workspace of semi-axes 60, 45, 35 mm: 396 cm^3.
  const auto inside = [](const Eigen::Vector3d& x) {
    return x.cwiseQuotient(Eigen::Vector3d(0.060, 0.045, 0.035)).squaredNorm() <= 1.0;
  };
  const GravityMap map = testing::makeExploredFixtureMap(testing::analyticGravity, inside);
  saveMap(map, file("explored.json"));
  int at_vertex = 0;
  int off_vertex = 0;
  int solved = 0;
  for (const VertexEstimate& v : map.vertices()) {
    if (v.measuredOffVertex()) {
      ++off_vertex;
    } else if (v.provenance == VertexProvenance::kFilled) {
      ++solved;
    } else if (v.outcome == VertexOutcome::kConverged) {
      ++at_vertex;
    }
  }
  ASSERT_GT(off_vertex, 0);
  ASSERT_GT(solved, 0);
  const CommandRun run = autograv("inspect " + file("explored.json"));
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::string values = std::to_string(at_vertex) + " measured at the vertex, " +
                             std::to_string(off_vertex) +
                             " measured inside the stops (off vertex), " + std::to_string(solved) +
                             " solved from the measurements";
  EXPECT_NE(run.output.find(values), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("explored along 26 probe directions"), std::string::npos) << run.output;
  const ExploredWorkspace& workspace = map.metadata().workspace;
  char reach[96];
  std::snprintf(reach, sizeof reach, "reach %.1f min,", workspace.minRadius_m() * 1e3);
  EXPECT_NE(run.output.find(reach), std::string::npos) << run.output;
  std::snprintf(reach, sizeof reach, "%.1f max mm", workspace.maxRadius_m() * 1e3);
  EXPECT_NE(run.output.find(reach), std::string::npos) << run.output;
  // The volume inside the probes' stops: the boundary model through 26 stops lies inside the
  // ellipsoid, and the volume is the one counted on a 2 mm lattice of points it contains.
  const auto at = run.output.find("volume about ");
  ASSERT_NE(at, std::string::npos) << run.output;
  const double volume_cm3 = std::stod(run.output.substr(at + 13));
  constexpr double kStep_m = 0.002;
  long inside_points = 0;
  for (double x = -0.061; x < 0.061; x += kStep_m) {
    for (double y = -0.046; y < 0.046; y += kStep_m) {
      for (double z = -0.036; z < 0.036; z += kStep_m) {
        if (workspace.contains(Eigen::Vector3d(x, y, z))) ++inside_points;
      }
    }
  }
  const double counted_cm3 = inside_points * kStep_m * kStep_m * kStep_m * 1e6;
  EXPECT_NEAR(volume_cm3, counted_cm3, 0.03 * counted_cm3);
  EXPECT_LT(volume_cm3, 396.0);
  EXPECT_NE(run.output.find("refinement 6: trilinear on a 37x37x37 grid, one cell beyond the box, "
                            "of the fit to every measurement"),
            std::string::npos)
      << run.output;
  // The model, how it was chosen, and every candidate's score.
  EXPECT_NE(run.output.find(std::string("field model            ") + toString(map.fieldModel())),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("chosen from the measurements"), std::string::npos) << run.output;
  for (const char* candidate : {"conservative  leave-one-out median", "componentwise leave-one-out",
                                "corrected     leave-one-out"}) {
    EXPECT_NE(run.output.find(candidate), std::string::npos) << candidate << "\n" << run.output;
  }
  EXPECT_EQ(run.output.find("filled"), std::string::npos) << run.output;

  // How the measurements agree with one another: each one from the fit of the others, with the
  // same figures the library gives.
  const MeasurementAgreement expected =
      measurementAgreement(map.grid(), map.vertices(), map.fieldModel(), map.curlWeight());
  const double largest_ratio = expected.max_rel;
  char agreement[96];
  std::snprintf(agreement, sizeof agreement, "largest %.2f %% of |G_hat|", 100.0 * largest_ratio);
  EXPECT_NE(run.output.find("leave-one-out          each measurement from the fit of the others: "
                            "median "),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find(agreement), std::string::npos) << run.output;
  if (largest_ratio > 0.01) {
    EXPECT_NE(run.output.find("least sure at vertex " +
                              std::to_string(expected.least_sure_vertices.front()) + " "),
              std::string::npos)
        << run.output;
  } else {
    EXPECT_NE(run.output.find("every measurement agrees with the others within 1 % of |G_hat|"),
              std::string::npos)
        << run.output;
  }

  // A map made without an exploration says so, in the same words.
  const CommandRun plain = autograv("inspect " + kMap);
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_NE(plain.output.find("not explored"), std::string::npos) << plain.output;
  EXPECT_NE(plain.output.find(" 0 measured inside the stops (off vertex), 32 solved from the "
                              "measurements"),
            std::string::npos)
      << plain.output;
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
