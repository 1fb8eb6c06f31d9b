#include "autograv/map/vertex_fill.h"

#include <functional>

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

Eigen::Vector3d affineField(const Eigen::Vector3d& x) {
  const Eigen::Matrix3d gradient = (Eigen::Matrix3d() << 8, 2, -3, 1, -6, 2, 4, -1, 12).finished();
  return Eigen::Vector3d(0.3, -0.2, 2.1) + gradient * x;
}

/// Every vertex converged at the field's value, except those `unreachable` says, which carry
/// garbage that the fill must replace.
std::vector<VertexEstimate> verticesOf(
    const WorkspaceGrid& grid, const std::function<bool(const Eigen::Vector3d&)>& unreachable) {
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    const Eigen::Vector3d x = grid.vertexPosition(i);
    if (unreachable(x)) {
      v.outcome = VertexOutcome::kUnreachable;
      v.gravity_n = Eigen::Vector3d(40.0, -40.0, 40.0);  // what a stalled estimate grows to
    } else {
      v.outcome = VertexOutcome::kConverged;
      v.gravity_n = affineField(x);
    }
  }
  return vertices;
}

TEST(VertexFillTest, AnAffineFieldIsReproducedAtFilledCornersAndEdges) {
  // The box fitted around a sphere: its corners and edges lie beyond the workspace.
  const WorkspaceGrid grid(Eigen::Vector3d(0.0, 0.01, 0.0), Eigen::Vector3d(0.128, 0.127, 0.09),
                           Eigen::Vector3i(5, 5, 4));
  const auto outside = [](const Eigen::Vector3d& x) {
    return (x - Eigen::Vector3d(0.0, 0.01, 0.0)).norm() > 0.075;
  };
  std::vector<VertexEstimate> vertices = verticesOf(grid, outside);
  int expected_filled = 0;
  for (const auto& v : vertices) expected_filled += v.outcome == VertexOutcome::kUnreachable;
  ASSERT_GT(expected_filled, 20);
  EXPECT_EQ(fillUnreachableVertices(grid, vertices), expected_filled);
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    const Eigen::Vector3d truth = affineField(grid.vertexPosition(i));
    // Exact up to the vanishing membrane term (about 1e-9 of the field).
    EXPECT_LT((v.gravity_n - truth).norm(), 1e-6) << "vertex " << i;
    EXPECT_EQ(v.provenance, outside(grid.vertexPosition(i)) ? VertexProvenance::kFilled
                                                            : VertexProvenance::kMeasured);
  }
}

TEST(VertexFillTest, AnInteriorHoleIsFilledSmoothlyAndOtherOutcomesAreLeftAlone) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.08, 5);
  std::vector<VertexEstimate> vertices =
      verticesOf(grid, [](const Eigen::Vector3d& x) { return x.norm() < 1e-9; });  // the centre
  const int failed = grid.vertexIndex(0, 0, 0);
  vertices[static_cast<std::size_t>(failed)].outcome = VertexOutcome::kIterationCap;
  vertices[static_cast<std::size_t>(failed)].gravity_n = Eigen::Vector3d(1.0, 2.0, 3.0);
  EXPECT_EQ(fillUnreachableVertices(grid, vertices), 1);
  const int centre = grid.vertexIndex(2, 2, 2);
  EXPECT_LT(
      (vertices[static_cast<std::size_t>(centre)].gravity_n - affineField(Eigen::Vector3d::Zero()))
          .norm(),
      1e-6);
  // A vertex that failed for another reason keeps its value and provenance: it is not data
  // for the fill and not filled either.
  EXPECT_EQ(vertices[static_cast<std::size_t>(failed)].gravity_n, Eigen::Vector3d(1.0, 2.0, 3.0));
  EXPECT_EQ(vertices[static_cast<std::size_t>(failed)].provenance, VertexProvenance::kMeasured);
}

TEST(VertexFillTest, CoplanarMeasurementsStillGiveAFiniteFill) {
  // Only the bottom layer converged: the thin-plate energy alone cannot tell the vertical
  // gradient; the membrane term makes the answer unique (constant upwards).
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), Eigen::Vector3d(0.06, 0.06, 0.04),
                           Eigen::Vector3i(3, 3, 3));
  std::vector<VertexEstimate> vertices =
      verticesOf(grid, [](const Eigen::Vector3d& x) { return x.z() > -0.019; });
  EXPECT_EQ(fillUnreachableVertices(grid, vertices), 18);
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const Eigen::Vector3i c = grid.vertexCoordinates(i);
    const VertexEstimate& v = vertices[static_cast<std::size_t>(i)];
    ASSERT_TRUE(v.gravity_n.allFinite());
    const auto below = vertices[static_cast<std::size_t>(grid.vertexIndex(c.x(), c.y(), 0))];
    // Only the tiny membrane term decides here, so the system is ill-conditioned (about 1e9):
    // constant to some micronewtons.
    EXPECT_LT((v.gravity_n - below.gravity_n).norm(), 1e-4) << "vertex " << i;
  }
}

TEST(VertexFillTest, NothingToFillFromLeavesTheVerticesAsTheyAre) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 2);
  std::vector<VertexEstimate> vertices =
      verticesOf(grid, [](const Eigen::Vector3d&) { return true; });
  EXPECT_EQ(fillUnreachableVertices(grid, vertices), 0);
  for (const auto& v : vertices) EXPECT_EQ(v.provenance, VertexProvenance::kMeasured);
  std::vector<VertexEstimate> wrong_size(3);
  EXPECT_THROW(fillUnreachableVertices(grid, wrong_size), Error);
}

}  // namespace
}  // namespace autograv
