// The field figures a calibration reports against the simulation's truth: where a released stylus
// would drift (the error beats the device's breakaway force).
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/map/gravity_map.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {
namespace {

/// A map of `device`'s true field on a fine cube around its workspace, every value off by
/// `offset_n`. Unit: [N]
GravityMap offsetMap(const SimulatedDevice& device, const Eigen::Vector3d& offset_n) {
  const WorkspaceGrid grid(device.workspaceCenter_m(),
                           2.4 * device.specifications().workspace_radius_m, 9);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
    vertex.outcome = VertexOutcome::kConverged;
    vertex.gravity_n = device.trueGravity(grid.vertexPosition(i)) + offset_n;
  }
  return GravityMap(grid, std::move(vertices), MapMetadata{});
}

TEST(FieldErrorTest, TheShareAboveBreakawayIsWhereTheErrorBeatsIt) {
  const auto device =
      makeSimulatedDevice("sim:omega", 1, FrictionLevel::kTypical, {1, ActuatorTolerance::kIdeal});
  const GravityMap map = offsetMap(*device, Eigen::Vector3d(0.0, 0.1, 0.0));
  // The trilinear table of a smooth field errs by a few millinewtons at most: the 100 mN offset
  // is the error everywhere.
  const FieldErrorReport below = measureFieldError(map, *device, 4000, 1, 5e-3, 0.05);
  EXPECT_NEAR(below.max_n, 0.1, 0.01);
  EXPECT_EQ(below.breakaway_n, 0.05);
  EXPECT_EQ(below.above_breakaway_fraction, 1.0);
  const FieldErrorReport above = measureFieldError(map, *device, 4000, 1, 5e-3, 0.2);
  EXPECT_EQ(above.above_breakaway_fraction, 0.0);
  // Without a breakaway force nothing is counted; the other figures do not change.
  const FieldErrorReport none = measureFieldError(map, *device, 4000, 1);
  EXPECT_EQ(none.above_breakaway_fraction, 0.0);
  EXPECT_EQ(none.p90_rel, below.p90_rel);
  EXPECT_THROW(measureFieldError(map, *device, 4000, 1, 5e-3, -1.0), Error);
}

}  // namespace
}  // namespace autograv::sim
