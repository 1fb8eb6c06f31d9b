// A unit's map corrected from another unit's (transferMap, `calibrate --like`), against the
// simulation's truth: sim:omega units 2 and 3 from unit 1's default calibration. Each
// UnitTransferTest calibrates that prior first (14 s under the sanitizers): all but the first
// are release-only (tests/CMakeLists.txt); UnitTransferPriorTest needs no calibration, and
// UnitTransferCheckTest's prior is unit 1's true field sampled where a calibration measures it
// (no calibration either): each of its tests is one transfer, a refusal path or the check's
// second measurement on its own.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/maintenance/unit_transfer.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/simulated_device.h"
#include "field_map.h"
#include "scaled_map.h"
#include "sim/experiments.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;

sim::SimulatedUnit unit(int number) {
  sim::SimulatedUnit simulated;
  simulated.number = number;
  return simulated;
}

class UnitTransferTest : public ::testing::Test {
 protected:
  // One default calibration of unit 1 (seed 1), the prior of every test; its own field error.
  static void SetUpTestSuite() {
    auto device = sim::makeSimulatedDevice("sim:omega", 1, sim::FrictionLevel::kTypical, unit(1));
    ASSERT_TRUE(device->open());
    const sim::CalibrationRunOptions options = sim::defaultCalibrationOptions(*device);
    const sim::CalibrationRunResult run = sim::runSimulatedCalibration(*device, options);
    MapMetadata metadata;
    metadata.device_model = device->specifications().model_name;
    metadata.device_serial = device->specifications().serial_number;
    metadata.created_utc = "2026-12-06T06:00:00Z";
    metadata.parameters = options.parameters;
    metadata.workspace = run.workspace;
    metadata.lookup_refinement = lookupRefinementFor(run.grid, kDefaultLookupRefinement);
    metadata.field_model = kDefaultFieldModel;
    prior_ = std::make_unique<GravityMap>(run.grid, run.vertices, metadata);
  }
  static void TearDownTestSuite() { prior_.reset(); }

  // Unit `number` (seed 2: other noise than the prior's run), open, its stylus released at the
  // prior's workspace centre with the prior's force, as a user leaves it.
  static std::unique_ptr<sim::SimulatedDevice> unitAtCentre(int number) {
    auto device =
        sim::makeSimulatedDevice("sim:omega", 2, sim::FrictionLevel::kTypical, unit(number));
    EXPECT_TRUE(device->open());
    const Eigen::Vector3d centre_m = prior_->metadata().workspace.center_m();
    device->setForce(prior_->gravityAt(centre_m));
    device->advance(1e-3);
    device->resetState(centre_m);
    return device;
  }

  static TransferResult transfer(sim::SimulatedDevice& device, const GravityMap& prior) {
    sim::SimulatedTickSource ticks(device, 1e-3, sim::SimulatedTickSource::Mode::kAsFastAsPossible);
    TransferOptions options;
    options.parameters = sim::toolParameters(device);
    options.prior_source = "unit1.json";
    return transferMap(device, ticks, prior, options);
  }

  static std::unique_ptr<GravityMap> prior_;
};

std::unique_ptr<GravityMap> UnitTransferTest::prior_;

