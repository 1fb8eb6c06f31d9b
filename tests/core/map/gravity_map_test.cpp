#include "autograv/map/gravity_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

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

TEST(GravityMapTest, OutsideTheMapExtendsLinearlyForOneCellThenHolds) {
  // The 5-vertex grid from -0.04 to 0.04 m has 20 mm cells: an affine field is exact up to 20 mm
  // outside, along one axis as in a corner, and holds the value reached there beyond.
  Eigen::Matrix3d gradient;
  gradient << 1.0, 2.0, -3.0, 0.5, -1.0, 4.0, 2.0, 0.0, 1.5;
  const Eigen::Vector3d offset(0.1, -0.2, -2.0);
  const GravityMap map = makeAffineMap(gradient, offset);
  const auto affine = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return offset + gradient * p;
  };
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(0.055, 0.0, -0.01), Eigen::Vector3d(-0.06, 0.01, -0.01),
        Eigen::Vector3d(0.0, 0.0, -0.065), Eigen::Vector3d(0.059, -0.059, 0.045)}) {
    EXPECT_TRUE(map.gravityAt(p).isApprox(affine(p), 1e-12)) << p.transpose();
  }
  const Eigen::Vector3d far(0.5, 0.0, -0.01);
  const Eigen::Vector3d one_cell_out(0.06, 0.0, -0.01);
  EXPECT_TRUE(map.gravityAt(far).isApprox(affine(one_cell_out), 1e-12));
  // However far and whichever way, the value stays within the vertices' range extended by a
  // cell's change: bounded.
  EXPECT_TRUE(map.gravityAt(Eigen::Vector3d::Constant(1e9))
                  .isApprox(affine(Eigen::Vector3d(0.06, 0.06, 0.05)), 1e-12));
  EXPECT_TRUE(map.gravityAt(Eigen::Vector3d::Constant(NAN)).allFinite());
  EXPECT_TRUE(map.gravityAt(Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()))
                  .allFinite());
}

// The textbook form of trilinear interpolation, eight weighted corners, for comparison.
Eigen::Vector3d referenceTrilinear(const GravityMap& map, const Eigen::Vector3d& position_m) {
  const WorkspaceGrid& grid = map.grid();
  const Eigen::Vector3d cells = (position_m - grid.minCorner_m()).cwiseQuotient(grid.spacing_m());
  int cell[3];
  double t[3];
  for (int axis = 0; axis < 3; ++axis) {
    // One cell of linear extension beyond the grid, held further out.
    const int last = grid.resolution()[axis] - 1;
    const double clamped = std::clamp(cells[axis], -1.0, last + 1.0);
    cell[axis] = std::clamp(static_cast<int>(std::floor(clamped)), 0, last - 1);
    t[axis] = clamped - cell[axis];
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int corner = 0; corner < 8; ++corner) {
    const int d[3] = {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
    double weight = 1.0;
    for (int axis = 0; axis < 3; ++axis) weight *= d[axis] ? t[axis] : 1.0 - t[axis];
    const int index = grid.vertexIndex(cell[0] + d[0], cell[1] + d[1], cell[2] + d[2]);
    sum += weight * map.vertices()[static_cast<std::size_t>(index)].gravity_n;
  }
  return sum;
}

TEST(GravityMapTest, LookupMatchesTheTextbookInterpolationAndTellsInsideFromOutside) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> value(-3.0, 3.0);
  std::uniform_real_distribution<double> coordinate(-0.1, 0.1);
  constexpr double kMargin_m = 0.01;
  for (int resolution = 2; resolution <= 7; ++resolution) {
    const WorkspaceGrid grid(Eigen::Vector3d(0.01, -0.02, 0.005), 0.07 + 0.01 * resolution,
                             resolution);
    std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
    for (auto& vertex : vertices) {
      vertex.gravity_n = Eigen::Vector3d(value(random), value(random), value(random));
    }
    const GravityMap map(grid, std::move(vertices), MapMetadata{});
    for (int k = 0; k < 2000; ++k) {
      const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
      bool inside = false;
      const Eigen::Vector3d gravity_n = map.gravityAt(p, kMargin_m, inside);
      EXPECT_LT((gravity_n - referenceTrilinear(map, p)).cwiseAbs().maxCoeff(), 1e-12)
          << "resolution " << resolution << " at " << p.transpose();
      EXPECT_EQ(gravity_n, map.gravityAt(p));
      EXPECT_EQ(inside, grid.contains(p, kMargin_m)) << p.transpose();
    }
    for (int i = 0; i < grid.vertexCount(); ++i) {  // exact at the vertices
      EXPECT_LT((map.gravityAt(grid.vertexPosition(i)) -
                 map.vertices()[static_cast<std::size_t>(i)].gravity_n)
                    .cwiseAbs()
                    .maxCoeff(),
                1e-12);
    }
    bool inside = true;
    map.gravityAt(Eigen::Vector3d(NAN, 0.0, 0.0), kMargin_m, inside);
    EXPECT_FALSE(inside);
  }
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

// No device's gravity is anywhere near kMaxGravityEstimate_n; a map holding such a value is
// corrupt, and interpolating or adding it in the servo path could overflow.
TEST(GravityMapTest, RejectsAnEstimateNoDeviceCouldHave) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 2);
  std::vector<VertexEstimate> vertices(8);
  vertices[5].gravity_n = Eigen::Vector3d(0.0, 0.0, -kMaxGravityEstimate_n);
  EXPECT_NO_THROW(GravityMap(grid, vertices, MapMetadata{}));
  vertices[5].gravity_n.z() = -1e300;
  try {
    GravityMap(grid, vertices, MapMetadata{});
    FAIL() << "a 1e300 N estimate was accepted";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("vertex 5"), std::string::npos) << error.what();
  }
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
