// Every measurement judged against the others before a map is saved: which stand out, where they
// are measured again, and which are left out of the fit.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/map/gravity_map.h"
#include "autograv/map/measurement_review.h"
#include "autograv/map/vertex_fill.h"

namespace autograv {
namespace {

// A field that bends over the workspace as a linkage's does (the gradient of
// U = z + 0.01 (cos 20x + sin 15y cos 12z), about 1 N), the scale of a desktop device. Unit: [N]
Eigen::Vector3d bentField(const Eigen::Vector3d& x_m) {
  return Eigen::Vector3d(-0.2 * std::sin(20.0 * x_m.x()),
                         0.15 * std::cos(15.0 * x_m.y()) * std::cos(12.0 * x_m.z()),
                         1.0 - 0.12 * std::sin(15.0 * x_m.y()) * std::sin(12.0 * x_m.z()));
}

// The bent field, steepening over the last 20 mm before the -x face as a delta's near its
// singular pose (sim:falcon: G_x from 0.10 to 0.45 N over the last 20 mm). Unit: [N]
Eigen::Vector3d steepBandField(const Eigen::Vector3d& x_m) {
  const double band = std::exp((-0.05 - x_m.x()) / 0.008);  // 1 at x = -50 mm
  return bentField(x_m) + Eigen::Vector3d(0.35 * band, 0.0, 0.1 * band);
}

// eps_G of the default estimation parameters (0.5 g-force). Unit: [N]
constexpr double kEpsG_n = 0.5e-3 * 9.81;

WorkspaceGrid fiveCube() { return WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 5); }

// Every vertex measured, with a relative noise of `noise_rel` per component (a hold's scatter).
std::vector<VertexEstimate> measured(const WorkspaceGrid& grid,
                                     Eigen::Vector3d (*field)(const Eigen::Vector3d&),
                                     double noise_rel, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, noise_rel);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
    const Eigen::Vector3d truth_n = field(grid.vertexPosition(i));
    vertex.gravity_n =
        truth_n + truth_n.norm() * Eigen::Vector3d(normal(random), normal(random), normal(random));
    vertex.outcome = VertexOutcome::kConverged;
    vertex.iterations = 8;
  }
  return vertices;
}

// A vertex on the +z face's middle (vertex (2, 2, 4)): held against a ceiling, it measured the
// ceiling's push with the weight.
int ceilingVertex(const WorkspaceGrid& grid) { return grid.vertexIndex(2, 2, 4); }

TEST(MeasurementReviewTest, NoMeasurementStandsOutOfASmoothFieldMeasuredWithScatterIn20Runs) {
  const WorkspaceGrid grid = fiveCube();
  for (unsigned seed = 1; seed <= 20; ++seed) {
    // 0.1 % per component: the scatter of the simulated devices' holds at typical friction.
    const MeasurementJudgement judgement =
        judgeMeasurements(grid, measured(grid, bentField, 1e-3, seed), kEpsG_n);
    EXPECT_EQ(judgement.measurements, grid.vertexCount());
    EXPECT_TRUE(judgement.standing_out.empty()) << "seed " << seed;
  }
}

TEST(MeasurementReviewTest, AMeasurementAStopPushed20PercentOffStandsOutAloneAndBy10Times) {
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 3);
  const int held = ceilingVertex(grid);
  vertices[static_cast<std::size_t>(held)].gravity_n *= 0.8;  // a ceiling took a fifth of it
  const MeasurementJudgement judgement = judgeMeasurements(grid, vertices, kEpsG_n);
  ASSERT_EQ(judgement.standing_out.size(), 1u);
  const StandingOutMeasurement& found = judgement.standing_out.front();
  EXPECT_EQ(found.vertex, held);
  EXPECT_GT(found.residual_rel, 10.0 * found.local_rel);
  EXPECT_GT(found.residual_rel, 0.1);
}

