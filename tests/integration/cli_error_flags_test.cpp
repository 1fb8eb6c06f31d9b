// The library's refusals name its C++ parameters; the `autograv` command prints the same
// refusals in its own flags (demo/cli/error_translation.cpp), for the same mistakes.

#include <filesystem>
#include <regex>
#include <string>

#include <gtest/gtest.h>

#include "../../demo/cli/error_translation.h"
#include "autograv/map/map_io.h"
#include "autograv/map/measurement_plan.h"
#include "run_command.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

using testing::runCommand;

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";

// This process's scratch folder, removed when the process ends (ctest runs one test a process).
std::string scratch(const std::string& name) {
  static const testing::ScratchFolder folder("cli-error-flags");
  return folder.file(name);
}

/// The run failed, printed `flag`, and no library parameter name leaked through.
void expectRefusalInFlags(const testing::CommandResult& run, const std::string& flag) {
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.output.find(flag), std::string::npos) << run.output;
  EXPECT_FALSE(std::regex_search(run.output, std::regex("(WizardConfig|EstimationParameters|"
                                                        "MapLoadOptions)::")))
      << run.output;
}

/// The program tests need `autograv`, which a build without the demo (the sanitizer stages) has
/// not.
#define SKIP_WITHOUT_PROGRAM()           \
  if (!std::filesystem::exists(kBinary)) \
  GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)"

TEST(CliErrorFlagsTest, ABetaThatCannotConvergeIsRefusedWithTheFlagThatChangesIt) {
  SKIP_WITHOUT_PROGRAM();
  const auto run =
      runCommand(kBinary +
                 " calibrate --device sim:omega --grid 2 --side-mm 50 --beta-per-s2 50 "
                 "--alpha-per-s 10 --out " +
                 scratch("slow.json"));
  expectRefusalInFlags(run, "--beta-per-s2");
}

TEST(CliErrorFlagsTest, AGridBeyondTheWorkspaceIsMeasuredInsideTheExploredWorkspace) {
  SKIP_WITHOUT_PROGRAM();
  // Once refused (its faces would have been holes); the wizard now explores the workspace first
  // and measures each vertex beyond the stops just inside them.
  const std::string path = scratch("big.json");
  const auto run = runCommand(kBinary +
                              " wizard --device sim:omega --auto-hand --grid 2 --box-mm "
                              "200x180x190 --verify-points 0 --out " +
                              path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const GravityMap map = loadMap(path);
  const ExploredWorkspace& workspace = map.metadata().workspace;
  ASSERT_FALSE(workspace.empty());
  EXPECT_NEAR(map.grid().size_m().x(), 0.200, 1e-9);
  int measured = 0;
  for (const VertexEstimate& vertex : map.vertices()) {
    if (vertex.outcome != VertexOutcome::kConverged) continue;
    ++measured;
    EXPECT_TRUE(vertex.measuredOffVertex());  // every corner lies beyond the stops
    EXPECT_TRUE(workspace.contains(vertex.measured_at_m, 0.5 * kBoundaryMargin_m));
  }
  EXPECT_GE(measured, 4);
}

TEST(CliErrorFlagsTest, BoundaryProbesReachTheExplorationOfBothCommands) {
  SKIP_WITHOUT_PROGRAM();
  // The wizard on a 2x2x2 grid (quick), calibrate as published: both save the radial directions
  // and the boundary ones in the map.
  const std::string wizard_map = scratch("wizard_boundary.json");
  const auto wizard = runCommand(kBinary +
                                 " wizard --device sim:omega --auto-hand --grid 2 "
                                 "--verify-points 0 --boundary-probes 50 --out " +
                                 wizard_map);
  ASSERT_EQ(wizard.exit_code, 0) << wizard.output;
  EXPECT_GT(loadMap(wizard_map).metadata().workspace.directions().size(), 60u);
  const std::string calibrate_map = scratch("calibrate_boundary.json");
  const auto calibrate = runCommand(kBinary +
                                    " calibrate --device sim:omega --grid 2 --boundary-probes 50 "
                                    "--out " +
                                    calibrate_map);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.output;
  EXPECT_GT(loadMap(calibrate_map).metadata().workspace.directions().size(), 60u);
  const auto refused = runCommand(kBinary +
                                  " calibrate --device sim:omega --boundary-probes -1 "
                                  "--out " +
                                  scratch("never.json"));
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.output.find("--boundary-probes"), std::string::npos) << refused.output;
}

TEST(CliErrorFlagsTest, ResumingWithNoCheckpointSaysToStartWithoutResume) {
  SKIP_WITHOUT_PROGRAM();
  const auto run = runCommand(kBinary +
                              " wizard --device sim:omega --auto-hand --grid 2 --side-mm 40 "
                              "--resume --out " +
                              scratch("none.json"));
  expectRefusalInFlags(run, "--resume");
}

TEST(CliErrorFlagsTest, TheTableTranslatesEveryParameterPhraseItHolds) {
  for (const cli::FlagTranslation& row : cli::flagTranslations()) {
    const std::string translated = cli::inCommandLineTerms(std::string("x ") + row.library_phrase);
    EXPECT_EQ(translated, std::string("x ") + row.command_line_phrase) << row.library_phrase;
  }
}

}  // namespace
}  // namespace autograv
