#include "autograv/map/workspace_grid.h"

#include <set>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

TEST(WorkspaceGridTest, VertexPositionsSpanTheCube) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.01, -0.02, 0.03), 0.06, 4);
  EXPECT_EQ(grid.vertexCount(), 64);
  EXPECT_TRUE(grid.spacing_m().isApprox(Eigen::Vector3d::Constant(0.02), 1e-14));
  EXPECT_TRUE(grid.vertexPosition(0).isApprox(Eigen::Vector3d(-0.02, -0.05, 0.0)));
  EXPECT_TRUE(grid.vertexPosition(63).isApprox(Eigen::Vector3d(0.04, 0.01, 0.06)));
  const int index = grid.vertexIndex(1, 2, 3);
  EXPECT_EQ(grid.vertexCoordinates(index), Eigen::Vector3i(1, 2, 3));
}

TEST(WorkspaceGridTest, NearestVertexClampsOutsidePoints) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 3);
  EXPECT_EQ(grid.nearestVertex(Eigen::Vector3d(1.0, 1.0, 1.0)), grid.vertexCount() - 1);
  EXPECT_EQ(grid.nearestVertex(Eigen::Vector3d(0.001, -0.002, 0.0)), grid.vertexIndex(1, 1, 1));
  EXPECT_TRUE(grid.contains(Eigen::Vector3d(0.05, 0.0, 0.0)));
  EXPECT_FALSE(grid.contains(Eigen::Vector3d(0.051, 0.0, 0.0)));
  EXPECT_TRUE(grid.contains(Eigen::Vector3d(0.051, 0.0, 0.0), 0.002));
}

TEST(WorkspaceGridTest, VisitOrderCoversEveryVertexWithOneCellMoves) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.09, 4);
  const auto order = grid.visitOrder(Eigen::Vector3d(0.1, 0.1, -0.1));
  ASSERT_EQ(order.size(), 64u);
  EXPECT_EQ(std::set<int>(order.begin(), order.end()).size(), 64u);
  EXPECT_EQ(order.front(), grid.vertexIndex(3, 3, 0));  // corner nearest the start
  for (std::size_t k = 1; k < order.size(); ++k) {
    const double move_m =
        (grid.vertexPosition(order[k]) - grid.vertexPosition(order[k - 1])).norm();
    EXPECT_NEAR(move_m, grid.maxSpacing_m(), 1e-12) << "move " << k;
  }
}

TEST(WorkspaceGridTest, RejectsBadArguments) {
  EXPECT_THROW(WorkspaceGrid(Eigen::Vector3d::Zero(), -0.1, 4), Error);
  EXPECT_THROW(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 1), Error);
  EXPECT_THROW(WorkspaceGrid(Eigen::Vector3d::Constant(NAN), 0.1, 4), Error);
}

TEST(WorkspaceGridTest, BoxHasItsOwnExtentAndResolutionPerAxis) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.01, 0.0, -0.02), Eigen::Vector3d(0.16, 0.12, 0.07),
                           Eigen::Vector3i(7, 5, 4));
  EXPECT_FALSE(grid.isCube());
  EXPECT_EQ(grid.vertexCount(), 140);
  EXPECT_TRUE(grid.spacing_m().isApprox(Eigen::Vector3d(0.16 / 6, 0.03, 0.07 / 3), 1e-14));
  EXPECT_NEAR(grid.maxSpacing_m(), 0.03, 1e-15);
  EXPECT_TRUE(grid.minCorner_m().isApprox(Eigen::Vector3d(-0.07, -0.06, -0.055), 1e-14));
  EXPECT_TRUE(grid.maxCorner_m().isApprox(Eigen::Vector3d(0.09, 0.06, 0.015), 1e-14));
  // Index = ix + nx (iy + ny iz), and back, for every vertex.
  for (int index = 0; index < grid.vertexCount(); ++index) {
    const Eigen::Vector3i c = grid.vertexCoordinates(index);
    EXPECT_TRUE(grid.hasVertex(c));
    EXPECT_EQ(grid.vertexIndex(c.x(), c.y(), c.z()), index);
    EXPECT_EQ(index, c.x() + 7 * (c.y() + 5 * c.z()));
    EXPECT_EQ(grid.nearestVertex(grid.vertexPosition(index)), index);
  }
  EXPECT_EQ(grid.vertexCoordinates(grid.vertexCount() - 1), Eigen::Vector3i(6, 4, 3));
  EXPECT_TRUE(grid.vertexPosition(grid.vertexIndex(6, 4, 3)).isApprox(grid.maxCorner_m(), 1e-14));
  EXPECT_FALSE(grid.hasVertex(Eigen::Vector3i(7, 0, 0)));
  EXPECT_FALSE(grid.hasVertex(Eigen::Vector3i(0, 0, -1)));
  // Containment uses each axis' own half extent.
  EXPECT_TRUE(grid.contains(Eigen::Vector3d(0.089, 0.0, -0.02)));
  EXPECT_FALSE(grid.contains(Eigen::Vector3d(0.01, 0.0, 0.016)));
  EXPECT_TRUE(grid.contains(Eigen::Vector3d(0.01, 0.0, 0.016), 0.002));
  EXPECT_EQ(grid.describe(),
            "7x5x4 vertices, 160.0 x 120.0 x 70.0 mm (cell 26.7 x 30.0 x 23.3 mm)");
}

TEST(WorkspaceGridTest, BoxVisitOrderCoversEveryVertexWithOneCellMoves) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.12, 0.08, 0.06),
                           Eigen::Vector3i(4, 3, 2));
  const auto order = grid.visitOrder(Eigen::Vector3d(0.1, -0.1, 0.1));
  ASSERT_EQ(order.size(), 24u);
  EXPECT_EQ(std::set<int>(order.begin(), order.end()).size(), 24u);
  EXPECT_EQ(order.front(), grid.vertexIndex(3, 0, 1));
  for (std::size_t k = 1; k < order.size(); ++k) {
    const Eigen::Vector3i step =
        grid.vertexCoordinates(order[k]) - grid.vertexCoordinates(order[k - 1]);
    EXPECT_EQ(step.cwiseAbs().sum(), 1) << "move " << k;
  }
}

TEST(WorkspaceGridTest, ACubeIsABoxWithEqualAxes) {
  const WorkspaceGrid cube(Eigen::Vector3d(0.0, 0.01, 0.0), 0.06, 4);
  const WorkspaceGrid box(Eigen::Vector3d(0.0, 0.01, 0.0), Eigen::Vector3d::Constant(0.06),
                          Eigen::Vector3i::Constant(4));
  EXPECT_TRUE(cube.isCube());
  EXPECT_TRUE(cube.sameGeometry(box));
  EXPECT_FALSE(cube.sameGeometry(WorkspaceGrid(Eigen::Vector3d(0.0, 0.01, 0.0),
                                               Eigen::Vector3d(0.06, 0.06, 0.05),
                                               Eigen::Vector3i::Constant(4))));
}

TEST(WorkspaceGridTest, BoxRejectsABadAxisAndNamesIt) {
  try {
    WorkspaceGrid(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1, 0.0, 0.1),
                  Eigen::Vector3i(3, 3, 3));
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("along y"), std::string::npos) << error.what();
  }
  try {
    WorkspaceGrid(Eigen::Vector3d::Zero(), Eigen::Vector3d::Constant(0.1),
                  Eigen::Vector3i(3, 3, 65));
    FAIL() << "expected an error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("65 along z"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace autograv