TEST_F(UnitTransferTest, AnotherUnitsMapIsCorrectedToThisUnitInUnderFortyFiveSeconds) {
  auto device = unitAtCentre(2);
  const sim::FieldErrorReport before = sim::measureFieldError(*prior_, *device, 20000, 1);
  const TransferResult result = transfer(*device, *prior_);
  ASSERT_TRUE(result.accepted) << result.refusal;
  ASSERT_TRUE(result.map.has_value());
  const sim::FieldErrorReport after = sim::measureFieldError(*result.map, *device, 20000, 1);
  // Unit 2's motors deliver 3 % less than unit 1's on one axis: the prior is 3 % off everywhere.
  EXPECT_GT(before.p50_rel, 0.02);
  // The prior's own error on unit 1 is 0.14 % (p90) and 0.23 % (p99); a whole calibration of
  // unit 2 reads the same.
  EXPECT_LT(after.p90_rel, 0.004);
  EXPECT_LT(after.p99_rel, 0.005);
  EXPECT_LE(result.seconds, 45.0);
  EXPECT_EQ(result.failed_points, 0);
  EXPECT_GE(result.prior.check_points, 2);
  EXPECT_LT(result.prior.check_max_rel, 0.005);
  EXPECT_LT(result.prior.workspace_difference_m, 0.002);
  EXPECT_EQ(device->saturationCount(), 0u);
  EXPECT_LT(result.seconds_above_continuous_force, 0.05 * result.seconds);
  // The map says where it came from and how it was corrected, and a saved copy keeps it.
  const MapMetadata& metadata = result.map->metadata();
  ASSERT_TRUE(metadata.prior.has_value());
  EXPECT_EQ(metadata.prior->source, "unit1.json");
  EXPECT_EQ(metadata.prior->device_serial, "SIM-OMEGA-0001");
  EXPECT_EQ(metadata.device_serial, "SIM-OMEGA-0002");
  EXPECT_EQ(metadata.prior->correction_model, "affine");
  const fs::path path = fs::path(::testing::TempDir()) / "unit_transfer_test_map.json";
  saveMap(*result.map, path.string());
  const GravityMap loaded = loadMap(path.string());
  ASSERT_TRUE(loaded.metadata().prior.has_value());
  EXPECT_EQ(loaded.metadata().prior->correction_model, "affine");
  EXPECT_EQ(loaded.metadata().prior->gain, metadata.prior->gain);
  fs::remove(path);
}

TEST_F(UnitTransferTest, TheChosenCorrectionIsTheOneThatPredictsLeftOutPointsBest) {
  auto device = unitAtCentre(3);
  const TransferResult result = transfer(*device, *prior_);
  ASSERT_TRUE(result.accepted) << result.refusal;
  ASSERT_GE(result.scores.size(), 3u);
  const CorrectionScore* chosen = nullptr;
  for (const CorrectionScore& score : result.scores) {
    if (toString(score.model) == result.prior.correction_model) chosen = &score;
  }
  ASSERT_NE(chosen, nullptr);
  for (const CorrectionScore& score : result.scores) {
    // Kept unless another beats it by the margin (5 %).
    EXPECT_GE(score.mean_rel, 0.95 * chosen->mean_rel - 1e-12) << toString(score.model);
  }
  // A plain shift cannot follow motors of different gains: it scores worse than the choice.
  EXPECT_EQ(result.scores.front().model, CorrectionModel::kShift);
  EXPECT_GT(result.scores.front().mean_rel, 2.0 * chosen->mean_rel);
}

TEST_F(UnitTransferTest, APriorTheCorrectionCannotExplainIsRefusedOnItsFitAndNoMapIsMade) {
  // The prior with every value off by its own random 8 %: no smooth correction explains it (a
  // bent link, a map of another device relabelled).
  const GravityMap scrambled = testing::scrambledMap(*prior_, 0.08, 5);
  auto device = unitAtCentre(2);
  const TransferResult result = transfer(*device, scrambled);
  EXPECT_FALSE(result.accepted);
  EXPECT_FALSE(result.map.has_value());
  // Refused on the fit's own leave-one-out error, before any check point is measured again.
  EXPECT_NE(result.refusal.find("measurements from the others only within"), std::string::npos)
      << result.refusal;
  EXPECT_NE(result.refusal.find("whole calibration"), std::string::npos) << result.refusal;
  EXPECT_GT(result.prior.check_max_rel, TransferOptions().max_check_error_rel);
  EXPECT_EQ(result.remeasured_points, 0);
}

TEST_F(UnitTransferTest, AUnitWhoseStopsLieElsewhereIsRefused) {
  // The prior's workspace grown by 15 mm in every direction: this unit meets its stops short.
  const ExploredWorkspace& explored = prior_->metadata().workspace;
  std::vector<double> radii_m = explored.radii_m();
  for (double& radius_m : radii_m) radius_m += 0.015;
  MapMetadata metadata = prior_->metadata();
  metadata.workspace = ExploredWorkspace(explored.center_m(), explored.directions(), radii_m);
  const GravityMap wider(prior_->grid(), prior_->vertices(), metadata);
  auto device = unitAtCentre(2);
  const TransferResult result = transfer(*device, wider);
  EXPECT_FALSE(result.accepted);
  EXPECT_NE(result.refusal.find("stops"), std::string::npos) << result.refusal;
  EXPECT_NEAR(result.prior.workspace_difference_m, 0.015, 0.003);
  EXPECT_EQ(result.converged_points, 0);  // refused before any point was measured
}

