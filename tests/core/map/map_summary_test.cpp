#include "autograv/map/map_summary.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "map_prior_fixture.h"

namespace autograv {
namespace {

VertexEstimate vertexWith(VertexOutcome outcome, int iterations, double seconds,
                          double gravity_z_n = 0.0) {
  VertexEstimate vertex;
  vertex.outcome = outcome;
  vertex.iterations = iterations;
  vertex.seconds = seconds;
  vertex.gravity_n = Eigen::Vector3d(0.0, 0.0, gravity_z_n);
  return vertex;
}

TEST(MapSummaryTest, FailedMeansHeldAtAReachablePointWithoutConverging) {
  for (const VertexOutcome outcome : {VertexOutcome::kIterationCap, VertexOutcome::kNoSteadyState,
                                      VertexOutcome::kSaturated, VertexOutcome::kDeviceFault}) {
    const VertexEstimate vertex = vertexWith(outcome, 60, 6.0);
    EXPECT_TRUE(isFailed(vertex)) << toString(outcome);
    EXPECT_TRUE(needsAnotherVisit(vertex)) << toString(outcome);
    EXPECT_TRUE(holdsNoValue(vertex)) << toString(outcome);
  }
  const VertexEstimate pending = vertexWith(VertexOutcome::kPending, 0, 0.0);
  EXPECT_FALSE(isFailed(pending));
  EXPECT_TRUE(needsAnotherVisit(pending));  // never visited: a redo pass goes there
  EXPECT_FALSE(holdsNoValue(pending));

  VertexEstimate unreachable = vertexWith(VertexOutcome::kUnreachable, 0, 0.0);
  EXPECT_FALSE(isFailed(unreachable));
  EXPECT_FALSE(needsAnotherVisit(unreachable));  // it would meet the same stop again
  EXPECT_TRUE(holdsNoValue(unreachable));        // nothing converged to solve it from
  unreachable.provenance = VertexProvenance::kFilled;
  EXPECT_FALSE(holdsNoValue(unreachable));

  const VertexEstimate converged = vertexWith(VertexOutcome::kConverged, 12, 1.0);
  EXPECT_FALSE(isFailed(converged));
  EXPECT_FALSE(needsAnotherVisit(converged));
  EXPECT_FALSE(holdsNoValue(converged));
}

TEST(MapSummaryTest, MedianIsTheMiddleValueOrTheMeanOfTheTwoMiddleOnes) {
  EXPECT_EQ(median({}), 0.0);
  EXPECT_EQ(median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(median({4.0, 1.0, 3.0, 2.0}), 2.5);
}

TEST(MapSummaryTest, CountsAndSpreadsOverEveryVertexAndOverTheConvergedOnes) {
  std::vector<VertexEstimate> vertices = {
      vertexWith(VertexOutcome::kConverged, 10, 1.0, -2.0),
      vertexWith(VertexOutcome::kIterationCap, 60, 6.0, -9.0),
      vertexWith(VertexOutcome::kConverged, 14, 2.0, -1.5),
      vertexWith(VertexOutcome::kPending, 0, 0.0),
      vertexWith(VertexOutcome::kUnreachable, 0, 0.0),
      vertexWith(VertexOutcome::kConverged, 20, 3.0, -2.5),
  };
  vertices[4].provenance = VertexProvenance::kFilled;
  const MapSummary summary = summarizeVertices(vertices);
  EXPECT_EQ(summary.vertices, 6);
  EXPECT_EQ(summary.converged, 3);
  EXPECT_EQ(summary.pending, 1);
  EXPECT_EQ(summary.unreachable, 1);
  EXPECT_EQ(summary.filled, 1);
  EXPECT_EQ(summary.at_vertex, 3);
  EXPECT_EQ(summary.solved, 1);
  EXPECT_EQ(summary.failed, std::vector<int>{1});
  EXPECT_EQ(summary.to_visit_again, (std::vector<int>{1, 3}));
  EXPECT_EQ(summary.iterations.min, 0);
  EXPECT_EQ(summary.iterations.median, 12.0);  // 0 0 10 14 20 60
  EXPECT_EQ(summary.iterations.max, 60);
  EXPECT_DOUBLE_EQ(summary.secondsPerVertex(), 2.0);
  const ConvergedVertexStats& converged = summary.converged_only;
  EXPECT_EQ(converged.iterations.min, 10);
  EXPECT_EQ(converged.iterations.median, 14.0);
  EXPECT_EQ(converged.iterations.max, 20);
  EXPECT_DOUBLE_EQ(converged.seconds, 6.0);
  EXPECT_DOUBLE_EQ(converged.gravity_min_n, 1.5);
  EXPECT_DOUBLE_EQ(converged.gravity_max_n, 2.5);
}

TEST(MapSummaryTest, AnEmptySetHasZeroSpreads) {
  const MapSummary summary = summarizeVertices({});
  EXPECT_EQ(summary.vertices, 0);
  EXPECT_EQ(summary.iterations.max, 0);
  EXPECT_EQ(summary.converged_only.iterations.median, 0.0);
}

TEST(MapSummaryTest, APriorSaysWhichUnitWhenAndHowMuchWasCorrected) {
  MapPrior prior = testing::affinePriorFixture();
  prior.gain(0, 1) = 0.5;  // off the diagonal: not shown
  const PriorText text = describePrior(prior);
  EXPECT_EQ(text.made_from, "map of unit SN-0017 made 2026-10-01T08:00:00Z (maps/omni-0017.json)");
  EXPECT_EQ(text.correction,
            "affine from 24 points; gain diag 1.012 / 0.987 / 1.003, offset [1.2, -30.4, 0.0] mN; "
            "checked on 4 points: mean 0.41 %, largest 0.93 %; workspace within 3.2 mm");

  // Nothing known of the prior unit, nothing left out to check with.
  prior.device_serial.clear();
  prior.created_utc.clear();
  prior.source.clear();
  prior.points_m.resize(1);
  prior.check_points = 0;
  const PriorText bare = describePrior(prior);
  EXPECT_EQ(bare.made_from, "map of unit (no serial) made at an unknown time");
  EXPECT_EQ(bare.correction.substr(0, 20), "affine from 1 point;");
  EXPECT_NE(bare.correction.find("; not checked (no point left out of the fit); workspace"),
            std::string::npos)
      << bare.correction;
}

}  // namespace
}  // namespace autograv
