// retare's map edit alone: every vertex moves by the one measured shift, and nothing else of
// the map changes.
#include <cstddef>

#include <gtest/gtest.h>

#include "autograv/maintenance/retare.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"
#include "explored_fixture_map.h"
#include "field_map.h"

namespace autograv {
namespace {

TEST(ShiftedMapTest, MovesEveryVertexByTheShiftAndKeepsEverythingElse) {
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.0, 0.01), 0.06, 3);
  MapMetadata metadata;
  metadata.device_model = "test arm";
  const auto map = testing::fieldMap(
      grid, [](const Eigen::Vector3d& x_m) { return Eigen::Vector3d(2.0 * x_m.x(), 0.0, 0.5); },
      metadata);
  const Eigen::Vector3d shift_n(0.0, 0.0, 0.02);
  const GravityMap shifted = shiftedMap(*map, shift_n);

  ASSERT_EQ(shifted.vertices().size(), map->vertices().size());
  for (std::size_t i = 0; i < map->vertices().size(); ++i) {
    EXPECT_TRUE(shifted.vertices()[i].gravity_n.isApprox(map->vertices()[i].gravity_n + shift_n))
        << "vertex " << i;
    EXPECT_EQ(shifted.vertices()[i].outcome, map->vertices()[i].outcome);
  }
  EXPECT_EQ(shifted.grid().resolution(), grid.resolution());
  EXPECT_EQ(shifted.metadata().device_model, "test arm");
  // Between vertices too: the interpolant is linear in the vertex values.
  const Eigen::Vector3d inside_m(0.013, -0.007, 0.02);
  EXPECT_TRUE(shifted.gravityAt(inside_m).isApprox(map->gravityAt(inside_m) + shift_n, 1e-12));
}

TEST(ShiftedMapTest, ACalibrationsMapMovesByTheShiftEverywhere) {
  // Measured off its vertices next to the stops and read through the fit the measurements chose,
  // as the calibrations make it: the off-vertex measurements move too, or the fit would pull the
  // values near the stops back to the old handle's.
  const GravityMap map = testing::makeExploredFixtureMap(
      [](const Eigen::Vector3d& x_m) {
        return Eigen::Vector3d(0.3 * x_m.x(), 0.3 * x_m.y() - 0.1, 2.0 + 5.0 * x_m.z() * x_m.z());
      },
      [](const Eigen::Vector3d& x_m) { return x_m.norm() < 0.045; });
  ASSERT_NE(map.fieldModel(), FieldModel::kThinPlate);
  const Eigen::Vector3d shift_n(0.0, 0.0, 0.05);
  const GravityMap shifted = shiftedMap(map, shift_n);
  // The map keeps the model it was chosen with: a constant shift is in every model's span.
  ASSERT_EQ(shifted.fieldModel(), map.fieldModel());
  ASSERT_EQ(shifted.curlWeight(), map.curlWeight());
  int off_vertex = 0;
  for (std::size_t i = 0; i < map.vertices().size(); ++i) {
    const VertexEstimate& before = map.vertices()[i];
    const VertexEstimate& after = shifted.vertices()[i];
    EXPECT_TRUE(after.gravity_n.isApprox(before.gravity_n + shift_n, 1e-9)) << "vertex " << i;
    if (before.measuredOffVertex()) {
      ++off_vertex;
      EXPECT_TRUE(after.measured_gravity_n.isApprox(before.measured_gravity_n + shift_n, 1e-12));
    }
  }
  EXPECT_GT(off_vertex, 20);
  for (const Eigen::Vector3d& x_m :
       {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.041, 0.0, 0.0),
        Eigen::Vector3d(-0.02, 0.03, -0.025), Eigen::Vector3d(0.0, -0.044, 0.005)}) {
    EXPECT_LT((shifted.gravityAt(x_m) - map.gravityAt(x_m) - shift_n).norm(), 1e-9)
        << x_m.transpose();
  }
}

TEST(ShiftedMapTest, AZeroShiftGivesTheSameValues) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 2);
  const auto map = testing::uniformFieldMap(grid, Eigen::Vector3d(0.1, -0.2, 0.45), "test arm");
  const GravityMap shifted = shiftedMap(*map, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < map->vertices().size(); ++i) {
    EXPECT_EQ(shifted.vertices()[i].gravity_n, map->vertices()[i].gravity_n);
  }
}

}  // namespace
}  // namespace autograv