TEST(UnitTransferStandOutTest, ACheckPointStandsOutAgainstTheOthersMedianNotAFixedLine) {
  const TransferOptions options;
  // sim:falcon unit 2 seed 2 from unit 1 seed 1 before the second measurement: one point at
  // 3.13 %, the others about 1 % (a mean of 1.29 %).
  const std::vector<double> one_off = {0.0101, 0.0087, 0.0122, 0.0313, 0.0095, 0.0110};
  EXPECT_EQ(standingOut(one_off, options.stand_out_mads, options.stand_out_min_rel),
            std::vector<bool>({false, false, false, true, false, false}));
  // Every point about 3 % off (a unit the correction does not explain): none stands out.
  const std::vector<double> all_off = {0.031, 0.034, 0.029, 0.036, 0.032};
  EXPECT_EQ(standingOut(all_off, options.stand_out_mads, options.stand_out_min_rel),
            std::vector<bool>(all_off.size(), false));
  // Far off alike, one 0.6 points above the others' median: not twice what they show.
  const std::vector<double> far_off = {0.0923, 0.0862, 0.0931, 0.0868};
  EXPECT_EQ(standingOut(far_off, options.stand_out_mads, options.stand_out_min_rel),
            std::vector<bool>(far_off.size(), false));
}

TEST(UnitTransferStandOutTest, NoPointStandsOutWithinTheMeasurementsOwnScatter) {
  const TransferOptions options;
  // The others all alike (no spread): 0.4 % above them is still the measurements' scatter.
  const std::vector<double> alike = {0.002, 0.002, 0.002, 0.006};
  EXPECT_EQ(standingOut(alike, options.stand_out_mads, options.stand_out_min_rel),
            std::vector<bool>(alike.size(), false));
  EXPECT_EQ(
      standingOut({0.002, 0.002, 0.002, 0.008}, options.stand_out_mads, options.stand_out_min_rel),
      std::vector<bool>({false, false, false, true}));
}

TEST(UnitTransferStandOutTest, WithFewerThanThreeCheckPointsEachOneStandsOut) {
  EXPECT_EQ(standingOut({0.01, 0.04}, 3.0, 0.005), std::vector<bool>({true, true}));
  EXPECT_EQ(standingOut({0.04}, 3.0, 0.005), std::vector<bool>({true}));
  EXPECT_TRUE(standingOut({}, 3.0, 0.005).empty());
}

// sim:omega unit 1's true field (seed 1), sampled where a default calibration measures: at the
// vertices of the grid around a workspace explored to its 55 mm stops, and just inside the
// stops for the cells they cut. A prior as good as a calibration can make, made in no time.
class UnitTransferCheckTest : public ::testing::Test {
 protected:
  static GravityMap truthPrior() {
    auto unit1 = sim::makeSimulatedDevice("sim:omega", 1, sim::FrictionLevel::kTypical, unit(1));
    const std::vector<Eigen::Vector3d> directions = ExploredWorkspace::probeDirections(26);
    const ExploredWorkspace workspace(unit1->workspaceCenter_m(), directions,
                                      std::vector<double>(directions.size(), 0.055));
    const WorkspaceGrid grid = gridAroundWorkspace(workspace, Eigen::Vector3i::Constant(4));
    const MeasurementPlan plan = planMeasurements(grid, workspace);
    std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
    for (int i = 0; i < grid.vertexCount(); ++i) {
      VertexEstimate& vertex = vertices[static_cast<std::size_t>(i)];
      const Eigen::Vector3d vertex_m = grid.vertexPosition(i);
      vertex.gravity_n = unit1->trueGravity(vertex_m);
      const auto index = static_cast<std::size_t>(i);
      if (!plan.measure[index]) {
        vertex.outcome = VertexOutcome::kUnreachable;
        continue;
      }
      vertex.outcome = VertexOutcome::kConverged;
      if (plan.offVertex(grid, i)) {
        vertex.measured_at_m = plan.points_m[index];
        vertex.measured_gravity_n = unit1->trueGravity(plan.points_m[index]);
      }
    }
    MapMetadata metadata;
    metadata.device_model = unit1->specifications().model_name;
    metadata.device_serial = unit1->specifications().serial_number;
    metadata.parameters = sim::toolParameters(*unit1);
    metadata.workspace = workspace;
    metadata.lookup_refinement = lookupRefinementFor(grid, kDefaultLookupRefinement);
    metadata.field_model = kDefaultFieldModel;
    return GravityMap(grid, std::move(vertices), std::move(metadata));
  }

