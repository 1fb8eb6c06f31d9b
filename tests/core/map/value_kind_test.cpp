#include "autograv/map/value_kind.h"

#include <string>

#include <gtest/gtest.h>

namespace autograv {
namespace {

TEST(ValueKindTest, NamesWhereEachValueComesFrom) {
  VertexEstimate pending;
  EXPECT_EQ(valueKind(pending), ValueKind::kNone);

  VertexEstimate at_vertex;
  at_vertex.outcome = VertexOutcome::kConverged;
  EXPECT_EQ(valueKind(at_vertex), ValueKind::kAtVertex);

  VertexEstimate failed;
  failed.outcome = VertexOutcome::kIterationCap;
  EXPECT_EQ(valueKind(failed), ValueKind::kNone);

  // Beyond the stops, measured just inside them: its value is solved, from its own measurement
  // among the others (fillUnreachableVertices marks it filled).
  VertexEstimate off_vertex;
  off_vertex.outcome = VertexOutcome::kConverged;
  off_vertex.provenance = VertexProvenance::kFilled;
  off_vertex.measured_at_m = Eigen::Vector3d(0.01, 0.0, 0.0);
  EXPECT_EQ(valueKind(off_vertex), ValueKind::kOffVertex);

  // Its point inside the stops could not be held either: no measurement, solved like the rest.
  VertexEstimate unheld = off_vertex;
  unheld.outcome = VertexOutcome::kUnreachable;
  EXPECT_EQ(valueKind(unheld), ValueKind::kSolved);
  unheld.provenance = VertexProvenance::kMeasured;  // before the solve: nothing to show yet
  EXPECT_EQ(valueKind(unheld), ValueKind::kNone);

  VertexEstimate solved;
  solved.outcome = VertexOutcome::kUnreachable;
  solved.provenance = VertexProvenance::kFilled;
  EXPECT_EQ(valueKind(solved), ValueKind::kSolved);

  // A map of schema 1 or 2: filled vertices had no measurement point; they read as solved.
  VertexEstimate old_filled;
  old_filled.outcome = VertexOutcome::kUnreachable;
  old_filled.provenance = VertexProvenance::kFilled;
  EXPECT_EQ(valueKind(old_filled), ValueKind::kSolved);
}

TEST(ValueKindTest, NamesAreTheOnesTheToolsPrint) {
  EXPECT_EQ(std::string(toString(ValueKind::kNone)), "none");
  EXPECT_EQ(std::string(toString(ValueKind::kAtVertex)), "at vertex");
  EXPECT_EQ(std::string(toString(ValueKind::kOffVertex)), "off vertex");
  EXPECT_EQ(std::string(toString(ValueKind::kSolved)), "solved");
}

}  // namespace
}  // namespace autograv
