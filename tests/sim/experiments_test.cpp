#include "sim/experiments.h"

#include <vector>

#include <gtest/gtest.h>

namespace autograv::sim {
namespace {

SweepRow seedRow(int seed, int converged, double iterations_median, double max_error_rel,
                 double residual_median_n) {
  SweepRow row;
  row.device = "sim:omni";
  row.seed = seed;
  row.calibration.vertices = 27;
  row.calibration.converged = converged;
  row.calibration.iterations_median = iterations_median;
  row.calibration.iterations_max = static_cast<int>(2 * iterations_median);
  row.calibration.seconds_per_vertex = seed;
  row.calibration.accuracy.max_error_rel = max_error_rel;
  row.calibration.accuracy.max_error_n = 10.0 * max_error_rel;
  row.calibration.accuracy.rms_residual_n = 0.1 * seed;
  row.residual_n.median = residual_median_n;
  row.residual_n.max = 2.0 * residual_median_n;
  return row;
}

TEST(FoldSeedsTest, SumsConvergenceAndTakesMediansOfMediansAndTheWorstOfWorsts) {
  const SweepRow a = seedRow(1, 27, 10.0, 0.01, 0.004);
  const SweepRow b = seedRow(2, 26, 14.0, 0.03, 0.002);
  const SweepRow c = seedRow(3, 27, 12.0, 0.02, 0.003);
  const SweepRow folded = foldSeeds({&a, &b, &c});
  EXPECT_TRUE(folded.failure.empty());
  EXPECT_EQ(folded.calibration.vertices, 81);
  EXPECT_EQ(folded.calibration.converged, 80);
  EXPECT_EQ(folded.calibration.iterations_median, 12.0);
  EXPECT_EQ(folded.calibration.iterations_max, 28);
  EXPECT_DOUBLE_EQ(folded.calibration.seconds_per_vertex, 2.0);
  EXPECT_EQ(folded.calibration.accuracy.max_error_rel, 0.03);
  EXPECT_DOUBLE_EQ(folded.calibration.accuracy.max_error_n, 0.3);
  EXPECT_DOUBLE_EQ(folded.calibration.accuracy.rms_residual_n, 0.2);
  EXPECT_EQ(folded.residual_n.median, 0.003);
  EXPECT_DOUBLE_EQ(folded.residual_n.max, 0.008);
}

TEST(FoldSeedsTest, AFailedSeedNamesItselfOnlyWhenNoSeedRan) {
  SweepRow failed = seedRow(2, 0, 0.0, 0.0, 0.0);
  failed.failure = "calibration refused";
  const SweepRow ran = seedRow(1, 27, 10.0, 0.01, 0.004);
  EXPECT_EQ(foldSeeds({&failed}).failure, "seed 2: calibration refused");
  const SweepRow some = foldSeeds({&ran, &failed});
  EXPECT_EQ(some.failure, "seed 2: calibration refused");  // kept: not every seed ran
  EXPECT_EQ(some.calibration.converged, 27);
}

TEST(FoldSweepSeedsTest, FoldsConsecutiveRowsOfOneDeviceLevelAndMethod) {
  std::vector<SweepRow> rows = {seedRow(1, 27, 10.0, 0.01, 0.004),
                                seedRow(2, 27, 12.0, 0.01, 0.004),
                                seedRow(1, 27, 11.0, 0.01, 0.004)};
  rows[2].friction = FrictionLevel::kHigh;
  const std::vector<SweepRow> folded = foldSweepSeeds(rows);
  ASSERT_EQ(folded.size(), 2u);
  EXPECT_EQ(folded[0].calibration.iterations_median, 11.0);
  EXPECT_EQ(folded[1].friction, FrictionLevel::kHigh);
}

}  // namespace
}  // namespace autograv::sim