  // The grid vertex of the `n`-th check point, and where it is measured: the spread's
  // (check_every * n + check_every - 1)-th point.
  static int checkVertex(const GravityMap& prior, int n) {
    const TransferOptions options;
    const std::vector<int> spread = spreadMeasuredVertices(prior, options.max_points);
    return spread[static_cast<std::size_t>(options.check_every * n + options.check_every - 1)];
  }
  static Eigen::Vector3d measuredAt_m(const GravityMap& prior, int vertex) {
    return prior.vertices()[static_cast<std::size_t>(vertex)].measuredAt_m(
        prior.grid().vertexPosition(vertex));
  }

  static std::unique_ptr<sim::SimulatedDevice> unitAtCentre(const GravityMap& prior, int number) {
    auto device =
        sim::makeSimulatedDevice("sim:omega", 2, sim::FrictionLevel::kTypical, unit(number));
    EXPECT_TRUE(device->open());
    const Eigen::Vector3d centre_m = prior.metadata().workspace.center_m();
    device->setForce(prior.gravityAt(centre_m));
    device->advance(1e-3);
    device->resetState(centre_m);
    return device;
  }

  static TransferResult transfer(HapticDevice& device, sim::SimulatedDevice& simulated,
                                 const GravityMap& prior,
                                 int check_every = TransferOptions().check_every) {
    sim::SimulatedTickSource ticks(simulated, 1e-3,
                                   sim::SimulatedTickSource::Mode::kAsFastAsPossible);
    TransferOptions options;
    options.parameters = sim::toolParameters(simulated);
    options.check_every = check_every;
    return transferMap(device, ticks, prior, options);
  }
};

// A hand that leans on the stylus, sideways with `push_n`, while it is within 3 mm of `point_m`
// on its first visit there, and lets go once it has left by 10 mm: one hold measured wrong.
class LeaningHand final : public HapticDevice {
 public:
  LeaningHand(HapticDevice& inner, const Eigen::Vector3d& point_m, const Eigen::Vector3d& push_n)
      : inner_(inner), point_m_(point_m), push_n_(push_n) {}
  bool open() override { return inner_.open(); }
  bool close() override { return inner_.close(); }
  bool calibrate(bool force) override { return inner_.calibrate(force); }
  bool getPosition(Eigen::Vector3d& position_m) override {
    const bool ok = inner_.getPosition(position_m);
    const double distance_m = (position_m - point_m_).norm();
    if (ok && distance_m < 0.003) {
      near_ = true;
    } else if (ok && near_ && distance_m > 0.010) {
      near_ = false;
      done_ = true;
    }
    return ok;
  }
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override {
    return inner_.getLinearVelocity(velocity_m_per_s);
  }
  bool getUserSwitch(int index, bool& pressed) override {
    return inner_.getUserSwitch(index, pressed);
  }
  bool setForce(const Eigen::Vector3d& force_n) override {
    return inner_.setForce(near_ && !done_ ? Eigen::Vector3d(force_n + push_n_) : force_n);
  }
  const DeviceSpecifications& specifications() const override { return inner_.specifications(); }
  bool leaned() const noexcept { return done_; }

 private:
  HapticDevice& inner_;
  Eigen::Vector3d point_m_;
  Eigen::Vector3d push_n_;
  bool near_ = false;
  bool done_ = false;
};

