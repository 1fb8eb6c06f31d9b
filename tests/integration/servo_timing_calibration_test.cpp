// Calibration on a loop that keeps its own time: a stall in the middle of a vertex neither ends it
// with a wrong estimate nor faults it, the estimators allocate nothing on a jittery loop, and a
// small calibration on a desktop or a free-running loop matches the exact loop's accuracy.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/device/servo_sample.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/servo_timing_model.h"
#include "autograv/sim/simulated_device.h"
#include "core/estimation/vertex_estimator.h"
#include "sim/experiments.h"

namespace autograv {
namespace {

struct VertexRun {
  VertexEstimate estimate;
  double error_rel = 0.0;  ///< |G_hat - G| / |G| against the simulation's truth
  int spoilt_windows = 0;
};

/// One vertex at the workspace centre of `name` (seed 1, typical friction), initialized by the
/// simulated hand, on an exact 1 kHz loop that stalls for `stall_s` once `stall_at_s` of the
/// vertex has passed (never, for a negative time).
VertexRun runVertex(const std::string& name, double stall_at_s, double stall_s) {
  auto device = sim::makeSimulatedDevice(name, 1);
  device->open();
  device->calibrate();
  const EstimationParameters parameters = sim::toolParameters(*device);
  const Eigen::Vector3d vertex_m = device->workspaceCenter_m();
  const sim::InitializationResult initialization =
      sim::initializeWithSimulatedHand(*device, parameters, vertex_m);
  EXPECT_TRUE(initialization.ok) << initialization.message;
  VertexEstimator estimator(parameters, device->specifications().max_linear_force_n);
  estimator.start(vertex_m, initialization.gravity_n);
  double elapsed_s = 0.0, interval_s = parameters.servo_period_s;
  bool stalled = false;
  VertexRun run;
  while (!estimator.finished() && elapsed_s < 120.0) {
    const ServoSample sample = readServoSample(*device, interval_s);
    Eigen::Vector3d force_n;
    estimator.step(sample, force_n);
    device->setForce(force_n);
    interval_s = parameters.servo_period_s;
    if (!stalled && stall_at_s >= 0.0 && elapsed_s >= stall_at_s) {
      interval_s = stall_s;  // the force just sent is held all that time
      stalled = true;
    }
    device->advance(interval_s);
    elapsed_s += interval_s;
  }
  run.estimate = estimator.estimate();
  const Eigen::Vector3d truth_n = device->trueGravity(vertex_m);
  run.error_rel = (run.estimate.gravity_n - truth_n).norm() / truth_n.norm();
  return run;
}

class VertexStallTest : public ::testing::TestWithParam<std::string> {};

TEST_P(VertexStallTest, AStallInTheMiddleOfAVertexNeitherSpoilsTheEstimateNorFaultsIt) {
  const VertexRun exact = runVertex(GetParam(), -1.0, 0.0);
  ASSERT_EQ(exact.estimate.outcome, VertexOutcome::kConverged);
  // A 20 ms stall at ten places across the vertex: in a transient, inside a window, in the
  // windows the final estimate is read from.
  for (int place = 1; place <= 10; ++place) {
    const double stall_at_s = exact.estimate.seconds * place / 11.0;
    const VertexRun stalled = runVertex(GetParam(), stall_at_s, 0.020);
    EXPECT_EQ(stalled.estimate.outcome, VertexOutcome::kConverged)
        << GetParam() << " stall at " << stall_at_s << " s";
    // Within half a percent of |G|: a stall moves the steady state a window reads as friction
    // does, no more (one vertex through typical friction scatters by that much on its own, and
    // a whole calibration's worst measured point is about 1.3 %).
    EXPECT_LT(std::abs(stalled.error_rel - exact.error_rel), 0.005)
        << GetParam() << " stall at " << stall_at_s << " s: error " << 100 * stalled.error_rel
        << " % against " << 100 * exact.error_rel << " %";
    EXPECT_LT(stalled.estimate.seconds, 1.5 * exact.estimate.seconds + 1.0) << GetParam();
  }
}

INSTANTIATE_TEST_SUITE_P(EverySimulatedDevice, VertexStallTest,
                         ::testing::ValuesIn(sim::simulatedDeviceNames()));

/// One vertex at `vertex_m` of sim:falcon (seed 1, typical friction), started at rest there with
/// the manual initialization's G_hat_0 from the workspace centre, on a loop of `timing` (its
/// lateness drawn from `clock_seed`).
VertexEstimate runFalconVertex(const Eigen::Vector3d& vertex_m, sim::ServoTiming timing,
                               double& error_rel, bool* stop_contact = nullptr,
                               std::uint64_t clock_seed = 1) {
  auto device = sim::makeSimulatedDevice("sim:falcon", 1);
  device->open();
  device->calibrate();
  const EstimationParameters parameters = sim::toolParameters(*device);
  const sim::InitializationResult initialization =
      sim::initializeWithSimulatedHand(*device, parameters, device->workspaceCenter_m());
  EXPECT_TRUE(initialization.ok) << initialization.message;
  device->setForce(device->trueGravity(vertex_m));  // reaches the motors by the reset below
  device->advance(parameters.servo_period_s);
  device->resetState(vertex_m);
  VertexEstimator estimator(parameters, device->specifications().max_linear_force_n);
  estimator.start(vertex_m, initialization.gravity_n);
  sim::ServoTimingModel clock(timing, clock_seed, parameters.servo_period_s);
  while (!estimator.finished() && clock.now_s() < 120.0) {
    const ServoSample sample = readServoSample(*device, clock.lastInterval_s());
    Eigen::Vector3d force_n;
    estimator.step(sample, force_n);
    device->setForce(force_n);
    device->advance(clock.nextInterval_s());
  }
  const Eigen::Vector3d truth_n = device->trueGravity(vertex_m);
  error_rel = (estimator.estimate().gravity_n - truth_n).norm() / truth_n.norm();
  if (stop_contact != nullptr) *stop_contact = estimator.stopContact();
  return estimator.estimate();
}

// Next to sim:falcon's -x face G_x grows by 0.3 N over 10 mm. A desktop loop's jitter widens the
// steady-state windows' tolerance, so a window pair may agree while the end-effector still
// creeps, and eq. (12) then swings around its fixed point (this vertex: x between 0.33 and
// 0.38 N, steps of 10-25 mN) until the iteration cap. The swing rule ends it with the mean over
// the swing (VertexEstimator::kSwingHalf).
TEST(ServoTimingCalibrationTest, ASteepFieldVertexOnADesktopLoopConvergesAsOnAnExactOne) {
  const Eigen::Vector3d vertex_m(-0.0458, -0.0229, 0.0215);
  double exact_error_rel = 0.0, desktop_error_rel = 0.0;
  const VertexEstimate exact = runFalconVertex(vertex_m, sim::ServoTiming::kExact, exact_error_rel);
  const VertexEstimate desktop =
      runFalconVertex(vertex_m, sim::ServoTiming::kDesktop, desktop_error_rel);
  ASSERT_EQ(exact.outcome, VertexOutcome::kConverged);
  EXPECT_EQ(desktop.outcome, VertexOutcome::kConverged);
  EXPECT_LE(desktop.iterations, 2 * exact.iterations + 4)
      << "exact " << exact.iterations << " iterations";
  EXPECT_LT(desktop_error_rel, 0.01) << "exact " << 100 * exact_error_rel << " %";
  RecordProperty("exact_iterations", exact.iterations);
  RecordProperty("desktop_iterations", desktop.iterations);
}

// 1 mm inside sim:falcon's -x stop, where G_x changes by 0.05 N per mm. On a desktop loop a
// steady state may be taken while the end-effector still creeps toward the vertex (at about
// 0.4 mm/s under the dither): the step then looks held, as by a stop. Half of these clocks ended
// the vertex there, 6-8 % off and marked unreachable, before a held step was looked at again
// for at least VertexEstimator::kStopSecondLook_s.
TEST(ServoTimingCalibrationTest, ACreepNextToAStopIsNotTakenForTheStop) {
  const Eigen::Vector3d vertex_m(-0.0484, -0.0007, -0.0010);
  for (const std::uint64_t clock_seed : {1, 4, 6, 8}) {
    double error_rel = 0.0;
    bool stop_contact = true;
    const VertexEstimate estimate =
        runFalconVertex(vertex_m, sim::ServoTiming::kDesktop, error_rel, &stop_contact, clock_seed);
    EXPECT_EQ(estimate.outcome, VertexOutcome::kConverged) << "clock seed " << clock_seed;
    EXPECT_FALSE(stop_contact) << "clock seed " << clock_seed;
    EXPECT_LT(error_rel, 0.01) << "clock seed " << clock_seed;
  }
}

// The whole default calibration of sim:falcon on a desktop loop measures its points as the exact
// loop does: no point taken for a stop that the exact loop measures, and every swing's mean taken
// over the swing alone (without the approach, vertex 80's mean was 1.4 % off in x).
TEST(ServoTimingCalibrationTest, ADesktopLoopMeasuresEveryPointOfTheFalconAsTheExactLoopDoes) {
  int converged[2] = {0, 0};
  const sim::ServoTiming timings[2] = {sim::ServoTiming::kExact, sim::ServoTiming::kDesktop};
  for (int t = 0; t < 2; ++t) {
    auto device = sim::makeSimulatedDevice("sim:falcon", 1);
    ASSERT_TRUE(device->open() && device->calibrate());
    // As `autograv calibrate --device sim:falcon --servo-timing T` runs it.
    sim::CalibrationRunOptions options = sim::defaultCalibrationOptions(*device);
    options.servo_timing = timings[t];
    options.servo_timing_seed = 1;
    const sim::CalibrationRunResult run = sim::runSimulatedCalibration(*device, options);
    ASSERT_EQ(run.status, AutoCalibrator::Status::kFinished);
    for (int index = 0; index < run.grid.vertexCount(); ++index) {
      const VertexEstimate& vertex = run.vertices[static_cast<std::size_t>(index)];
      if (vertex.outcome != VertexOutcome::kConverged) continue;
      ++converged[t];
      const Eigen::Vector3d truth_n =
          device->trueGravity(vertex.measuredAt_m(run.grid.vertexPosition(index)));
      // The exact loop within 1 % of |G| everywhere. The desktop loop's late ticks shake the
      // holds of the -x face's points, 1.5 mm from the stops where the field is steepest
      // (vertices 55, 60 and 80: 1.3-1.4 %), within 1.5 %.
      const double limit = timings[t] == sim::ServoTiming::kExact ? 0.01 : 0.015;
      EXPECT_LT((vertex.measuredGravity_n() - truth_n).norm(), limit * truth_n.norm())
          << sim::toString(timings[t]) << ", vertex " << index << ", " << vertex.iterations
          << " iterations";
    }
  }
  EXPECT_GE(converged[1], converged[0]);
}

TEST(ServoTimingAllocationTest, EstimatorsOnAJitteryLoopAllocateNothing) {
  auto device = sim::makeSimulatedDevice("sim:omni", 1);
  device->open();
  device->calibrate();
  const EstimationParameters parameters = sim::toolParameters(*device);
  const WorkspaceGrid grid(device->workspaceCenter_m(), 0.02, 2);
  AutoCalibrator calibrator(grid, parameters, device->specifications().max_linear_force_n);
  device->resetState(grid.center_m());
  calibrator.start(grid.center_m(), device->trueGravity(grid.center_m()));
  sim::ServoTimingModel timing(sim::ServoTiming::kDesktop, 1);
  ServoLoopStats stats;
  std::vector<ServoSample> samples;
  testing::AllocationCounter counter;
  for (int tick = 0; tick < 20000; ++tick) {
    const ServoSample sample = readServoSample(*device, timing.lastInterval_s());
    Eigen::Vector3d force_n;
    calibrator.step(sample, force_n);
    device->setForce(force_n);
    device->advance(timing.nextInterval_s());
    stats.record(timing.lastInterval_s(), timing.lastLateness_s());
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_GT(calibrator.visitedCount(), 0);  // it did get through vertices meanwhile
}

struct TimedCalibration {
  double max_error_rel = 0.0;
  double rms_rel = 0.0;
  double seconds = 0.0;
  int converged = 0;
  double seconds_above_continuous_force = 0.0;
  ServoLoopStats::Summary loop;
};

TimedCalibration calibrateCube(const std::string& name, sim::ServoTiming timing) {
  auto device = sim::makeSimulatedDevice(name, 1);
  device->open();
  device->calibrate();
  sim::DefaultCubeOptions cube;
  cube.servo_timing = timing;
  const sim::DefaultCubeCalibration calibration = sim::calibrateDefaultCube(*device, cube);
  const sim::CalibrationRunResult& run = calibration.run;
  const sim::AccuracyReport accuracy = sim::measureAccuracy(*calibration.map, *device, 500);
  TimedCalibration result;
  result.max_error_rel = accuracy.max_error_rel;
  result.rms_rel = accuracy.rms_residual_rel;
  result.seconds = run.simulated_seconds;
  result.converged = calibration.map->convergedCount();
  result.seconds_above_continuous_force = run.seconds_above_continuous_force;
  result.loop = run.servo_loop;
  return result;
}

TEST(ServoTimingCalibrationTest, DesktopAndFreeLoopsCalibrateAsAccuratelyAsAnExactOne) {
  const TimedCalibration exact = calibrateCube("sim:omega", sim::ServoTiming::kExact);
  EXPECT_NEAR(exact.loop.rate_hz, 1000.0, 1e-6);
  EXPECT_NEAR(exact.loop.longest_gap_ms, 1.0, 1e-9);
  for (const sim::ServoTiming timing : {sim::ServoTiming::kDesktop, sim::ServoTiming::kFree}) {
    const TimedCalibration timed = calibrateCube("sim:omega", timing);
    const char* name = sim::toString(timing);
    EXPECT_EQ(timed.converged, exact.converged) << name;
    EXPECT_LT(std::abs(timed.max_error_rel - exact.max_error_rel), 0.003) << name;
    EXPECT_LT(std::abs(timed.rms_rel - exact.rms_rel), 0.003) << name;
    EXPECT_LT(timed.seconds, 1.15 * exact.seconds) << name;
    if (timing == sim::ServoTiming::kFree) {
      EXPECT_GT(timed.loop.rate_hz, 2000.0);
      EXPECT_LT(timed.loop.rate_hz, 8000.0);
    } else {
      EXPECT_NEAR(timed.loop.rate_hz, 1000.0, 5.0);
      EXPECT_GT(timed.loop.lateness_p50_ms, 0.3);
    }
  }
}

// sim:omni's dither peaks just under its 0.88 N continuous rating. On a jittery loop the
// estimator pays back the impulse that late ticks delivered too much or too little; those
// paybacks must fit in what the rating leaves, or the device runs above it for much of the
// calibration (6-7 % on a desktop loop before they were budgeted).
TEST(ServoTimingCalibrationTest, AJitteryLoopKeepsTheDeviceWithinItsContinuousRating) {
  const TimedCalibration exact = calibrateCube("sim:omni", sim::ServoTiming::kExact);
  const TimedCalibration desktop = calibrateCube("sim:omni", sim::ServoTiming::kDesktop);
  RecordProperty("exact_above_continuous_s", std::to_string(exact.seconds_above_continuous_force));
  RecordProperty("desktop_above_continuous_s",
                 std::to_string(desktop.seconds_above_continuous_force));
  EXPECT_LT(desktop.seconds_above_continuous_force, 0.02 * desktop.seconds);
  EXPECT_LT(desktop.seconds_above_continuous_force,
            exact.seconds_above_continuous_force + 0.01 * desktop.seconds);
  EXPECT_EQ(desktop.converged, exact.converged);
}

}  // namespace
}  // namespace autograv
