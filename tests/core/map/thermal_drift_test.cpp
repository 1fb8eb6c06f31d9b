#include "autograv/map/thermal_drift.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

// A 4 x 4 x 4 grid measured in visit order while the motors warm: vertex i at load
// kLoadStep * (i + 1), reading the field divided by what the motors then deliver, 1 - k L.
constexpr double kLoadStep = 0.002;
constexpr double kEps = 0.005;  // the calibration's eps_G. Unit: [N]

Eigen::Vector3d field_n(const Eigen::Vector3d& x) {
  return Eigen::Vector3d(0.02 + 0.3 * x.y(), -0.01, -0.5 + 0.8 * x.x() - 0.4 * x.z());
}

struct WarmingCalibration {
  explicit WarmingCalibration(double gain_loss_per_load)
      : grid(Eigen::Vector3d::Zero(), 0.12, 4), k(gain_loss_per_load) {
    vertices.resize(static_cast<std::size_t>(grid.vertexCount()));
    for (int i = 0; i < grid.vertexCount(); ++i) {
      VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
      vertex.outcome = VertexOutcome::kConverged;
      vertex.thermal_load = kLoadStep * (i + 1);
      vertex.gravity_n = field_n(grid.vertexPosition(i)) / (1.0 - k * vertex.thermal_load);
    }
  }
  // The references measured again at `load`, each reading off by `noise_n` along z.
  void measureAgain(const std::vector<DriftReference>& references, double load,
                    const std::vector<double>& noise_n = {}) {
    for (std::size_t j = 0; j < references.size(); ++j) {
      VertexEstimate& vertex = vertices[static_cast<std::size_t>(references[j].vertex)];
      vertex.thermal_load = load;
      vertex.gravity_n = field_n(references[j].point_m) / (1.0 - k * load);
      if (j < noise_n.size()) vertex.gravity_n.z() += noise_n[j];
    }
  }
  double worstError_rel() const {
    double worst = 0.0;
    for (int i = 0; i < grid.vertexCount(); ++i) {
      const Eigen::Vector3d truth = field_n(grid.vertexPosition(i));
      worst = std::max(
          worst, (vertices[static_cast<std::size_t>(i)].gravity_n - truth).norm() / truth.norm());
    }
    return worst;
  }
  WorkspaceGrid grid;
  double k;
  std::vector<VertexEstimate> vertices;
};

TEST(ThermalDriftTest, TheFirstPointsAreMeasuredAgainWhereTheyWereMeasured) {
  WarmingCalibration calibration(0.3);
  const Eigen::Vector3d inside_m(-0.05, -0.05, -0.052);  // vertex 0 measured inside a stop
  calibration.vertices[0].measured_at_m = inside_m;
  calibration.vertices[0].measured_gravity_n = Eigen::Vector3d(0.0, 0.0, -0.45);
  calibration.vertices[1].outcome = VertexOutcome::kUnreachable;
  const std::vector<DriftReference> references =
      planThermalDriftCheck(calibration.grid, calibration.vertices, {2});
  ASSERT_EQ(references.size(), static_cast<std::size_t>(kThermalDriftPoints));
  EXPECT_EQ(references[0].vertex, 0);
  EXPECT_EQ(references[0].point_m, inside_m);
  EXPECT_EQ(references[0].first_value_n, Eigen::Vector3d(0.0, 0.0, -0.45));
  EXPECT_EQ(references[1].vertex, 3) << "1 unreachable, 2 measured again anyway";
  EXPECT_EQ(references[2].vertex, 4);
  EXPECT_EQ(references[1].point_m, calibration.grid.vertexPosition(3));
  EXPECT_EQ(references[1].first_value_n, calibration.vertices[3].gravity_n);
  EXPECT_DOUBLE_EQ(references[1].first_load, 4 * kLoadStep);
}

TEST(ThermalDriftTest, PointsMeasuredAboveHalfTheLastLoadAreNotReferences) {
  WarmingCalibration calibration(0.3);
  std::vector<int> exclude;
  for (int i = 0; i < 40; ++i) exclude.push_back(i);  // the first 40 measured again anyway
  const std::vector<DriftReference> references =
      planThermalDriftCheck(calibration.grid, calibration.vertices, exclude);
  ASSERT_EQ(references.size(), 0u) << "vertex 40 was measured at 0.082 of a highest 0.128";
}

TEST(ThermalDriftTest, VerticesRestoredFromAnEarlierRunAreNeitherReferencesNorCorrected) {
  WarmingCalibration calibration(0.3);
  for (int i = 0; i < 10; ++i) calibration.vertices[static_cast<std::size_t>(i)].thermal_load = 0.0;
  const std::vector<DriftReference> references =
      planThermalDriftCheck(calibration.grid, calibration.vertices);
  ASSERT_EQ(references.size(), 3u);
  EXPECT_EQ(references[0].vertex, 10);
  const Eigen::Vector3d restored_n = calibration.vertices[4].gravity_n;
  calibration.measureAgain(references, 0.14);
  const ThermalDrift drift =
      concludeThermalDrift(calibration.grid, calibration.vertices, references, kEps);
  EXPECT_NEAR(drift.gain_loss_per_load, 0.3, 1e-9);
  EXPECT_EQ(calibration.vertices[4].gravity_n, restored_n) << "kept bit for bit";
}