TEST_F(UnitTransferCheckTest, ACheckPointThatStandsOutOnceIsMeasuredAgainAndTheUnitIsAccepted) {
  const GravityMap prior = truthPrior();
  const int vertex = checkVertex(prior, 1);
  auto device = unitAtCentre(prior, 2);
  // 8 % of |G| sideways during the first hold there: that check point alone past the 3 % line.
  const Eigen::Vector3d point_m = measuredAt_m(prior, vertex);
  const Eigen::Vector3d push_n(0.08 * device->trueGravity(point_m).norm(), 0.0, 0.0);
  LeaningHand hand(*device, point_m, push_n);
  const TransferResult result = transfer(hand, *device, prior);
  EXPECT_TRUE(hand.leaned());
  ASSERT_TRUE(result.accepted) << result.refusal;
  EXPECT_EQ(result.remeasured_points, 1);
  EXPECT_GT(result.first_check_max_rel, TransferOptions().max_check_error_rel);
  // Measured again, the point agrees with the others (sim:omega unit 2 meets its check points
  // within 0.5 %).
  EXPECT_LT(result.prior.check_max_rel, 0.01);
  EXPECT_GT(result.remeasure_seconds, 0.0);
  EXPECT_LT(result.remeasure_seconds, 10.0);
  const sim::FieldErrorReport after = sim::measureFieldError(*result.map, *device, 20000, 1);
  EXPECT_LT(after.p90_rel, 0.005);
}

TEST_F(UnitTransferCheckTest, ACheckPointStillOffWhenMeasuredAgainRefusesTheUnit) {
  GravityMap truth = truthPrior();
  // The prior 20 % off at one check point's vertex alone (a measurement the prior's own run got
  // wrong): no fit point sees it, so the correction explains the fit points, and the check
  // point stays off wherever it is measured.
  const int vertex = checkVertex(truth, 1);
  std::vector<VertexEstimate> vertices = truth.vertices();
  VertexEstimate& off = vertices[static_cast<std::size_t>(vertex)];
  off.gravity_n *= 1.2;
  if (off.measuredOffVertex()) off.measured_gravity_n *= 1.2;
  const GravityMap prior(truth.grid(), std::move(vertices), truth.metadata());
  auto device = unitAtCentre(prior, 2);
  const TransferResult result = transfer(*device, *device, prior);
  EXPECT_FALSE(result.accepted);
  EXPECT_FALSE(result.map.has_value());
  EXPECT_NE(result.refusal.find("misses its"), std::string::npos) << result.refusal;
  EXPECT_NE(result.refusal.find("check points by up to"), std::string::npos) << result.refusal;
  EXPECT_NE(result.refusal.find("again"), std::string::npos) << result.refusal;
  EXPECT_EQ(result.refusal.find("measurements from the others only within"), std::string::npos)
      << result.refusal;
  EXPECT_EQ(result.remeasured_points, 1);
  EXPECT_GT(result.prior.check_max_rel, TransferOptions().max_check_error_rel);
  // Only that point is off: the fit explains its points as for a sound prior.
  ASSERT_FALSE(result.scores.empty());
  EXPECT_LT(std::min_element(result.scores.begin(), result.scores.end(),
                             [](const CorrectionScore& a, const CorrectionScore& b) {
                               return a.mean_rel < b.mean_rel;
                             })
                ->mean_rel,
            0.01);
}

TEST_F(UnitTransferCheckTest, ACheckThatIsOffEverywhereRefusesWithoutMeasuringAgain) {
  // The prior 10 % too large at every check point's vertex alike: the fit explains its points,
  // every check point is off, and none stands out from the others, so none is measured again.
  // Every third point checks, so that the first 12 points hold 4 check points to compare (the
  // default's 2 are too few to judge one against the others: each is measured again).
  const int check_every = 3;
  GravityMap truth = truthPrior();
  std::vector<VertexEstimate> vertices = truth.vertices();
  const std::vector<int> spread = spreadMeasuredVertices(truth, TransferOptions().max_points);
  for (auto k = static_cast<std::size_t>(check_every - 1); k < spread.size();
       k += static_cast<std::size_t>(check_every)) {
    VertexEstimate& off = vertices[static_cast<std::size_t>(spread[k])];
    off.gravity_n *= 1.1;
    if (off.measuredOffVertex()) off.measured_gravity_n *= 1.1;
  }
  const GravityMap prior(truth.grid(), std::move(vertices), truth.metadata());
  auto device = unitAtCentre(prior, 2);
  const TransferResult result = transfer(*device, *device, prior, check_every);
  EXPECT_FALSE(result.accepted);
  EXPECT_NE(result.refusal.find("check points by up to"), std::string::npos) << result.refusal;
  EXPECT_EQ(result.refusal.find("again"), std::string::npos) << result.refusal;
  EXPECT_EQ(result.remeasured_points, 0) << ::testing::PrintToString(result.check_errors_rel);
  EXPECT_GE(result.prior.check_points, 3);
}

