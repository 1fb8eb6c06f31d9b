#include "autograv/map/workspace_fit.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/serial_arm_device.h"
#include "autograv/sim/simulated_device.h"

namespace autograv {
namespace {

TEST(WorkspaceFitTest, ABoxAroundASphereHoldsNinetyPercentOfIt) {
  const Eigen::Vector3d centre(0.01, -0.02, 0.03);
  const double radius_m = 0.075;
  const ReachabilityTest sphere = [&](const Eigen::Vector3d& x) {
    return (x - centre).norm() <= radius_m;
  };
  const WorkspaceFit fit = fitWorkspaceBox(sphere, centre, radius_m, 0.9);
  EXPECT_GE(fit.workspace_coverage, 0.9);
  EXPECT_LT(fit.workspace_coverage, 0.93);  // no bigger than it needs to be
  EXPECT_LT((fit.center_m - centre).norm(), 2e-3);
  // Symmetric, and between the inscribed cube (side 2 r / sqrt 3) and the enclosing one.
  EXPECT_LT(fit.size_m.maxCoeff() - fit.size_m.minCoeff(), 3e-3);
  EXPECT_GT(fit.size_m.minCoeff(), 2.0 * radius_m / std::sqrt(3.0));
  EXPECT_LT(fit.size_m.maxCoeff(), 2.0 * radius_m);
  // The coverage function agrees with the fit's own figure.
  const WorkspaceGrid box(fit.center_m, fit.size_m, Eigen::Vector3i::Constant(2));
  EXPECT_NEAR(workspaceCoverage(box, sphere, centre, radius_m, 20000, 11), fit.workspace_coverage,
              0.01);
}

TEST(WorkspaceFitTest, AFlatWorkspaceGivesAFlatBox) {
  const ReachabilityTest slab = [](const Eigen::Vector3d& x) {
    return std::abs(x.x()) <= 0.08 && std::abs(x.y()) <= 0.06 && std::abs(x.z()) <= 0.035;
  };
  const WorkspaceFit fit = fitWorkspaceBox(slab, Eigen::Vector3d::Zero(), 0.1, 0.9);
  EXPECT_GE(fit.workspace_coverage, 0.9);
  EXPECT_GT(fit.size_m.x(), fit.size_m.y());
  EXPECT_GT(fit.size_m.y(), fit.size_m.z());
  EXPECT_LE(fit.size_m.z(), 0.070 + 1e-9);
}

TEST(WorkspaceFitTest, RefusesWhatCannotBeFitted) {
  const ReachabilityTest nowhere = [](const Eigen::Vector3d&) { return false; };
  EXPECT_THROW(fitWorkspaceBox(nowhere, Eigen::Vector3d::Zero(), 0.1), Error);
  const ReachabilityTest everywhere = [](const Eigen::Vector3d&) { return true; };
  EXPECT_THROW(fitWorkspaceBox(everywhere, Eigen::Vector3d::Zero(), 0.1, 1.5), Error);
}

class DeviceWorkspaceFitTest : public ::testing::TestWithParam<std::string> {};

TEST_P(DeviceWorkspaceFitTest, TheDefaultBoxCoversNinetyPercentOfTheReachableWorkspace) {
  const auto device = sim::makeSimulatedDevice(GetParam(), 1);
  const WorkspaceFit fit = sim::fitGridToDevice(*device);
  EXPECT_GE(fit.workspace_coverage, 0.9) << GetParam();
  const WorkspaceGrid grid(fit.center_m, fit.size_m, Eigen::Vector3i::Constant(5));
  EXPECT_GE(sim::deviceWorkspaceCoverage(*device, grid), 0.9) << GetParam();
  // The box's faces stay within reach of the centre: no face is all holes.
  EXPECT_LE(0.5 * fit.size_m.maxCoeff(), device->specifications().workspace_radius_m);
  EXPECT_TRUE(device->isReachable(fit.center_m));
}

INSTANTIATE_TEST_SUITE_P(EverySimulatedDevice, DeviceWorkspaceFitTest,
                         ::testing::ValuesIn(sim::simulatedDeviceNames()));

TEST(WorkspaceFitTest, TheOmniReachesNeitherBeyondItsSphereNorPastItsElbowStop) {
  const auto device = sim::makeSimulatedDevice("sim:omni", 1);
  const double radius_m = device->specifications().workspace_radius_m;
  EXPECT_TRUE(device->isReachable(Eigen::Vector3d::Zero()));
  EXPECT_TRUE(device->isReachable(Eigen::Vector3d(0.0, 0.0, 0.99 * radius_m)));
  EXPECT_FALSE(device->isReachable(Eigen::Vector3d(0.0, 0.0, 1.01 * radius_m)));
  // The elbow stop lies beyond the sphere (SerialArmDevice refuses an arm whose stop cuts into
  // it): every point of the sphere is on the arm's branch within the stop, and a pose folded past
  // the stop is unreachable, beyond the sphere too.
  const auto& arm = dynamic_cast<const sim::SerialArmDevice&>(*device);
  const double max_offset_rad = arm.parameters().max_elbow_offset_rad;
  Eigen::Vector3d q;
  for (int i = -3; i <= 3; ++i) {
    for (int j = -3; j <= 3; ++j) {
      for (int k = -3; k <= 3; ++k) {
        // A point of the 7x7x7 lattice pulled into the sphere: the corners onto its surface.
        const Eigen::Vector3d lattice(i, j, k);
        const Eigen::Vector3d point_m =
            radius_m * lattice / std::max(3.0, lattice.norm()) * (1.0 - 1e-9);
        ASSERT_TRUE(arm.inverseKinematics(point_m, q)) << point_m.transpose();
        EXPECT_LT(std::abs(q[2] - q[1]), max_offset_rad) << point_m.transpose();
        EXPECT_TRUE(device->isReachable(point_m)) << point_m.transpose();
      }
    }
  }
  const Eigen::Vector3d folded = arm.forwardKinematics(Eigen::Vector3d(0.0, 0.4802, 0.4802 - 1.45));
  ASSERT_TRUE(arm.inverseKinematics(folded, q)) << folded.transpose();
  EXPECT_NEAR(q[2] - q[1], -1.45, 1e-9);
  EXPECT_FALSE(device->isReachable(folded));
  EXPECT_GT(folded.norm(), radius_m);
}

}  // namespace
}  // namespace autograv