TEST(ThermalDriftTest, MotorsThatNeverWarmedAreNotLookedAt) {
  WarmingCalibration calibration(0.3);
  for (VertexEstimate& vertex : calibration.vertices) vertex.thermal_load *= 0.1;  // < 0.013
  EXPECT_TRUE(planThermalDriftCheck(calibration.grid, calibration.vertices).empty());
}

TEST(ThermalDriftTest, AnExactDriftIsFittedAndTakenOutOfEveryMeasurement) {
  WarmingCalibration calibration(0.3);
  const std::vector<DriftReference> references =
      planThermalDriftCheck(calibration.grid, calibration.vertices);
  ASSERT_EQ(references.size(), 3u);
  calibration.measureAgain(references, 0.14);
  EXPECT_GT(calibration.worstError_rel(), 0.035) << "the last points read 4 % more command";
  const ThermalDrift drift =
      concludeThermalDrift(calibration.grid, calibration.vertices, references, kEps);
  EXPECT_NEAR(drift.gain_loss_per_load, 0.3, 1e-9);
  EXPECT_EQ(drift.points, 3);
  EXPECT_NEAR(drift.first_load, 2 * kLoadStep, 1e-12);
  EXPECT_NEAR(drift.again_load, 0.14, 1e-12);
  EXPECT_NEAR(drift.drift_rel, (1.0 - 0.3 * 2 * kLoadStep) / (1.0 - 0.042) - 1.0, 1e-4);
  EXPECT_LT(calibration.worstError_rel(), 1e-12) << "every value that of cold motors";
}

TEST(ThermalDriftTest, MeasurementsWithinTheirRepeatabilityGiveTheDriftWithinTwoStandardErrors) {
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, kEps / 2.0);
  for (int run = 0; run < 20; ++run) {
    WarmingCalibration calibration(0.3);
    const std::vector<DriftReference> references =
        planThermalDriftCheck(calibration.grid, calibration.vertices);
    calibration.measureAgain(references, 0.3, {noise(random), noise(random), noise(random)});
    const ThermalDrift drift =
        concludeThermalDrift(calibration.grid, calibration.vertices, references, kEps);
    EXPECT_GT(drift.gain_loss_standard_error, 0.0);
    EXPECT_NEAR(drift.gain_loss_per_load, 0.3, 2.0 * drift.gain_loss_standard_error)
        << "run " << run;
  }
}

TEST(ThermalDriftTest, MeasurementsThatReadLessCommandAgainCorrectNothing) {
  WarmingCalibration calibration(-0.2);  // a torque that would rise as it warms: scatter
  const std::vector<DriftReference> references =
      planThermalDriftCheck(calibration.grid, calibration.vertices);
  calibration.measureAgain(references, 0.14);
  const std::vector<VertexEstimate> before = calibration.vertices;
  const ThermalDrift drift =
      concludeThermalDrift(calibration.grid, calibration.vertices, references, kEps);
  EXPECT_EQ(drift.gain_loss_per_load, 0.0);
  EXPECT_LT(drift.drift_rel, 0.0);
  for (std::size_t i = 0; i < before.size(); ++i) {
    EXPECT_EQ(calibration.vertices[i].gravity_n, before[i].gravity_n);
  }
}

TEST(ThermalDriftTest, AReferenceWhoseSecondHoldFailedIsSkippedAndNoneLeavesTheMapAsItWas) {
  WarmingCalibration calibration(0.3);
  const std::vector<DriftReference> references =
      planThermalDriftCheck(calibration.grid, calibration.vertices);
  calibration.measureAgain(references, 0.14);
  calibration.vertices[static_cast<std::size_t>(references[0].vertex)].outcome =
      VertexOutcome::kIterationCap;
  ThermalDrift drift =
      concludeThermalDrift(calibration.grid, calibration.vertices, references, kEps);
  EXPECT_EQ(drift.points, 2);
  EXPECT_NEAR(drift.gain_loss_per_load, 0.3, 1e-9);

  WarmingCalibration untouched(0.3);
  const std::vector<VertexEstimate> before = untouched.vertices;
  drift = concludeThermalDrift(untouched.grid, untouched.vertices, {}, kEps);
  EXPECT_EQ(drift.points, 0);
  EXPECT_EQ(drift.gain_loss_per_load, 0.0);
  EXPECT_EQ(untouched.vertices[10].gravity_n, before[10].gravity_n);
  EXPECT_THROW(concludeThermalDrift(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 3),
                                    untouched.vertices, {}, kEps),
               Error);
}

TEST(ThermalDriftTest, TheScaleGivesBackTheLostTorqueAndNeverMoreThanDoubles) {
  ThermalDrift drift;
  EXPECT_EQ(thermalScale(drift, 0.5), 1.0) << "no drift seen: no correction";
  drift.gain_loss_per_load = 0.3;
  EXPECT_EQ(thermalScale(drift, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(thermalScale(drift, 0.1), 1.0 / 0.97);
  EXPECT_DOUBLE_EQ(thermalScale(drift, 5.0), 1.0 / kMinThermalGain);
  EXPECT_EQ(thermalScale(drift, -1.0), 1.0);
}

}  // namespace
}  // namespace autograv
