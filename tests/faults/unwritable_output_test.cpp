// Every file the programs write, aimed at a full disk (/dev/full, a full file system) and at a
// read-only folder: the user is told which file and why, and nothing saved before is damaged.
#include <sys/stat.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "fault_test_support.h"
#include "subprocess.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using testing::Findings;

using testing::TestFolder;

GravityMap smallMap(const std::string& serial) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, 0.1), 0.04, 2);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n = Eigen::Vector3d(0.0, 0.01 * i, 2.0);
    vertices[static_cast<std::size_t>(i)].iterations = 5;
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = "sim:omega";
  metadata.device_serial = serial;
  metadata.created_utc = "2026-11-30T12:00:00Z";
  return GravityMap(grid, std::move(vertices), metadata);
}

/// The message of the autograv::Error `save` throws, or "" when it does not throw.
template <typename Save>
std::string errorOf(Save&& save) {
  try {
    save();
  } catch (const Error& error) {
    return error.what();
  }
  return "";
}

bool isCharacterDevice(const char* path) {
  struct stat status {};
  return ::stat(path, &status) == 0 && S_ISCHR(status.st_mode);
}

TEST(UnwritableOutputTest, DevFullIsNamedWithTheReasonAndStaysADevice) {
  ASSERT_TRUE(isCharacterDevice("/dev/full"));
  const std::string message = errorOf([] { saveMap(smallMap("new"), "/dev/full"); });
  EXPECT_NE(message.find("'/dev/full'"), std::string::npos) << message;
  EXPECT_NE(message.find("No space left on device"), std::string::npos) << message;
  EXPECT_NE(message.find("disk is full"), std::string::npos) << message;
  // Written into, never replaced: a rename over it (we are root in CI) would have swapped the
  // device for a plain file.
  EXPECT_TRUE(isCharacterDevice("/dev/full"));
  EXPECT_TRUE(errorOf([] { writeFileAtomically("/dev/null", "anything", "report"); }).empty());
  EXPECT_TRUE(isCharacterDevice("/dev/null"));
}

TEST(UnwritableOutputTest, AReadOnlyFolderIsNamedAndTheFilesInItAreUntouched) {
  const TestFolder folder;
  saveMap(smallMap("old"), folder.file("map.json"));
  const std::string old_text = testing::readFile(folder.file("map.json"));
  const testing::ConfinedRun run = testing::runWithReadOnlyFolder(folder.path(), [&] {
    return Findings{
        {"map", errorOf([&] { saveMap(smallMap("new"), folder.file("map.json")); })},
        {"new_file", errorOf([&] { saveMap(smallMap("new"), folder.file("other.json")); })}};
  });
  ASSERT_TRUE(run.ran) << run.why_not;
  const std::string reason = testing::unwritableReason(run);
  for (const std::string key : {"map", "new_file"}) {
    const std::string& message = run.findings.at(key);
    EXPECT_NE(message.find(folder.path()), std::string::npos) << message;
    EXPECT_NE(message.find(reason), std::string::npos) << message;
    EXPECT_NE(message.find("is the folder writable?"), std::string::npos) << message;
  }
  EXPECT_EQ(testing::readFile(folder.file("map.json")), old_text);
  EXPECT_EQ(folder.names(), std::vector<std::string>{"map.json"});
}

TEST(UnwritableOutputTest, AFullDiskKeepsTheOldFileAndLeavesNoTemporaryFile) {
  const TestFolder folder;
  const std::string old_text = mapToJson(smallMap("old"));
  const testing::ConfinedRun run =
      testing::runWithFullDisk(folder.path(), 64 * 1024, {{"map.json", old_text}}, [&] {
        Findings findings{
            {"message", errorOf([&] { saveMap(smallMap("new"), folder.file("map.json")); })},
            {"after", testing::readFile(folder.file("map.json"))}};
        for (const auto& entry : fs::directory_iterator(folder.path())) {
          findings["names"] += entry.path().filename().string() + " ";
        }
        return findings;
      });
  if (!run.ran)
    GTEST_SKIP() << "no private mount namespace here (" << run.why_not << "); "
                 << "DevFullIsNamedWithTheReasonAndStaysADevice covers a full disk";
  const std::string& message = run.findings.at("message");
  EXPECT_NE(message.find(folder.file("map.json")), std::string::npos) << message;
  EXPECT_NE(message.find("No space left on device"), std::string::npos) << message;
  EXPECT_NE(message.find("previous file, if any, is untouched"), std::string::npos) << message;
  EXPECT_EQ(run.findings.at("after"), old_text);
  EXPECT_EQ(run.findings.at("names").find(".tmp-"), std::string::npos) << run.findings.at("names");
}

// --- the programs ----------------------------------------------------------------------------

class UnwritableProgramOutputTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(testing::kAutogravProgram)) {
      GTEST_SKIP() << testing::kAutogravProgram << " is not built (AUTOGRAV_BUILD_DEMO=OFF)";
    }
    // Where the test gives no write permission and the child runs as user nobody, the other
    // folder must stay writable for it.
    fs::permissions(open_.path(), fs::perms::all);
    // What a user saved before in the folder that has become read-only (or full).
    saveMap(smallMap("old"), locked_.file("map.json"));
    saveMap(smallMap("old checkpoint"), locked_.file("map.json.partial"));
    testing::writeFile(locked_.file("report.json"), "{\"old\": true}\n");
    before_ = snapshot();
  }

  std::vector<std::string> snapshot() const {
    std::vector<std::string> files;
    for (const std::string& name : locked_.names()) {
      files.push_back(name + ":" + testing::readFile(locked_.file(name)));
    }
    return files;
  }

  /// `autograv <arguments>` is refused with a message naming `named`; the locked folder is kept.
  void expectRefused(const std::string& arguments, const std::string& named) {
    SCOPED_TRACE("autograv " + arguments);
    testing::expectAutogravRefused(locked_.path(), arguments, named);
    EXPECT_EQ(snapshot(), before_) << "a file in the read-only folder changed";
  }

  std::string locked(const std::string& name) const { return locked_.file(name); }
  std::string writable(const std::string& name) const { return open_.file(name); }
  std::string fixtureMap() const {
    return AUTOGRAV_SOURCE_DIR "/tests/visual/golden/omega_map.json";
  }

 private:
  TestFolder locked_;
  TestFolder open_;
  std::vector<std::string> before_;
};

TEST_F(UnwritableProgramOutputTest, CalibrateSaysSoBeforeTheDeviceMoves) {
  // The map and its checkpoint in a read-only folder; then only the report.
  expectRefused("calibrate --device sim:omega --grid 2 --side-mm 40 --out " + locked("new.json"),
                locked("new.json"));
  expectRefused("calibrate --device sim:omega --grid 2 --side-mm 40 --out " + writable("map.json") +
                    " --report " + locked("report.json"),
                locked("report.json"));
  EXPECT_FALSE(fs::exists(writable("map.json")));
}

TEST_F(UnwritableProgramOutputTest, WizardSaysSoBeforeTheDeviceMoves) {
  expectRefused(
      "wizard --device sim:omega --auto-hand --grid 2 --side-mm 40 --out " + locked("new.json"),
      locked("new.json"));
  expectRefused("wizard --device sim:omega --auto-hand --grid 2 --side-mm 40 --out " +
                    writable("map.json") + " --report " + locked("report.json"),
                locked("report.json"));
}

TEST_F(UnwritableProgramOutputTest, ReportsOfVerifySimAndThePaperExperiment) {
  expectRefused(
      "verify " + fixtureMap() + " --device sim:omega --points 2 --report " + locked("report.json"),
      locked("report.json"));
  expectRefused("sim --device sim:omega --seconds 0.1 --report " + locked("report.json"),
                locked("report.json"));
  expectRefused("paper-experiment --report " + locked("report.json"), locked("report.json"));
}

TEST_F(UnwritableProgramOutputTest, ReportsToDevFullSayTheDiskIsFull) {
  const testing::ProgramRun run =
      testing::runAutograv("sim --device sim:omega --seconds 0.1 --report /dev/full");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("'/dev/full'"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("No space left on device"), std::string::npos) << run.output;
  EXPECT_TRUE(isCharacterDevice("/dev/full"));
}

TEST_F(UnwritableProgramOutputTest, CalibrateOnAFullDiskKeepsTheEarlierMapAndCheckpoint) {
  const TestFolder full;
  const std::string old_map = mapToJson(smallMap("old"));
  const std::string out = full.file("map.json");
  const testing::ConfinedRun run =
      testing::runWithFullDisk(full.path(), 256 * 1024, {{"map.json", old_map}}, [&] {
        const testing::ProgramRun program =
            testing::runAutograv("calibrate --device sim:omega --grid 2 --side-mm 40 --out " + out);
        return Findings{{"exit", std::to_string(program.exit_code)},
                        {"output", program.output},
                        {"map", testing::readFile(out)},
                        {"checkpoint_exists", fs::exists(out + ".partial") ? "yes" : "no"}};
      });
  if (!run.ran)
    GTEST_SKIP() << "no private mount namespace here (" << run.why_not << "); "
                 << "ReportsToDevFullSayTheDiskIsFull covers a full disk";
  const std::string& output = run.findings.at("output");
  EXPECT_EQ(run.findings.at("exit"), "2") << output;
  EXPECT_NE(output.find("No space left on device"), std::string::npos) << output;
  EXPECT_NE(output.find(out), std::string::npos) << output;
  EXPECT_EQ(run.findings.at("map"), old_map);
  EXPECT_EQ(run.findings.at("checkpoint_exists"), "no");
}

}  // namespace
}  // namespace autograv
