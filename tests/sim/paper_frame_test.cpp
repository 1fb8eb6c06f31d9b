#include "autograv/sim/paper_frame.h"

#include <gtest/gtest.h>
#include <Eigen/LU>

namespace autograv::sim {
namespace {

TEST(PaperFrameTest, PaperPointsLandWhereTheBriefSays) {
  // Paper: x right, y up, z toward the user, mm. CHAI3D: x toward the user, y right, z up, m.
  EXPECT_TRUE(paperTargetPoint_m().isApprox(Eigen::Vector3d(0.0, 0.0, -0.030), 1e-15));
  EXPECT_TRUE(paperStartPoint_m().isApprox(Eigen::Vector3d(0.0116, -0.0092, -0.0683), 1e-15));
}

TEST(PaperFrameTest, AxesMapOneToOneAndKeepHandedness) {
  Eigen::Matrix3d rotation;
  for (int axis = 0; axis < 3; ++axis) {
    rotation.col(axis) = paperToChai3dFrame(1000.0 * Eigen::Vector3d::Unit(axis));
  }
  EXPECT_TRUE(rotation.col(0).isApprox(Eigen::Vector3d::UnitY()));  // right
  EXPECT_TRUE(rotation.col(1).isApprox(Eigen::Vector3d::UnitZ()));  // up
  EXPECT_TRUE(rotation.col(2).isApprox(Eigen::Vector3d::UnitX()));  // toward the user
  EXPECT_NEAR(rotation.determinant(), 1.0, 1e-15);
}

TEST(PaperFrameTest, RoundTrip) {
  const Eigen::Vector3d paper(-9.2, -68.3, 11.6);
  EXPECT_TRUE(chai3dToPaperFrame(paperToChai3dFrame(paper)).isApprox(paper, 1e-15));
}

}  // namespace
}  // namespace autograv::sim