TEST(MeasurementReviewTest, AMeasurementTwoPercentOffAFieldKnownTo0Point1PercentStandsOut) {
  // Not a fixed percentage: 2 % is far outside what these measurements scatter by.
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 4);
  const int held = grid.vertexIndex(1, 3, 0);
  vertices[static_cast<std::size_t>(held)].gravity_n *= 1.02;
  const MeasurementJudgement judgement = judgeMeasurements(grid, vertices, kEpsG_n);
  ASSERT_EQ(judgement.standing_out.size(), 1u);
  EXPECT_EQ(judgement.standing_out.front().vertex, held);
}

TEST(MeasurementReviewTest, AFieldThatSteepensNearAStopLeavesEveryMeasurementThereStanding) {
  // The band's measurements all disagree with the fit alike: a steep field, not a contradiction.
  const WorkspaceGrid grid = fiveCube();
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const MeasurementJudgement judgement =
        judgeMeasurements(grid, measured(grid, steepBandField, 1e-3, seed), kEpsG_n);
    EXPECT_TRUE(judgement.standing_out.empty()) << "seed " << seed;
  }
}

TEST(MeasurementReviewTest, AtMostOneInTwentyMeasurementsStandsOut) {
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 5);
  std::mt19937 random(9);
  for (int k = 0; k < 30; ++k) {
    vertices[random() % vertices.size()].gravity_n *= 1.3;  // a device that drifts, not a stop
  }
  const MeasurementJudgement judgement = judgeMeasurements(grid, vertices, kEpsG_n);
  EXPECT_LE(static_cast<double>(judgement.standing_out.size()),
            kStandOutShare * grid.vertexCount());
}

TEST(MeasurementReviewTest, TooFewMeasurementsAreNotJudged) {
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 2);
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 0.0, 1);
  vertices[0].gravity_n *= 2.0;
  const MeasurementJudgement judgement = judgeMeasurements(grid, vertices, kEpsG_n);
  EXPECT_EQ(judgement.measurements, 8);
  EXPECT_TRUE(judgement.standing_out.empty());
}

TEST(MeasurementReviewTest, TwoMeasurementsThatDisagreeAndBothStandOutAreLeftOutOfTheFit) {
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 6);
  const int held = ceilingVertex(grid);
  const Eigen::Vector3d clear_n = vertices[static_cast<std::size_t>(held)].gravity_n;
  vertices[static_cast<std::size_t>(held)].gravity_n = 0.8 * clear_n;
  std::vector<ReviewedMeasurement> reviewed = planReview(grid, vertices, kEpsG_n);
  ASSERT_EQ(reviewed.size(), 1u);
  EXPECT_EQ(reviewed.front().verdict, ReviewVerdict::kPending);
  EXPECT_EQ(reviewed.front().again_point_m, grid.vertexPosition(held));
  // Measured again, and held by the stop again, harder.
  const Eigen::Vector3d again_n = 0.7 * clear_n;
  vertices[static_cast<std::size_t>(held)].gravity_n = again_n;
  concludeReview(grid, vertices, reviewed, kEpsG_n);
  EXPECT_EQ(reviewed.front().verdict, ReviewVerdict::kLeftOut);
  EXPECT_GT(reviewed.front().again_residual_rel, 0.1);
  const VertexEstimate& vertex = vertices[static_cast<std::size_t>(held)];
  EXPECT_EQ(vertex.outcome, VertexOutcome::kLeftOut);
  EXPECT_EQ(vertex.measured_gravity_n, again_n);  // what it measured is kept, and where
  EXPECT_EQ(vertex.measured_at_m, grid.vertexPosition(held));

  // The map leaves it out of the fit: its value within 0.5 % of the truth, not 30 % off.
  MapMetadata metadata;
  metadata.field_model = FieldModel::kChoose;
  metadata.lookup_refinement = 2;
  metadata.reviewed_measurements = reviewed;
  fillUnreachableVertices(grid, vertices);
  const GravityMap map(grid, vertices, metadata);
  const Eigen::Vector3d truth_n = bentField(grid.vertexPosition(held));
  EXPECT_LT((map.gravityAt(grid.vertexPosition(held)) - truth_n).norm() / truth_n.norm(), 5e-3);
  EXPECT_EQ(map.metadata().reviewed_measurements.size(), 1u);
}

