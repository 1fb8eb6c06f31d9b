#include "autograv/map/explored_workspace.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/LU>

#include "autograv/error.h"
#include "autograv/map/measurement_plan.h"
#include "probed_workspaces.h"

namespace autograv {
namespace {

using testing::probedCube;
using testing::probedSphere;

// How many of the boundary's triangles hold `u` in their cone.
int conesHolding(const ExploredWorkspace& workspace, const Eigen::Vector3d& u) {
  int holding = 0;
  for (const std::array<int, 3>& corners : workspace.facets()) {
    Eigen::Matrix3d spanned;
    spanned << workspace.directions()[static_cast<std::size_t>(corners[0])],
        workspace.directions()[static_cast<std::size_t>(corners[1])],
        workspace.directions()[static_cast<std::size_t>(corners[2])];
    const Eigen::Vector3d weights = spanned.inverse() * u;
    holding += weights.minCoeff() >= -1e-9 ? 1 : 0;
  }
  return holding;
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

TEST(ExploredWorkspaceTest, ClearanceAlongAPathIsTheRoomBeyondThePointThatWay) {
  // 4 mm from the +x face of a cube of half-width 50 mm.
  const ExploredWorkspace cube = probedCube(0.05);
  const Eigen::Vector3d point(0.046, 0.01, -0.02);
  constexpr double kLimit = 0.01;
  EXPECT_NEAR(cube.clearanceAlong_m(point, Eigen::Vector3d::UnitX(), kLimit), 0.004, 1e-12);
  // Along the face, and away from it, the room is the whole limit.
  EXPECT_EQ(cube.clearanceAlong_m(point, Eigen::Vector3d::UnitY(), kLimit), kLimit);
  EXPECT_EQ(cube.clearanceAlong_m(point, -Eigen::Vector3d::UnitX(), kLimit), kLimit);
  // Obliquely toward the face: 4 mm / cos(60 deg).
  const Eigen::Vector3d oblique(0.5, std::sqrt(0.75), 0.0);
  EXPECT_NEAR(cube.clearanceAlong_m(point, oblique, kLimit), 0.008, 1e-12);
  // Through a corner region, where the line leaves through a triangle of the edge directions:
  // what contains() says, to the resolution.
  const Eigen::Vector3d corner_point(0.045, 0.045, 0.03);
  const Eigen::Vector3d diagonal = Eigen::Vector3d(1.0, 1.0, 1.0).normalized();
  const double diagonal_m = cube.clearanceAlong_m(corner_point, diagonal, kLimit);
  EXPECT_TRUE(cube.contains(corner_point + (diagonal_m - 1e-9) * diagonal));
  EXPECT_FALSE(cube.contains(corner_point + (diagonal_m + 1e-6) * diagonal));
  // Outside there is no room; an empty workspace knows of no stop.
  EXPECT_EQ(
      cube.clearanceAlong_m(Eigen::Vector3d(0.06, 0.0, 0.0), -Eigen::Vector3d::UnitX(), kLimit),
      0.0);
  EXPECT_EQ(ExploredWorkspace().clearanceAlong_m(point, Eigen::Vector3d::UnitX(), kLimit), kLimit);
}

TEST(ExploredWorkspaceTest, ClearanceWhereNoTriangleCoversTheLineIsSteppedThroughContains) {
  // Probed over the upper half only: below, the model knows nothing but its shortest reach.
  std::vector<Eigen::Vector3d> upper;
  for (const Eigen::Vector3d& u : ExploredWorkspace::probeDirections(60)) {
    if (u.z() > 0.1) upper.push_back(u);
  }
  const ExploredWorkspace cap(Eigen::Vector3d::Zero(), upper,
                              std::vector<double>(upper.size(), 0.05));
  const Eigen::Vector3d point(0.0, 0.0, -0.02);
  constexpr double kResolution = 5e-4;
  const double down_m = cap.clearanceAlong_m(point, -Eigen::Vector3d::UnitZ(), 0.1, kResolution);
  EXPECT_TRUE(cap.contains(point - down_m * Eigen::Vector3d::UnitZ()));
  EXPECT_FALSE(cap.contains(point - (down_m + kResolution) * Eigen::Vector3d::UnitZ()));
}

TEST(ExploredWorkspaceTest, DepthIsMeasuredSquareToTheBoundaryNotAlongTheRay) {
  // A cube of half-width 50 mm probed along its 26 lattice directions: every boundary point lies
  // on a face, and the facets near the +x face lie in its plane.
  const ExploredWorkspace cube = probedCube(0.05);
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

TEST(ExploredWorkspaceTest, TheBoundaryIsOneTriangulationOfTheDirections) {
  // Spread directions, and a cube's lattice (four of its directions lie on one circle, where a
  // triangulation must still choose).
  std::vector<ExploredWorkspace> workspaces;
  for (int count : {6, 26, 50, 200}) {
    workspaces.push_back(probedSphere(Eigen::Vector3d::Zero(), 0.05, count));
  }
  workspaces.push_back(probedCube(0.05));
  for (const ExploredWorkspace& workspace : workspaces) {
    const std::size_t n = workspace.directions().size();
    // A closed triangulated sphere: F = 2 n - 4, and every direction is a corner.
    EXPECT_EQ(workspace.facets().size(), 2 * n - 4) << n << " directions";
    std::vector<int> corner_of(n, 0);
    for (const auto& corners : workspace.facets()) {
      for (int c : corners) ++corner_of[static_cast<std::size_t>(c)];
    }
    EXPECT_EQ(std::count(corner_of.begin(), corner_of.end(), 0), 0) << n << " directions";
    // Every direction of space lies in a triangle's cone, and off the edges in one only.
    int covered = 0;
    int once = 0;
    const std::vector<Eigen::Vector3d> samples = ExploredWorkspace::probeDirections(997);
    for (const Eigen::Vector3d& u : samples) {
      const int holding = conesHolding(workspace, u);
      covered += holding >= 1 ? 1 : 0;
      once += holding == 1 ? 1 : 0;
    }
    EXPECT_EQ(covered, static_cast<int>(samples.size())) << n << " directions";
    EXPECT_GT(once, static_cast<int>(0.97 * static_cast<double>(samples.size())))
        << n << " directions";
  }
}

TEST(ExploredWorkspaceTest, TheModelMovesContinuouslyWithTheReach) {
  // Two explorations of one workspace whose reaches differ by a tenth of a millimetre plan the
  // same points to within about that much: the plan does not jump between facets.
  const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(26);
  std::vector<double> radii(directions.size());
  for (std::size_t i = 0; i < directions.size(); ++i) {
    const Eigen::Vector3d& u = directions[i];
    radii[i] = 1.0 / std::sqrt(std::pow(u.x() / 0.09, 2) + std::pow(u.y() / 0.07, 2) +
                               std::pow(u.z() / 0.05, 2));
  }
  std::vector<double> nudged = radii;
  for (std::size_t i = 0; i < nudged.size(); ++i) nudged[i] += (i % 3 == 0 ? 1e-4 : -1e-4);
  const ExploredWorkspace first(Eigen::Vector3d::Zero(), directions, radii);
  const ExploredWorkspace second(Eigen::Vector3d::Zero(), directions, nudged);
  const WorkspaceGrid grid = gridAroundWorkspace(first, Eigen::Vector3i::Constant(5));
  const MeasurementPlan a = planMeasurements(grid, first);
  const MeasurementPlan b = planMeasurements(grid, second);
  double largest_m = 0.0;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (!(a.measure[k] && b.measure[k])) continue;
    largest_m = std::max(largest_m, (a.points_m[k] - b.points_m[k]).norm());
  }
  EXPECT_LT(largest_m, 0.5e-3);
  // Along a line across many facets the pulled point never jumps.
  Eigen::Vector3d previous = first.pullInside(Eigen::Vector3d(0.1, -0.08, 0.06), 0.004);
  for (int step = 1; step <= 2000; ++step) {
    const double t = step / 2000.0;
    const Eigen::Vector3d outside(0.1 - 0.2 * t, -0.08 + 0.16 * t, 0.06 - 0.02 * t);
    const Eigen::Vector3d pulled = first.pullInside(outside, 0.004);
    EXPECT_LT((pulled - previous).norm(), 1e-3) << "step " << step;
    EXPECT_GE(first.depth_m(pulled), 0.004 - 1e-9);
    previous = pulled;
  }
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
  // So many directions that the triangulation alone would take minutes.
  const std::size_t too_many = ExploredWorkspace::kMaxDirections + 1;
  EXPECT_THROW(ExploredWorkspace(Eigen::Vector3d::Zero(),
                                 std::vector<Eigen::Vector3d>(too_many, Eigen::Vector3d::UnitX()),
                                 std::vector<double>(too_many, 0.05)),
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
