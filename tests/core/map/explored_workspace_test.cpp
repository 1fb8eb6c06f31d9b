#include "autograv/map/explored_workspace.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/map/measurement_plan.h"

namespace autograv {
namespace {

// A sphere of `radius_m` probed along `count` directions.
ExploredWorkspace probedSphere(const Eigen::Vector3d& center_m, double radius_m, int count) {
  const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(count);
  return ExploredWorkspace(center_m, directions, std::vector<double>(directions.size(), radius_m));
}

TEST(ExploredWorkspaceTest, ProbeDirectionsAreUnitSpreadAndAPath) {
  const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(26);
  ASSERT_EQ(directions.size(), 26u);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < directions.size(); ++i) {
    EXPECT_NEAR(directions[i].norm(), 1.0, 1e-12);
    sum += directions[i];
    // Spread: no two closer than 20 degrees.
    for (std::size_t j = 0; j < i; ++j) EXPECT_LT(directions[i].dot(directions[j]), std::cos(0.35));
  }
  EXPECT_LT(sum.norm(), 0.5);  // balanced over the sphere
  EXPECT_THROW(ExploredWorkspace::probeDirections(5), Error);
}

TEST(ExploredWorkspaceTest, TheModelOfAConvexWorkspaceLiesInsideIt) {
  const Eigen::Vector3d center(0.01, -0.02, 0.0);
  const ExploredWorkspace sphere = probedSphere(center, 0.05, 26);
  for (const Eigen::Vector3d& u : ExploredWorkspace::probeDirections(500)) {
    const double reach = sphere.boundaryDistance_m(u);
    EXPECT_LE(reach, 0.05 + 1e-12);
    EXPECT_GT(reach, 0.05 * 0.75);  // the chords between 26 directions sag
  }
  // Exactly the probed reach along a probed direction.
  EXPECT_NEAR(sphere.boundaryDistance_m(sphere.directions()[3]), 0.05, 1e-12);
}

TEST(ExploredWorkspaceTest, ContainsAndPullInsideKeepTheMargin) {
  const Eigen::Vector3d center(0.0, 0.0, 0.01);
  const ExploredWorkspace sphere = probedSphere(center, 0.05, 26);
  EXPECT_TRUE(sphere.contains(center));
  EXPECT_TRUE(sphere.contains(center + Eigen::Vector3d(0.03, 0.0, 0.0), 0.004));
  EXPECT_FALSE(sphere.contains(center + Eigen::Vector3d(0.06, 0.0, 0.0)));
  const Eigen::Vector3d outside = center + Eigen::Vector3d(0.05, 0.05, 0.05);
  const Eigen::Vector3d pulled = sphere.pullInside(outside, 0.004);
  EXPECT_TRUE(sphere.contains(pulled, 0.004 - 1e-9));
  EXPECT_NEAR(sphere.depth_m(pulled), 0.004, 1e-9);
  // Along the ray from the centre.
  EXPECT_NEAR((pulled - center).normalized().dot((outside - center).normalized()), 1.0, 1e-12);
  // An empty workspace knows nothing and holds everything.
  const ExploredWorkspace unknown;
  EXPECT_TRUE(unknown.contains(outside));
  EXPECT_EQ(unknown.pullInside(outside, 0.004), outside);
}

TEST(ExploredWorkspaceTest, DepthIsMeasuredSquareToTheBoundaryNotAlongTheRay) {
  // A cube of half-width 50 mm probed along its 26 lattice directions: every boundary point lies
  // on a face, and the facets near the +x face lie in its plane.
  std::vector<Eigen::Vector3d> directions;
  std::vector<double> radii;
  for (int i = -1; i <= 1; ++i) {
    for (int j = -1; j <= 1; ++j) {
      for (int k = -1; k <= 1; ++k) {
        if (i == 0 && j == 0 && k == 0) continue;
        const Eigen::Vector3d u = Eigen::Vector3d(i, j, k).normalized();
        directions.push_back(u);
        radii.push_back(0.05 / u.cwiseAbs().maxCoeff());
      }
    }
  }
  const ExploredWorkspace cube(Eigen::Vector3d::Zero(), directions, radii);
  // 5 mm from the +x face along its normal; along the oblique ray from the centre it is 6.4 mm.
  const Eigen::Vector3d near_face(0.045, 0.03, 0.02);
  EXPECT_NEAR(cube.depth_m(near_face), 0.005, 1e-9);
  EXPECT_GT(cube.boundaryDistance_m(near_face) - near_face.norm(), 0.006);
  EXPECT_TRUE(cube.contains(near_face, 0.0049));
  EXPECT_FALSE(cube.contains(near_face, 0.0051));
  // Pulled inside, a point beyond the face keeps the margin from the face itself.
  const Eigen::Vector3d beyond(0.06, 0.036, 0.024);
  const Eigen::Vector3d pulled = cube.pullInside(beyond, 0.004);
  EXPECT_NEAR(pulled.x(), 0.046, 1e-9);
  EXPECT_NEAR((pulled.normalized()).dot(beyond.normalized()), 1.0, 1e-12);
}

TEST(ExploredWorkspaceTest, RefusesWhatIsNoWorkspace) {
  const std::vector<Eigen::Vector3d> six = ExploredWorkspace::probeDirections(6);
  EXPECT_THROW(ExploredWorkspace(Eigen::Vector3d::Zero(), six, std::vector<double>(5, 0.05)),
               Error);
  EXPECT_THROW(ExploredWorkspace(Eigen::Vector3d::Zero(), six, std::vector<double>(6, -0.05)),
               Error);
  std::vector<Eigen::Vector3d> zero = six;
  zero[2].setZero();
  EXPECT_THROW(ExploredWorkspace(Eigen::Vector3d::Zero(), zero, std::vector<double>(6, 0.05)),
               Error);
}

TEST(MeasurementPlanTest, NoPointLiesOutsideTheWorkspaceAndEveryCutCellHasOne) {
  const ExploredWorkspace sphere = probedSphere(Eigen::Vector3d::Zero(), 0.05, 26);
  const WorkspaceGrid grid = gridAroundWorkspace(sphere, Eigen::Vector3i::Constant(5));
  EXPECT_NEAR(grid.size_m().maxCoeff(), 0.1, 0.01);  // the model sags between the directions
  const MeasurementPlan plan = planMeasurements(grid, sphere);
  EXPECT_EQ(plan.at_vertex + plan.off_vertex + plan.skipped, grid.vertexCount());
  EXPECT_GT(plan.off_vertex, 0);
  for (int i = 0; i < grid.vertexCount(); ++i) {
    if (!plan.measure[static_cast<std::size_t>(i)]) continue;
    EXPECT_TRUE(
        sphere.contains(plan.points_m[static_cast<std::size_t>(i)], kBoundaryMargin_m - 1e-9))
        << "vertex " << i;
    EXPECT_EQ(plan.offVertex(grid, i), !sphere.contains(grid.vertexPosition(i), kBoundaryMargin_m));
  }
  // The centre vertex is measured where it is.
  EXPECT_FALSE(plan.offVertex(grid, grid.vertexIndex(2, 2, 2)));
}

TEST(MeasurementPlanTest, WithoutAWorkspaceEveryVertexIsMeasuredWhereItIs) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 3);
  const MeasurementPlan plan = planMeasurements(grid, ExploredWorkspace());
  EXPECT_EQ(plan.at_vertex, grid.vertexCount());
  for (int i = 0; i < grid.vertexCount(); ++i) EXPECT_FALSE(plan.offVertex(grid, i));
}

}  // namespace
}  // namespace autograv
