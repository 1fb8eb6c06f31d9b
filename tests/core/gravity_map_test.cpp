#include "autograv/gravity_map.h"

#include <random>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"

namespace autograv {
namespace {

// A map whose vertices hold an affine field; trilinear interpolation must reproduce it exactly.
GravityMap makeAffineMap(const Eigen::Matrix3d& gradient, const Eigen::Vector3d& offset) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, -0.01), 0.08, 5);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n = offset + gradient * grid.vertexPosition(i);
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
  }
  return GravityMap(grid, std::move(vertices), MapMetadata{});
}

TEST(GravityMapTest, TrilinearInterpolationIsExactForAnAffineField) {
  Eigen::Matrix3d gradient;
  gradient << 1.0, 2.0, -3.0, 0.5, -1.0, 4.0, 2.0, 0.0, 1.5;
  const Eigen::Vector3d offset(0.1, -0.2, -2.0);
  const GravityMap map = makeAffineMap(gradient, offset);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-0.04, 0.04);
  for (int k = 0; k < 200; ++k) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random) - 0.01);
    EXPECT_TRUE(map.gravityAt(p).isApprox(offset + gradient * p, 1e-12));
  }
  EXPECT_TRUE(map.isComplete());
}

TEST(GravityMapTest, PointsOutsideAreClampedToTheBoundary) {
  const GravityMap map = makeAffineMap(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const Eigen::Vector3d outside(0.5, 0.0, -0.01);
  const Eigen::Vector3d boundary(0.04, 0.0, -0.01);
  EXPECT_TRUE(map.gravityAt(outside).isApprox(map.gravityAt(boundary)));
  EXPECT_TRUE(map.gravityAt(Eigen::Vector3d::Constant(NAN)).allFinite());
}

TEST(GravityMapTest, QueriesAllocateNothing) {
  const GravityMap map = makeAffineMap(Eigen::Matrix3d::Identity(), Eigen::Vector3d::Ones());
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  testing::AllocationCounter counter;
  for (int k = 0; k < 10000; ++k) sum += map.gravityAt(Eigen::Vector3d::Constant(1e-6 * k));
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(sum.allFinite());
}

TEST(GravityMapTest, RejectsMismatchedOrNonFiniteVertices) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 2);
  EXPECT_THROW(GravityMap(grid, std::vector<VertexEstimate>(7), MapMetadata{}), Error);
  std::vector<VertexEstimate> vertices(8);
  vertices[3].gravity_n.x() = NAN;
  EXPECT_THROW(GravityMap(grid, vertices, MapMetadata{}), Error);
}

TEST(GravityMapTest, OutcomeNamesRoundTrip) {
  for (auto outcome :
       {VertexOutcome::kPending, VertexOutcome::kConverged, VertexOutcome::kIterationCap,
        VertexOutcome::kNoSteadyState, VertexOutcome::kSaturated, VertexOutcome::kDeviceFault}) {
    VertexOutcome parsed{};
    ASSERT_TRUE(parseVertexOutcome(toString(outcome), parsed));
    EXPECT_EQ(parsed, outcome);
  }
  VertexOutcome parsed{};
  EXPECT_FALSE(parseVertexOutcome("bogus", parsed));
}

}  // namespace
}  // namespace autograv