// An Omega's map (any field: the model is refused first) on a Falcon.
TEST(UnitTransferPriorTest, AMapOfAnotherModelIsRefusedBeforeTheDeviceMoves) {
  const auto omega_map = testing::uniformFieldMap(WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 3),
                                                  Eigen::Vector3d(0.0, 0.0, 1.0), "sim:omega");
  auto falcon = sim::makeSimulatedDevice("sim:falcon", 1);
  ASSERT_TRUE(falcon->open());
  const Eigen::Vector3d before_m = falcon->truePosition_m();
  sim::SimulatedTickSource ticks(*falcon, 1e-3, sim::SimulatedTickSource::Mode::kAsFastAsPossible);
  TransferOptions options;
  options.parameters = sim::toolParameters(*falcon);
  try {
    transferMap(*falcon, ticks, *omega_map, options);
    FAIL() << "an Omega's map was taken as a Falcon's prior";
  } catch (const Error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("another model"), std::string::npos) << message;
    EXPECT_NE(message.find("whole calibration"), std::string::npos) << message;
  }
  EXPECT_EQ(falcon->time_s(), 0.0);
  EXPECT_EQ(falcon->truePosition_m(), before_m);
}

TEST(UnitTransferPriorTest, AShiftCorrectionMovesEveryValueByTheShift) {
  const auto prior = testing::fieldMap(
      WorkspaceGrid(Eigen::Vector3d::Zero(), 0.1, 4),
      [](const Eigen::Vector3d& x) {
        return Eigen::Vector3d(0.1 * x.y(), 0.1 * x.x(), 1.0 + x.z());
      },
      MapMetadata{});
  MapPrior correction;
  correction.correction_model = "shift";
  correction.offset_n = Eigen::Vector3d(0.001, -0.002, 0.05);
  const GravityMap corrected = correctedMap(*prior, correction, prior->metadata());
  for (std::size_t i = 0; i < prior->vertices().size(); ++i) {
    EXPECT_TRUE(corrected.vertices()[i].gravity_n.isApprox(
        prior->vertices()[i].gravity_n + correction.offset_n, 1e-12));
  }
  const Eigen::Vector3d centre_m = prior->grid().center_m();
  EXPECT_TRUE(corrected.gravityAt(centre_m).isApprox(
      prior->gravityAt(centre_m) + correction.offset_n, 1e-6));
  ASSERT_TRUE(corrected.metadata().prior.has_value());
}

TEST(MapLibraryOtherUnitTest, FindsAnotherUnitsWholeCalibrationAndSkipsItsOwnAndCorrectedMaps) {
  const fs::path dir = fs::path(::testing::TempDir()) / "map_library_other_unit";
  fs::remove_all(dir);
  const MapLibrary library(dir.string());
  EXPECT_EQ(library.findOtherUnit("sim:omega", "SIM-OMEGA-0002"), "");
  const auto mapOf = [](const std::string& serial, bool corrected) {
    const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.1, 2);
    std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
    for (VertexEstimate& vertex : vertices) {
      vertex.gravity_n = Eigen::Vector3d(0.0, 0.0, 1.0);
      vertex.outcome = VertexOutcome::kConverged;
    }
    MapMetadata metadata;
    metadata.device_model = "sim:omega";
    metadata.device_serial = serial;
    if (corrected) {
      metadata.prior = MapPrior{};
      metadata.prior->correction_model = "shift";
    }
    return GravityMap(grid, vertices, metadata);
  };
  const std::string own = library.save(mapOf("SIM-OMEGA-0002", false));
  EXPECT_EQ(library.findOtherUnit("sim:omega", "SIM-OMEGA-0002"), "");  // its own
  library.save(mapOf("SIM-OMEGA-0003", true));
  EXPECT_EQ(library.findOtherUnit("sim:omega", "SIM-OMEGA-0002"), "");  // corrected, not whole
  const std::string whole = library.save(mapOf("SIM-OMEGA-0001", false));
  EXPECT_EQ(library.findOtherUnit("sim:omega", "SIM-OMEGA-0002"), whole);
  EXPECT_EQ(library.findOtherUnit("sim:omega", "SIM-OMEGA-0001"), own);
  EXPECT_EQ(library.findOtherUnit("sim:falcon", ""), "");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace autograv
