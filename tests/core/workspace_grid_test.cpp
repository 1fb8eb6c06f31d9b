#include "autograv/map/workspace_grid.h"

#include <set>

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

}  // namespace
}  // namespace autograv
