// `autograv inspect` of a map corrected from another unit's map (schema 6): the real binary says
// which unit's map it came from and the correction, in its own label column; a calibrated map
// shows neither row.
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "autograv/map/map_io.h"
#include "field_map.h"
#include "map_prior_fixture.h"
#include "run_command.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using testing::runCommand;

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";

/// One row of inspect's output: the label padded to its 22-character column.
std::string row(const char* label, const std::string& value) {
  char padded[32];
  std::snprintf(padded, sizeof padded, "%-22s ", label);
  return "\n" + std::string(padded) + value + "\n";
}

class InspectPriorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(kBinary)) GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
  }

  /// A 4x4x4 map of a gently varying field (a 0.2 kg end-effector's weight), with `prior`.
  std::string saveFieldMap(const std::string& name, const std::optional<MapPrior>& prior) const {
    MapMetadata metadata;
    metadata.device_model = "sim:omni";
    metadata.device_serial = "SN-0042";
    metadata.created_utc = "2026-11-23T13:25:00Z";
    metadata.prior = prior;
    const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, 0.0), 0.08, 4);
    const auto map = testing::fieldMap(
        grid,
        [](const Eigen::Vector3d& x) {
          return Eigen::Vector3d(0.1 * x.y(), 0.1 * x.x(), -1.96 + 0.5 * x.z());
        },
        metadata);
    const std::string path = folder_.file(name);
    saveMap(*map, path);
    return path;
  }

  testing::ScratchFolder folder_{"inspect-prior"};
};

TEST_F(InspectPriorTest, ACorrectedMapSaysWhereItCameFromAndTheCorrection) {
  const MapPrior prior = testing::affinePriorFixture();
  const std::string path = saveFieldMap("corrected.json", prior);
  const auto result = runCommand(kBinary + " inspect " + path);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  // Labels padded to inspect's column, like every other row.
  EXPECT_NE(result.output.find(row("made from",
                                   "map of unit SN-0017 made 2026-10-01T08:00:00Z "
                                   "(maps/omni-0017.json)")),
            std::string::npos)
      << result.output;
  EXPECT_NE(result.output.find(row("correction",
                                   "affine from 24 points; gain diag 1.012 / 0.987 / 1.003, "
                                   "offset [1.2, -30.4, 0.0] mN; checked on 4 points: mean 0.41 "
                                   "%, largest 0.93 %; workspace within 3.2 mm")),
            std::string::npos)
      << result.output;
}

TEST_F(InspectPriorTest, ACalibratedMapShowsNoPrior) {
  const auto result = runCommand(kBinary + " inspect " + saveFieldMap("calibrated.json", {}));
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output.find("made from"), std::string::npos) << result.output;
  EXPECT_EQ(result.output.find("\ncorrection"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace autograv
