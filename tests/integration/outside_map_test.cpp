// Outside its grid a map is extended linearly for one cell from the boundary cell: on a
// simulated device, closer to the truth than the boundary value an application would otherwise
// get when the stylus leaves the calibrated box.
#include <random>

#include <gtest/gtest.h>

#include "autograv/sim/simulated_device.h"
#include "sim/experiments.h"

namespace autograv {
namespace {

class OutsideMapTest : public ::testing::TestWithParam<std::string> {};

TEST_P(OutsideMapTest, TheExtendedMapIsCloserToTheTruthThanTheBoundaryValue) {
  auto device = sim::makeSimulatedDevice(GetParam(), 1);
  ASSERT_TRUE(device->open());
  sim::DefaultCubeOptions cube;
  cube.resolution = 5;
  cube.explore = false;  // every vertex of the default cube is reachable
  const GravityMap map = *sim::calibrateDefaultCube(*device, cube).map;
  ASSERT_TRUE(map.isComplete());

  // Reachable points 8-12 mm outside the box, where a hand that leaves the map goes first.
  const Eigen::Vector3d low_m = map.grid().minCorner_m();
  const Eigen::Vector3d high_m = low_m + map.grid().size_m();
  std::mt19937 random(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double extended_sum = 0.0;
  double boundary_sum = 0.0;
  int count = 0;
  for (int k = 0; k < 200000 && count < 500; ++k) {
    const Eigen::Vector3d p_m =
        device->workspaceCenter_m() + device->specifications().workspace_radius_m *
                                          Eigen::Vector3d(unit(random), unit(random), unit(random));
    const Eigen::Vector3d on_box_m = p_m.cwiseMax(low_m).cwiseMin(high_m);
    const double outside_m = (p_m - on_box_m).norm();
    if (outside_m < 0.008 || outside_m > 0.012 || !device->isReachable(p_m)) continue;
    const Eigen::Vector3d truth_n = device->trueGravity(p_m);
    extended_sum += (map.gravityAt(p_m) - truth_n).norm() / truth_n.norm();
    boundary_sum += (map.gravityAt(on_box_m) - truth_n).norm() / truth_n.norm();
    ++count;
  }
  ASSERT_EQ(count, 500);
  const double extended_mean = extended_sum / count;
  const double boundary_mean = boundary_sum / count;
  RecordProperty("extended_mean_percent", std::to_string(100.0 * extended_mean));
  RecordProperty("boundary_mean_percent", std::to_string(100.0 * boundary_mean));
  EXPECT_LT(extended_mean, 0.5 * boundary_mean);
  EXPECT_LT(extended_mean, 0.015);
}

INSTANTIATE_TEST_SUITE_P(EverySimulatedDevice, OutsideMapTest,
                         ::testing::Values("sim:omega", "sim:omni", "sim:falcon"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           return info.param.substr(4);
                         });

}  // namespace
}  // namespace autograv
