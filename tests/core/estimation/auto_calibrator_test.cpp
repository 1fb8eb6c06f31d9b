#include "autograv/estimation/auto_calibrator.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/map/measurement_review.h"
#include "ideal_point_mass.h"
#include "probed_workspaces.h"

namespace autograv {
namespace {

constexpr double kPeriod = 1e-3;

struct Fixture {
  testing::IdealPointMass device;
  WorkspaceGrid grid{Eigen::Vector3d(0.0, 0.0, -0.01), 0.06, 3};
  EstimationParameters parameters;
  AutoCalibrator calibrator{grid, parameters, 12.0};

  AutoCalibrator::Status run(long max_ticks, int stop_after_vertices = -1) {
    AutoCalibrator::Status status = AutoCalibrator::Status::kIdle;
    int finished = 0;
    for (long tick = 0; tick < max_ticks; ++tick) {
      Eigen::Vector3d force;
      status = calibrator.step(device.sample(), force);
      device.advance(force, kPeriod);
      if (status == AutoCalibrator::Status::kVertexFinished && ++finished == stop_after_vertices) {
        break;
      }
      if (status == AutoCalibrator::Status::kFinished ||
          status == AutoCalibrator::Status::kDeviceFault)
        break;
    }
    return status;
  }
};

TEST(AutoCalibratorTest, CalibratesEveryVertexOfTheGrid) {
  Fixture f;
  f.device.position_m = f.grid.center_m();
  f.calibrator.start(f.device.position_m, 0.8 * f.device.gravity(f.device.position_m));
  EXPECT_EQ(f.run(2'000'000), AutoCalibrator::Status::kFinished);
  const GravityMap map = f.calibrator.makeMap(MapMetadata{});
  EXPECT_TRUE(map.isComplete());
  for (int i = 0; i < f.grid.vertexCount(); ++i) {
    const Eigen::Vector3d truth = f.device.gravity(f.grid.vertexPosition(i));
    EXPECT_LT((map.vertices()[i].gravity_n - truth).norm(), f.parameters.eps_g_n) << "vertex " << i;
  }
  // The field is affine, so the measured Lipschitz constant is the largest |J e_k|.
  EXPECT_NEAR(f.calibrator.lipschitzEstimate_n_per_m(),
              f.device.gradient_n_per_m.colwise().norm().maxCoeff(), 0.5);
  EXPECT_LT(f.calibrator.peakForce_n(), 12.0);
}

TEST(AutoCalibratorTest, APointAStopHoldsShortIsMeasuredBackFromTheStop) {
  // The +x face of the grid lies 2 mm beyond a stop the plan did not know of.
  Fixture f;
  f.device.wall_x_m = f.grid.maxCorner_m().x() - 0.002;
  f.device.position_m = f.grid.center_m();
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  EXPECT_EQ(f.run(4'000'000), AutoCalibrator::Status::kFinished);
  EXPECT_EQ(f.calibrator.stopRetreats(), 9);  // every vertex of the +x face, once
  for (int i = 0; i < f.grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = f.calibrator.vertices()[static_cast<std::size_t>(i)];
    EXPECT_EQ(vertex.outcome, VertexOutcome::kConverged) << "vertex " << i;
    const bool on_face = f.grid.vertexCoordinates(i).x() == 2;
    EXPECT_EQ(vertex.measuredOffVertex(), on_face) << "vertex " << i;
    if (!on_face) continue;
    // Measured back from the stop, by kStopRetreat_m, and right there.
    EXPECT_NEAR(vertex.measured_at_m.x(), f.device.wall_x_m - AutoCalibrator::kStopRetreat_m, 1e-3);
    EXPECT_LT((vertex.measured_gravity_n - f.device.gravity(vertex.measured_at_m)).norm(),
              2.0 * f.parameters.eps_g_n);
  }
}

TEST(AutoCalibratorTest, APointAStopHoldsDuringItsHoldIsMovedBackAndMeasuredClearOfIt) {
  // The explored boundary lies 2 mm beyond the real stop (a probe presses into its rubber: about
  // as much on sim:falcon's travel stops), so the plan's points next to the +x face stand half a
  // millimetre inside the stop. Each is seen held (the held-still or the creep rule) and moved
  // back a millimetre at a time, and measured clear of the stop or left to the fill, never with
  // the stop's reaction in its value.
  Fixture f;
  const double explored_half_width_m = 0.5 * f.grid.size_m().x();
  f.device.wall_x_m = f.grid.center_m().x() + explored_half_width_m - 0.002;
  f.device.position_m = f.grid.center_m();
  AutoCalibrator calibrator(f.grid, f.parameters, 12.0);
  calibrator.setPlan(
      planMeasurements(f.grid, testing::probedCube(explored_half_width_m, f.grid.center_m())));
  calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  AutoCalibrator::Status status = AutoCalibrator::Status::kIdle;
  for (long tick = 0; tick < 4'000'000 && status != AutoCalibrator::Status::kFinished; ++tick) {
    Eigen::Vector3d force;
    status = calibrator.step(f.device.sample(), force);
    f.device.advance(force, kPeriod);
  }
  ASSERT_EQ(status, AutoCalibrator::Status::kFinished);
  RecordProperty("stop_retreats", std::to_string(calibrator.stopRetreats()));
  EXPECT_GT(calibrator.stopRetreats(), 0);
  int measured = 0;
  for (int i = 0; i < f.grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = calibrator.vertices()[static_cast<std::size_t>(i)];
    if (f.grid.vertexCoordinates(i).x() != 2) {
      EXPECT_EQ(vertex.outcome, VertexOutcome::kConverged) << "vertex " << i;
      continue;
    }
    if (vertex.outcome == VertexOutcome::kUnreachable) continue;  // solved from the others
    ASSERT_EQ(vertex.outcome, VertexOutcome::kConverged) << "vertex " << i;
    ++measured;
    EXPECT_LT(vertex.measured_at_m.x(), f.device.wall_x_m - 0.25e-3) << "vertex " << i;
    EXPECT_LT((vertex.measured_gravity_n - f.device.gravity(vertex.measured_at_m)).norm(),
              2.0 * f.parameters.eps_g_n)
        << "vertex " << i << ": the stop's reaction taken for gravity";
  }
  EXPECT_GE(measured, 6);
}

TEST(AutoCalibratorTest, AMeasurementAKnockSpoiledIsMeasuredAgainAndReplacedByTheSecond) {
  // A hand knocks the arm (a push of 15 % of |G| sideways and up) through vertex 13's first hold
  // only: its measurement stands out of the 27, is measured again where it was
  // (remeasureAt), and the second measurement, within eps_G of the truth, replaces the first.
  Fixture f;
  const int knocked = 13;
  const Eigen::Vector3d knock_n = 0.15 * 2.1 * Eigen::Vector3d(0.6, 0.0, 0.8);
  f.device.position_m = f.grid.center_m();
  f.calibrator.start(f.device.position_m, 0.8 * f.device.gravity(f.device.position_m));
  bool first_visit = true;
  AutoCalibrator::Status status = AutoCalibrator::Status::kIdle;
  for (long tick = 0; tick < 2'000'000 && status != AutoCalibrator::Status::kFinished; ++tick) {
    Eigen::Vector3d force;
    status = f.calibrator.step(f.device.sample(), force);
    const bool holding = f.calibrator.currentVertex() == knocked &&
                         f.calibrator.state() == AutoCalibrator::Status::kEstimating;
    f.device.advance(holding && first_visit ? Eigen::Vector3d(force + knock_n) : force, kPeriod);
    if (status == AutoCalibrator::Status::kVertexFinished &&
        f.calibrator.lastFinishedVertex() == knocked) {
      first_visit = false;
    }
  }
  ASSERT_EQ(status, AutoCalibrator::Status::kFinished);
  {
    const Eigen::Vector3d first_n = f.calibrator.vertices()[knocked].gravity_n;
    const Eigen::Vector3d truth_first_n = f.device.gravity(f.grid.vertexPosition(knocked));
    ASSERT_GT((first_n - truth_first_n).norm(), 0.2)
        << first_n.transpose() << " / " << truth_first_n.transpose() << " outcome "
        << toString(f.calibrator.vertices()[knocked].outcome);
  }
  std::vector<ReviewedMeasurement> reviewed =
      planReview(f.grid, f.calibrator.vertices(), f.parameters.eps_g_n);
  ASSERT_EQ(reviewed.size(), 1u);
  EXPECT_EQ(reviewed.front().first.vertex, knocked);
  EXPECT_GT(reviewed.front().first.residual_rel, 0.1);
  f.calibrator.remeasureAt(knocked, reviewed.front().again_point_m);
  EXPECT_EQ(f.calibrator.vertices()[knocked].outcome, VertexOutcome::kPending);
  f.calibrator.visitOnly({knocked});
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  EXPECT_EQ(f.run(2'000'000), AutoCalibrator::Status::kFinished);
  std::vector<VertexEstimate> vertices = f.calibrator.vertices();
  concludeReview(f.grid, vertices, reviewed, f.parameters.eps_g_n);
  EXPECT_EQ(reviewed.front().verdict, ReviewVerdict::kReplaced);
  const Eigen::Vector3d truth_n = f.device.gravity(f.grid.vertexPosition(knocked));
  EXPECT_EQ(vertices[knocked].outcome, VertexOutcome::kConverged);
  EXPECT_LT((vertices[knocked].gravity_n - truth_n).norm(), f.parameters.eps_g_n);
}

TEST(AutoCalibratorTest, RemeasureAtRefusesAVertexOutsideTheGridOrAPointThatIsNotFinite) {
  Fixture f;
  EXPECT_THROW(f.calibrator.remeasureAt(27, f.grid.center_m()), Error);
  EXPECT_THROW(f.calibrator.remeasureAt(-1, f.grid.center_m()), Error);
  EXPECT_THROW(f.calibrator.remeasureAt(3, Eigen::Vector3d(0.0, std::nan(""), 0.0)), Error);
}

TEST(AutoCalibratorTest, MovesAccelerateWithTheRoomBeyondTheirTarget) {
  AutoCalibrator::Options options;
  const double gentle = options.max_move_acceleration_m_per_s2;
  const double deep = options.deep_move_acceleration_m_per_s2;
  EXPECT_EQ(AutoCalibrator::moveAcceleration_m_per_s2(options, 0.0), gentle);
  EXPECT_EQ(AutoCalibrator::moveAcceleration_m_per_s2(options, AutoCalibrator::kMoveRoom_m),
            gentle);
  EXPECT_NEAR(AutoCalibrator::moveAcceleration_m_per_s2(options, 1.5 * AutoCalibrator::kMoveRoom_m),
              1.5 * gentle, 1e-12);
  EXPECT_EQ(AutoCalibrator::moveAcceleration_m_per_s2(options, 0.1), deep);
  // The room a move asks the workspace for is where the deep acceleration is reached.
  EXPECT_NEAR(AutoCalibrator::deepMoveRoom_m(options), AutoCalibrator::kMoveRoom_m * deep / gentle,
              1e-15);
  EXPECT_NEAR(
      AutoCalibrator::moveAcceleration_m_per_s2(options, AutoCalibrator::deepMoveRoom_m(options)),
      deep, 1e-12);
  AutoCalibrator::Options brisk;
  brisk.deep_move_acceleration_m_per_s2 = 4.0 * gentle;
  EXPECT_NEAR(AutoCalibrator::deepMoveRoom_m(brisk), 4.0 * AutoCalibrator::kMoveRoom_m, 1e-15);
  // The saturation pre-check judges the quickest move.
  const EstimationParameters parameters;
  EXPECT_NEAR(AutoCalibrator::largestHoldStep_m(parameters, options),
              AutoCalibrator::kMassUncertainty * deep / parameters.beta_per_s2, 1e-15);
  options.deep_move_acceleration_m_per_s2 = 0.5 * gentle;  // never slower than the gentle moves
  EXPECT_EQ(AutoCalibrator::moveAcceleration_m_per_s2(options, 0.1), gentle);
  EXPECT_EQ(AutoCalibrator::deepMoveRoom_m(options), AutoCalibrator::kMoveRoom_m);
}

// Calibrates a 3 x 3 x 3 grid whose +x face lies 4 mm (kMoveRoom_m) inside a stop, on an arm three
// times heavier than the paper's |G|/g (what AutoCalibrator::kMassUncertainty allows): the plan's
// workspace is the cube the stop bounds.
struct NextToAStop {
  Fixture f;
  explicit NextToAStop(const AutoCalibrator::Options& options)
      : calibrator(f.grid, f.parameters, 12.0, options) {
    const double half_width_m = 0.5 * f.grid.size_m().x() + AutoCalibrator::kMoveRoom_m;
    f.device.wall_x_m = f.grid.center_m().x() + half_width_m;
    f.device.mass_factor = AutoCalibrator::kMassUncertainty;
    f.device.position_m = f.grid.center_m();
    calibrator.setPlan(
        planMeasurements(f.grid, testing::probedCube(half_width_m, f.grid.center_m())));
    calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
    for (long tick = 0; tick < 2'000'000; ++tick) {
      Eigen::Vector3d force;
      const AutoCalibrator::Status status = calibrator.step(f.device.sample(), force);
      moving_s += status == AutoCalibrator::Status::kMoving ? kPeriod : 0.0;
      f.device.advance(force, kPeriod);
      if (status == AutoCalibrator::Status::kFinished) break;
    }
  }
  AutoCalibrator calibrator;
  double moving_s = 0.0;
};

TEST(AutoCalibratorTest, QuickMovesLeaveTheStopsAlone) {
  AutoCalibrator::Options gentle_only;
  gentle_only.deep_move_acceleration_m_per_s2 = gentle_only.max_move_acceleration_m_per_s2;
  const NextToAStop gentle(gentle_only);
  const NextToAStop quick{AutoCalibrator::Options()};
  ASSERT_EQ(quick.calibrator.state(), AutoCalibrator::Status::kFinished);
  ASSERT_EQ(gentle.calibrator.state(), AutoCalibrator::Status::kFinished);
  RecordProperty("gentle_moving_s", std::to_string(gentle.moving_s));
  RecordProperty("quick_moving_s", std::to_string(quick.moving_s));
  RecordProperty("quick_max_x_beyond_face_mm",
                 std::to_string((quick.f.device.max_x_m - quick.f.grid.maxCorner_m().x()) * 1e3));
  // Along the faces and inward the moves take the deep acceleration; into a face, the gentle
  // (every face of the cube is 4 mm beyond the grid's, so most moves end next to one).
  EXPECT_LT(quick.moving_s, 0.9 * gentle.moving_s);
  EXPECT_LT(quick.f.device.max_x_m, quick.f.device.wall_x_m);
  EXPECT_EQ(quick.calibrator.stopRetreats(), 0);
  for (int i = 0; i < quick.f.grid.vertexCount(); ++i) {
    const VertexEstimate& vertex = quick.calibrator.vertices()[static_cast<std::size_t>(i)];
    EXPECT_EQ(vertex.outcome, VertexOutcome::kConverged) << "vertex " << i;
    const Eigen::Vector3d at_m = vertex.measuredAt_m(quick.f.grid.vertexPosition(i));
    EXPECT_LT((vertex.measuredGravity_n() - quick.f.device.gravity(at_m)).norm(),
              quick.f.parameters.eps_g_n)
        << "vertex " << i;
  }
  // Every move at the deep acceleration would have overshot toward the stop twice as far
  // (2.4 mm against 1.2 mm beyond the face, with the stop at 4 mm).
  AutoCalibrator::Options quick_everywhere;
  quick_everywhere.max_move_acceleration_m_per_s2 =
      quick_everywhere.deep_move_acceleration_m_per_s2;
  const NextToAStop rammed(quick_everywhere);
  RecordProperty("rammed_max_x_beyond_face_mm",
                 std::to_string((rammed.f.device.max_x_m - rammed.f.grid.maxCorner_m().x()) * 1e3));
  EXPECT_GT(rammed.f.device.max_x_m, quick.f.device.max_x_m + 0.001);
}

TEST(AutoCalibratorTest, ExtrapolationSavesIterationsWithoutChangingTheResult) {
  Fixture plain;
  AutoCalibrator::Options options;
  options.extrapolate_initial_estimate = false;
  AutoCalibrator copy_only(plain.grid, plain.parameters, 12.0, options);
  Fixture smart;
  int iterations[2] = {0, 0};
  Fixture* runs[2] = {&plain, &smart};
  AutoCalibrator* calibrators[2] = {&copy_only, &smart.calibrator};
  for (int k = 0; k < 2; ++k) {
    Fixture& f = *runs[k];
    f.device.position_m = f.grid.center_m();
    calibrators[k]->start(f.device.position_m, f.device.gravity(f.device.position_m));
    for (long tick = 0; tick < 2'000'000; ++tick) {
      Eigen::Vector3d force;
      if (calibrators[k]->step(f.device.sample(), force) == AutoCalibrator::Status::kFinished)
        break;
      f.device.advance(force, kPeriod);
    }
    for (const auto& vertex : calibrators[k]->vertices()) iterations[k] += vertex.iterations;
    EXPECT_EQ(calibrators[k]->makeMap({}).convergedCount(), 27);
  }
  EXPECT_LT(iterations[1], iterations[0]);
}

// The first step at each point, for the points measured in the order they finished.
std::vector<double> firstStepErrors_m(Fixture& f, AutoCalibrator& calibrator) {
  f.device.position_m = f.grid.center_m();
  calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  std::vector<double> errors_m;
  for (long tick = 0; tick < 4'000'000; ++tick) {
    Eigen::Vector3d force;
    const AutoCalibrator::Status status = calibrator.step(f.device.sample(), force);
    if (status == AutoCalibrator::Status::kFinished) break;
    if (status == AutoCalibrator::Status::kVertexFinished) {
      const VertexEstimate& vertex =
          calibrator.vertices()[static_cast<std::size_t>(calibrator.lastFinishedVertex())];
      errors_m.push_back(vertex.history.empty() ? 1.0 : vertex.history.front().position_error_m);
    }
    f.device.advance(force, kPeriod);
  }
  return errors_m;
}

TEST(AutoCalibratorTest, EachPointStartsFromWhatTheMeasurementsSoFarPredict) {
  // An affine field measured at points up to 6 mm off the vertices, as near the stops: a fit to
  // the nearest measurements predicts the field at the next point exactly, so its first step
  // finds the end-effector where it should be; eq. (9)'s copy of the last estimate does not.
  MeasurementPlan plan;
  Fixture fitted;
  const int count = fitted.grid.vertexCount();
  plan.points_m.resize(static_cast<std::size_t>(count));
  plan.measure.assign(static_cast<std::size_t>(count), true);
  for (int i = 0; i < count; ++i) {
    const Eigen::Vector3d offset_m(((i * 7) % 5 - 2) * 0.003, ((i * 3) % 5 - 2) * 0.002,
                                   ((i * 11) % 5 - 2) * 0.0015);
    plan.points_m[static_cast<std::size_t>(i)] = fitted.grid.vertexPosition(i) + offset_m;
  }
  fitted.calibrator.setPlan(plan);
  Fixture along_lines;
  AutoCalibrator::Options copy_options;
  copy_options.extrapolate_initial_estimate = false;
  AutoCalibrator copying(along_lines.grid, along_lines.parameters, 12.0, copy_options);
  copying.setPlan(plan);
  const std::vector<double> fit_m = firstStepErrors_m(fitted, fitted.calibrator);
  const std::vector<double> copy_m = firstStepErrors_m(along_lines, copying);
  ASSERT_EQ(fit_m.size(), static_cast<std::size_t>(count));
  ASSERT_EQ(copy_m.size(), static_cast<std::size_t>(count));
  // From the eleventh point on: AutoCalibrator::kMinFitMeasurements are converged around each
  // from the seventh, but the first nine lie in one layer of the grid, and a fit to them cannot
  // know how the field changes toward the next layer (the tenth point, 1.1 mm off; a copy of
  // the last estimate, 2.0 mm).
  constexpr std::size_t kFirstFitted = 10;
  double fit_worst_m = 0.0;
  std::vector<double> later_copy(copy_m.begin() + kFirstFitted, copy_m.end());
  std::sort(later_copy.begin(), later_copy.end());
  const double copy_median_m = later_copy[later_copy.size() / 2];
  for (std::size_t k = kFirstFitted; k < fit_m.size(); ++k) {
    fit_worst_m = std::max(fit_worst_m, fit_m[k]);
  }
  RecordProperty("fit_worst_first_step_mm", std::to_string(fit_worst_m * 1e3));
  RecordProperty("copy_median_first_step_mm", std::to_string(copy_median_m * 1e3));
  EXPECT_LT(fit_worst_m, 0.1 * copy_median_m);
  for (const VertexEstimate& vertex : fitted.calibrator.vertices()) {
    EXPECT_EQ(vertex.outcome, VertexOutcome::kConverged);
    EXPECT_LT((vertex.measured_gravity_n - fitted.device.gravity(vertex.measured_at_m)).norm(),
              fitted.parameters.eps_g_n);
  }
}

TEST(AutoCalibratorTest, RestoredVerticesAreKeptBitForBitAndNotRevisited) {
  Fixture first;
  first.device.position_m = first.grid.center_m();
  first.calibrator.start(first.device.position_m, first.device.gravity(first.device.position_m));
  first.run(2'000'000, 10);  // "crash" after 10 vertices
  const std::vector<VertexEstimate> checkpoint = first.calibrator.vertices();
  int done = 0;
  for (const auto& v : checkpoint) done += v.outcome == VertexOutcome::kConverged;
  ASSERT_EQ(done, 10);

  Fixture second;
  second.calibrator.restore(checkpoint);
  EXPECT_EQ(second.calibrator.toVisitCount(), 17);
  second.device.position_m = second.grid.center_m();
  second.calibrator.start(second.device.position_m,
                          second.device.gravity(second.device.position_m));
  EXPECT_EQ(second.run(2'000'000), AutoCalibrator::Status::kFinished);
  for (std::size_t i = 0; i < checkpoint.size(); ++i) {
    if (checkpoint[i].outcome != VertexOutcome::kConverged) continue;
    EXPECT_EQ(second.calibrator.vertices()[i].gravity_n, checkpoint[i].gravity_n);
    EXPECT_EQ(second.calibrator.vertices()[i].iterations, checkpoint[i].iterations);
  }
  EXPECT_TRUE(second.calibrator.makeMap({}).isComplete());
  EXPECT_THROW(second.calibrator.restore(std::vector<VertexEstimate>(5)), Error);
}

TEST(AutoCalibratorTest, PauseHoldsAndResumeCarriesOn) {
  Fixture f;
  f.device.position_m = f.grid.center_m();
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  f.run(700);
  f.calibrator.pause();
  Eigen::Vector3d force;
  for (int k = 0; k < 2000; ++k) {
    EXPECT_EQ(f.calibrator.step(f.device.sample(), force), AutoCalibrator::Status::kPaused);
    f.device.advance(force, kPeriod);
  }
  const Eigen::Vector3d held = f.device.position_m;
  for (int k = 0; k < 500; ++k) {
    f.calibrator.step(f.device.sample(), force);
    f.device.advance(force, kPeriod);
  }
  EXPECT_LT((f.device.position_m - held).norm(), 1e-4);  // held still within 0.1 mm
  f.calibrator.resume();
  EXPECT_EQ(f.run(2'000'000), AutoCalibrator::Status::kFinished);
  EXPECT_TRUE(f.calibrator.makeMap({}).isComplete());
}

TEST(AutoCalibratorTest, AbortKeepsHoldingAndVisitOnlyRedoesChosenVertices) {
  Fixture f;
  f.device.position_m = f.grid.center_m();
  f.calibrator.visitOnly({4, 13});
  EXPECT_EQ(f.calibrator.toVisitCount(), 2);
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  EXPECT_EQ(f.run(2'000'000), AutoCalibrator::Status::kFinished);
  EXPECT_EQ(f.calibrator.makeMap({}).convergedCount(), 2);
  f.calibrator.abort();
  Eigen::Vector3d force;
  EXPECT_EQ(f.calibrator.step(f.device.sample(), force), AutoCalibrator::Status::kAborted);
  EXPECT_GT(force.norm(), 1.0);  // still carrying the weight, not dropping it
  EXPECT_THROW(f.calibrator.visitOnly({27}), Error);
}

TEST(AutoCalibratorTest, DeviceFaultStopsTheRunWithZeroForce) {
  Fixture f;
  f.device.position_m = f.grid.center_m();
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  f.run(3000);
  Eigen::Vector3d force = Eigen::Vector3d::Ones();
  AutoCalibrator::Status status = AutoCalibrator::Status::kMoving;
  for (int k = 0; k < 100; ++k) status = f.calibrator.step(ServoSample{}, force);
  EXPECT_EQ(status, AutoCalibrator::Status::kDeviceFault);
  EXPECT_EQ(force, Eigen::Vector3d::Zero());
}

TEST(AutoCalibratorTest, StepAllocatesNothing) {
  Fixture f;
  f.device.position_m = f.grid.center_m();
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  testing::AllocationCounter counter;
  const AutoCalibrator::Status status = f.run(2'000'000);
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_EQ(status, AutoCalibrator::Status::kFinished);
}

TEST(AutoCalibratorTest, StepAllocatesNothingWhenTheMovesConsultTheWorkspace) {
  Fixture f;
  f.device.position_m = f.grid.center_m();
  f.calibrator.setPlan(planMeasurements(
      f.grid, testing::probedSphere(f.grid.center_m(), 0.9 * f.grid.size_m().norm() / 2.0, 26)));
  f.calibrator.start(f.device.position_m, f.device.gravity(f.device.position_m));
  testing::AllocationCounter counter;
  const AutoCalibrator::Status status = f.run(2'000'000);
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_EQ(status, AutoCalibrator::Status::kFinished);
}

}  // namespace
}  // namespace autograv