TEST(MeasurementReviewTest, ASecondMeasurementThatAgreesWithTheOthersReplacesTheFirst) {
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 7);
  const int held = ceilingVertex(grid);
  const Eigen::Vector3d clear_n = vertices[static_cast<std::size_t>(held)].gravity_n;
  vertices[static_cast<std::size_t>(held)].gravity_n *= 0.8;
  std::vector<ReviewedMeasurement> reviewed = planReview(grid, vertices, kEpsG_n);
  ASSERT_EQ(reviewed.size(), 1u);
  vertices[static_cast<std::size_t>(held)].gravity_n = clear_n;  // clear of the stop this time
  concludeReview(grid, vertices, reviewed, kEpsG_n);
  EXPECT_EQ(reviewed.front().verdict, ReviewVerdict::kReplaced);
  EXPECT_LT(reviewed.front().again_residual_rel, 0.01);
  EXPECT_EQ(vertices[static_cast<std::size_t>(held)].outcome, VertexOutcome::kConverged);
  EXPECT_EQ(vertices[static_cast<std::size_t>(held)].gravity_n, clear_n);
}

TEST(MeasurementReviewTest, AMeasurementRepeatedWithin5TimesItsNeighboursScatterIsConfirmed) {
  // A steep field by a stop (sim:falcon's band: residuals of 2-3 % around the point): measured
  // again after a retreat from the stop 1 mm further in, 4 % apart, within 5 times that scatter.
  // The first measurement, nearer the stop, is what the map keeps.
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 8);
  const int steep = grid.vertexIndex(0, 2, 2);
  const Eigen::Vector3d first_m = grid.vertexPosition(steep) + Eigen::Vector3d(0.001, 0.0, 0.0);
  ReviewedMeasurement entry;
  entry.first.vertex = steep;
  entry.first.point_m = first_m;
  entry.first.value_n = bentField(first_m);
  entry.first.residual_rel = 0.19;
  entry.first.local_rel = 0.025;
  entry.again_point_m = first_m + Eigen::Vector3d(0.001, 0.0, 0.0);
  std::vector<ReviewedMeasurement> reviewed{entry};
  VertexEstimate& vertex = vertices[static_cast<std::size_t>(steep)];
  vertex.measured_at_m = entry.again_point_m;
  vertex.measured_gravity_n = 1.04 * entry.first.value_n;
  concludeReview(grid, vertices, reviewed, kEpsG_n);
  EXPECT_EQ(reviewed.front().verdict, ReviewVerdict::kConfirmed);
  EXPECT_EQ(vertex.outcome, VertexOutcome::kConverged);
  EXPECT_EQ(vertex.measured_at_m, first_m);
  EXPECT_EQ(vertex.measured_gravity_n, entry.first.value_n);
}

TEST(MeasurementReviewTest, AReviewWhoseRedoWasSkippedKeepsTheVertexAsItWas) {
  const WorkspaceGrid grid = fiveCube();
  std::vector<VertexEstimate> vertices = measured(grid, bentField, 1e-3, 9);
  const int held = ceilingVertex(grid);
  vertices[static_cast<std::size_t>(held)].gravity_n *= 0.8;
  std::vector<ReviewedMeasurement> reviewed = planReview(grid, vertices, kEpsG_n);
  ASSERT_EQ(reviewed.size(), 1u);
  const Eigen::Vector3d first_n = vertices[static_cast<std::size_t>(held)].gravity_n;
  concludeReview(grid, vertices, reviewed, kEpsG_n);
  EXPECT_EQ(reviewed.front().verdict, ReviewVerdict::kNotMeasuredAgain);
  EXPECT_EQ(vertices[static_cast<std::size_t>(held)].outcome, VertexOutcome::kConverged);
  EXPECT_EQ(vertices[static_cast<std::size_t>(held)].gravity_n, first_n);
}

TEST(MeasurementReviewTest, ConcludeRefusesVerticesThatDoNotMatchTheGrid) {
  std::vector<VertexEstimate> vertices(3);
  std::vector<ReviewedMeasurement> reviewed(1);
  EXPECT_THROW(concludeReview(fiveCube(), vertices, reviewed, kEpsG_n), Error);
}

}  // namespace
}  // namespace autograv
