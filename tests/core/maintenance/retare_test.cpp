// retare's map edit alone: every vertex moves by the one measured shift, and nothing else of
// the map changes.
#include <cstddef>

#include <gtest/gtest.h>

#include "autograv/maintenance/retare.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/workspace_grid.h"
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
