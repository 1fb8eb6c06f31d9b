// Maps made of measurements off their vertices, solved on a finer lookup grid, and written as
// schema 3.
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/map_io.h"
#include "autograv/map/vertex_fill.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

Eigen::Vector3d affineField(const Eigen::Vector3d& x) {
  Eigen::Matrix3d slope;
  slope << 2.0, -1.0, 0.5, 0.3, 1.5, -2.0, -0.7, 0.4, 3.0;
  return Eigen::Vector3d(0.1, -0.2, 1.0) + slope * x;
}

Eigen::Vector3d curvedField(const Eigen::Vector3d& x) {
  return Eigen::Vector3d(0.0, 0.0, 1.0) +
         Eigen::Vector3d(30.0 * x.x() * x.x(), 0.0, 40.0 * x.x() * x.y());
}

// A 5x5x5 map of `field` measured at every vertex, except that every vertex with x index 4 is
// measured 8 mm inside it instead (as beyond a stop), and its value left for the solver.
GravityMap measuredMap(Eigen::Vector3d (*field)(const Eigen::Vector3d&), int refinement) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.08, 5);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    v.outcome = VertexOutcome::kConverged;
    const Eigen::Vector3d at = grid.vertexPosition(i);
    if (grid.vertexCoordinates(i).x() == 4) {
      v.measured_at_m = at - Eigen::Vector3d(0.008, 0.0, 0.0);
      v.measured_gravity_n = field(v.measured_at_m);
      v.gravity_n = Eigen::Vector3d::Zero();
    } else {
      v.gravity_n = field(at);
    }
  }
  fillUnreachableVertices(grid, vertices);
  MapMetadata metadata;
  metadata.device_model = "test";
  metadata.created_utc = "2026-12-01T12:00:00Z";
  metadata.lookup_refinement = refinement;
  return GravityMap(grid, std::move(vertices), metadata);
}

TEST(MapRefinementTest, MeasurementsOffTheirVerticesReproduceAnAffineField) {
  for (const int refinement : {1, 2, 3}) {
    const GravityMap map = measuredMap(affineField, refinement);
    std::mt19937 random(7);
    std::uniform_real_distribution<double> inside(-0.04, 0.04);
    for (int k = 0; k < 200; ++k) {
      const Eigen::Vector3d x(inside(random), inside(random), inside(random));
      EXPECT_LT((map.gravityAt(x) - affineField(x)).norm(), 1e-6) << "refinement " << refinement;
    }
    // The solved vertex beyond reach carries the field's value there.
    const int far = map.grid().vertexIndex(4, 2, 2);
    EXPECT_EQ(map.vertices()[static_cast<std::size_t>(far)].provenance, VertexProvenance::kFilled);
    EXPECT_LT((map.vertices()[static_cast<std::size_t>(far)].gravity_n -
               affineField(map.grid().vertexPosition(far)))
                  .norm(),
              1e-6);
  }
}

TEST(MapRefinementTest, AFinerLookupFollowsACurvedFieldBetterAndKeepsTheVertices) {
  const GravityMap coarse = measuredMap(curvedField, 1);
  const GravityMap fine = measuredMap(curvedField, kThinPlateRefinement);
  double coarse_sum = 0.0, fine_sum = 0.0;
  std::mt19937 random(3);
  std::uniform_real_distribution<double> inside(-0.03, 0.03);
  for (int k = 0; k < 500; ++k) {
    const Eigen::Vector3d x(inside(random), inside(random), inside(random));
    coarse_sum += (coarse.gravityAt(x) - curvedField(x)).norm();
    fine_sum += (fine.gravityAt(x) - curvedField(x)).norm();
  }
  EXPECT_LT(fine_sum, 0.7 * coarse_sum);
  for (int i = 0; i < coarse.grid().vertexCount(); ++i) {
    if (coarse.grid().vertexCoordinates(i).x() == 4) continue;  // solved, not measured
    EXPECT_LT((fine.gravityAt(coarse.grid().vertexPosition(i)) -
               curvedField(coarse.grid().vertexPosition(i)))
                  .norm(),
              1e-9);
  }
}

