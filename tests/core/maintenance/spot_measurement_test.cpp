// The pure parts of the spot measurement that retare and check share: which vertices they
// measure, and what counts as a change of weight rather than of gravity's direction.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/maintenance/spot_measurement.h"
#include "autograv/map/workspace_grid.h"

namespace autograv {
namespace {

TEST(CentralVerticesTest, AreTheMiddleThenItsNearestNeighboursInIndexOrder) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 3);
  // 13 is the centre of a 3x3x3 grid; 4, 10, 12, 14, 16 and 22 are one cell away from it.
  EXPECT_EQ(centralVertices(grid, 1), (std::vector<int>{13}));
  EXPECT_EQ(centralVertices(grid, 7), (std::vector<int>{13, 4, 10, 12, 14, 16, 22}));
}

TEST(CentralVerticesTest, NeverMoreThanTheGridHasAndNoneForNone) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 2);
  const std::vector<int> all = centralVertices(grid, 100);
  EXPECT_EQ(all.size(), 8u);
  EXPECT_TRUE(centralVertices(grid, 0).empty());
}

TEST(ChangeOfWeightTest, AChangeAlongTheVerticalEitherWayIsAChangeOfWeight) {
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  EXPECT_TRUE(isChangeOfWeight(Eigen::Vector3d(0.0, 0.0, 0.05), up));   // a heavier handle
  EXPECT_TRUE(isChangeOfWeight(Eigen::Vector3d(0.0, 0.0, -0.05), up));  // a lighter one
  // 20 degrees off the vertical still is; 35 degrees is a tilt.
  const double within = 20.0 * M_PI / 180.0;
  const double beyond = 35.0 * M_PI / 180.0;
  EXPECT_TRUE(isChangeOfWeight(Eigen::Vector3d(std::sin(within), 0.0, std::cos(within)), up));
  EXPECT_FALSE(isChangeOfWeight(Eigen::Vector3d(std::sin(beyond), 0.0, std::cos(beyond)), up));
}

TEST(ChangeOfWeightTest, ASidewaysChangeIsATiltedOrMovedDevice) {
  const Eigen::Vector3d up(0.0, 0.0, 1.0);
  EXPECT_FALSE(isChangeOfWeight(Eigen::Vector3d(0.04, 0.0, 0.0), up));
  EXPECT_FALSE(isChangeOfWeight(Eigen::Vector3d(0.0, -0.04, 0.0), up));
}

}  // namespace
}  // namespace autograv