TEST(MapRefinementTest, TheRefinedLookupAllocatesNothing) {
  const GravityMap map = measuredMap(curvedField, kThinPlateRefinement);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  bool inside = false;
  testing::AllocationCounter counter;
  for (int k = 0; k < 10000; ++k) {
    const Eigen::Vector3d x(-0.06 + 1.2e-5 * k, 0.01, -0.02);
    sum += map.gravityAt(x) + map.gravityAt(x, 0.005, inside);
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(sum.allFinite());
}

TEST(MapRefinementTest, ARefinementOutOfRangeIsRefused) {
  EXPECT_THROW(measuredMap(affineField, 0), Error);
  EXPECT_THROW(measuredMap(affineField, kMaxLookupRefinement + 1), Error);
  // A fine grid refined much further would cost a long solve at every load: refused.
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 16);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (auto& vertex : vertices) vertex.outcome = VertexOutcome::kConverged;
  MapMetadata metadata;
  metadata.lookup_refinement = 4;  // 61^3 lookup vertices
  try {
    GravityMap(grid, vertices, metadata);
    ADD_FAILURE() << "expected a refusal";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("MapMetadata::lookup_refinement"), std::string::npos)
        << error.what();
  }
}

TEST(MapRefinementTest, AThinPlateLookupThatWouldTakeMinutesToBuildIsRefused) {
  // 33^3 lookup vertices: the sparse solve would take over a minute at every load.
  try {
    measuredMap(curvedField, kMaxLookupRefinement);
    ADD_FAILURE() << "expected a refusal";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what())
                  .find("makes more than " + std::to_string(kMaxThinPlateLookupVertices)),
              std::string::npos)
        << error.what();
  }
  // The finest thin-plate lookup the tools ever wrote (a 16x16x16 grid at refinement 2) loads.
  EXPECT_LE(
      lookupResolution(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 16), 2, FieldModel::kThinPlate)
          .cast<long>()
          .prod(),
      kMaxThinPlateLookupVertices);
}

TEST(MapRefinementTest, WorkspaceMeasurementsAndRefinementRoundTripInSchema3) {
  const testing::ScratchFolder folder("map-refinement");
  const std::string path = folder.file("refined_map.json");
  GravityMap original = measuredMap(curvedField, 2);
  MapMetadata metadata = original.metadata();
  metadata.workspace =
      ExploredWorkspace(Eigen::Vector3d(0.001, 0.0, -0.002), ExploredWorkspace::probeDirections(8),
                        std::vector<double>(8, 0.05));
  original = GravityMap(original.grid(), original.vertices(), metadata);
  saveMap(original, path);
  const GravityMap loaded = loadMap(path);
  EXPECT_EQ(loaded.metadata().lookup_refinement, 2);
  ASSERT_EQ(loaded.metadata().workspace.directions().size(), 8u);
  EXPECT_EQ(loaded.metadata().workspace.center_m(), metadata.workspace.center_m());
  EXPECT_EQ(loaded.metadata().workspace.radii_m(), metadata.workspace.radii_m());
  for (int i = 0; i < original.grid().vertexCount(); ++i) {
    const VertexEstimate& a = original.vertices()[static_cast<std::size_t>(i)];
    const VertexEstimate& b = loaded.vertices()[static_cast<std::size_t>(i)];
    EXPECT_EQ(a.measuredOffVertex(), b.measuredOffVertex()) << i;
    if (a.measuredOffVertex()) {
      EXPECT_EQ(a.measured_at_m, b.measured_at_m) << i;
      EXPECT_EQ(a.measured_gravity_n, b.measured_gravity_n) << i;
    }
  }
  const Eigen::Vector3d x(0.013, -0.021, 0.007);
  EXPECT_EQ(loaded.gravityAt(x), original.gravityAt(x));
}

}  // namespace
}  // namespace autograv
