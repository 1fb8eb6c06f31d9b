// The stop watch of a hold next to the boundary (VertexEstimator's push test, kPushProbe_m): a
// hold that a stop holds is never taken as converged, whichever way the stop faces, and a free
// hold is never taken for a stop. On the Omega-like point mass in a box of +/-40 mm (flat stops
// on every face: a floor and a ceiling across gravity, walls, edges).

#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/device/servo_sample.h"
#include "autograv/estimation/auto_calibrator.h"
#include "autograv/map/measurement_plan.h"
#include "autograv/sim/point_mass_device.h"
#include "autograv/sim/simulated_driver.h"
#include "core/estimation/vertex_estimator.h"
#include "probed_workspaces.h"

namespace autograv {
namespace {

constexpr double kServo_s = 1e-3;
constexpr double kHalfWidth_m = 0.040;

sim::PointMassParameters boxDevice(sim::FrictionLevel friction, double stop_n_per_m) {
  sim::PointMassParameters parameters = sim::omegaParameters(friction);
  parameters.workspace_shape = sim::WorkspaceShape::kBox;
  parameters.workspace_half_extents_m = Eigen::Vector3d::Constant(kHalfWidth_m);
  parameters.specifications.workspace_radius_m = kHalfWidth_m;
  parameters.end_stop_stiffness_n_per_m = stop_n_per_m;
  return parameters;
}

/// What one hold ended with.
struct Held {
  VertexEstimator::Status status = VertexEstimator::Status::kSettling;
  bool stop = false;
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();
  Eigen::Vector3d contact_direction = Eigen::Vector3d::Zero();
  Eigen::Vector3d outward_moved_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d inward_moved_m = Eigen::Vector3d::Zero();
  int push_tests = 0;
  double seconds = 0.0;
};

/// Holds `point_m` on `device` from rest there (at the stop's face when the point lies in it),
/// starting from the true gravity off by `start_error_n`, the way AutoCalibrator holds a
/// watched point: outward direction `outward`, push direction `push` (zero: `outward`).
Held hold(sim::PointMassDevice& device, const Eigen::Vector3d& point_m,
          const Eigen::Vector3d& outward, const Eigen::Vector3d& push,
          const Eigen::Vector3d& start_error_n) {
  const Eigen::Vector3d centre_m = device.workspaceCenter_m();
  const Eigen::Vector3d rest_m =
      centre_m + (point_m - centre_m).cwiseMax(-kHalfWidth_m).cwiseMin(kHalfWidth_m);
  device.resetState(rest_m);
  VertexEstimator estimator(EstimationParameters{}, device.specifications().max_linear_force_n);
  estimator.start(point_m, device.trueGravity(point_m) + start_error_n);
  estimator.setOutward(outward, push);
  Held held;
  for (int tick = 0; tick < 60'000 && !estimator.finished(); ++tick) {
    Eigen::Vector3d force_n;
    held.status = estimator.step(readServoSample(device, kServo_s), force_n);
    device.setForce(force_n);
    device.advance(kServo_s);
  }
  held.stop = estimator.stopContact();
  held.gravity_n = estimator.estimate().gravity_n;
  held.contact_direction = estimator.contactDirection();
  held.outward_moved_m = estimator.pushOutwardMoved_m();
  held.inward_moved_m = estimator.pushInwardMoved_m();
  held.push_tests = estimator.pushTests();
  held.seconds = estimator.estimate().seconds;
  return held;
}

sim::PointMassDevice openBox(sim::FrictionLevel friction, double stop_n_per_m, std::uint64_t seed) {
  sim::PointMassDevice device(boxDevice(friction, stop_n_per_m), seed);
  EXPECT_TRUE(device.open());
  EXPECT_TRUE(device.calibrate());
  return device;
}

/// A stop case: the point, where it lies against the faces, and how the hold is watched.
struct StopCase {
  const char* name;
  Eigen::Vector3d offset_m;  // from the centre
  Eigen::Vector3d outward;
  Eigen::Vector3d push;  // zero: the outward direction
};

// The point 0.15 mm inside the stop's rubber (a flat ceiling on a delta held 0.15 mm into it
// kept 20 % of |G|), or 0.1 mm short of it (grazing: the dither's swing of about +/-0.3 mm
// across gravity touches it).
constexpr double kInto_m = 0.15e-3;
constexpr double kGrazing_m = -0.1e-3;
constexpr double kFace_m = kHalfWidth_m;

std::vector<StopCase> stopCases() {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const Eigen::Vector3d diagonal = Eigen::Vector3d(1.0, 0.0, -1.0).normalized();
  return {
      {"floor", {0.004, -0.006, -(kFace_m + kInto_m)}, {0, 0, -1}, zero},
      {"ceiling", {-0.005, 0.003, kFace_m + kInto_m}, {0, 0, 1}, zero},
      {"wall", {kFace_m + kInto_m, 0.002, -0.004}, {1, 0, 0}, zero},
      // On the floor 1.5 mm from the +x wall: the push leans toward both faces (AutoCalibrator's
      // pushDirection); the wall lets the push's x part through, the floor blocks its z part.
      {"edge", {kFace_m - 1.5e-3, 0.002, -(kFace_m + kInto_m)}, diagonal, diagonal},
      {"edge_both", {kFace_m + kInto_m, -0.003, -(kFace_m + kInto_m)}, diagonal, diagonal},
      {"grazing_floor", {0.003, 0.004, -(kFace_m + kGrazing_m)}, {0, 0, -1}, zero},
      {"grazing_ceiling", {0.003, -0.002, kFace_m + kGrazing_m}, {0, 0, 1}, zero},
      {"grazing_wall", {0.001, kFace_m + kGrazing_m, 0.005}, {0, 1, 0}, zero},
  };
}

/// A free hold: `index` picks the friction, the face (or the edge of two faces), the depth
/// (1.5-5 mm from the stops, where AutoCalibrator watches a point) and the start error.
struct FreeCase {
  sim::FrictionLevel friction;
  Eigen::Vector3d offset_m;
  Eigen::Vector3d outward;
  Eigen::Vector3d push;
  Eigen::Vector3d start_error_n;
};

FreeCase freeCase(int index, sim::Random& random) {
  FreeCase c;
  c.friction = index % 2 == 0 ? sim::FrictionLevel::kTypical : sim::FrictionLevel::kHigh;
  auto uniform = [&](double low, double high) { return low + (high - low) * random.uniform(); };
  const int axis = (index / 2) % 3;
  const double sign = (index / 6) % 2 == 0 ? 1.0 : -1.0;
  const bool edge = (index / 12) % 3 == 0;  // a third of the holds at an edge
  for (int k = 0; k < 3; ++k) c.offset_m[k] = uniform(-0.03, 0.03);
  c.offset_m[axis] = sign * (kHalfWidth_m - uniform(1.5e-3, 5e-3));
  c.outward = Eigen::Vector3d::Zero();
  c.outward[axis] = sign;
  c.push = c.outward;
  if (edge) {
    const int other = (axis + 1 + (index / 36) % 2) % 3;
    const double other_sign = (index / 72) % 2 == 0 ? 1.0 : -1.0;
    c.offset_m[other] = other_sign * (kHalfWidth_m - uniform(1.5e-3, 5e-3));
    c.push[other] = other_sign;
    c.push.normalize();
  }
  for (int k = 0; k < 3; ++k) c.start_error_n[k] = uniform(-0.04, 0.04);
  return c;
}

EstimationParameters defaults() { return EstimationParameters{}; }

// Every way a stop can hold a watched hold, at stops of 1000 and 3000 N/m and both friction
// levels: the value is never taken with the stop's reaction in it. The held-still, creep and
// push rules share the catch (on this point mass the first two take most holds pressed into a
// face); a hold that rattles on a stiff wall without settling (grazing, 3000 N/m) ends
// kNoSteadyState, which AutoCalibrator answers by moving back (kBoundarySettle_s).
TEST(StopWatchTest, AHoldOnAFloorACeilingAWallAnEdgeOrGrazingIsNeverTakenWithTheStopsReaction) {
  const double eps_g_n = defaults().eps_g_n;
  for (const sim::FrictionLevel friction :
       {sim::FrictionLevel::kTypical, sim::FrictionLevel::kHigh}) {
    for (const double stop_n_per_m : {1000.0, 3000.0}) {
      for (const StopCase& c : stopCases()) {
        for (std::uint64_t seed = 1; seed <= 2; ++seed) {
          SCOPED_TRACE(::testing::Message() << c.name << ", " << stop_n_per_m << " N/m, "
                                            << sim::toString(friction) << ", seed " << seed);
          sim::PointMassDevice device = openBox(friction, stop_n_per_m, seed);
          const Eigen::Vector3d point_m = device.workspaceCenter_m() + c.offset_m;
          const Held held =
              hold(device, point_m, c.outward, c.push, Eigen::Vector3d(0.03, -0.02, 0.04));
          const double error_n = (held.gravity_n - device.trueGravity(point_m)).norm();
          EXPECT_TRUE(held.status != VertexEstimator::Status::kConverged || error_n < 2.0 * eps_g_n)
              << toString(held.status) << ", " << error_n << " N off";
          const bool pressed = c.offset_m.cwiseAbs().maxCoeff() > kHalfWidth_m;
          if (pressed) {
            EXPECT_TRUE(held.stop || held.status == VertexEstimator::Status::kUnreachable)
                << toString(held.status);
          }
        }
      }
    }
  }
}

// The push rule on its own: holds that the held-still and creep rules let converge. An edge
// whose floor holds the end-effector (pushed along the diagonal: the wall lets its x part
// through, 0.47-0.59 of the probe) and a floor or a ceiling that the dither grazes (the push
// follows by 0.22-0.32, the inward one by 0.97-1.07). Each ends against a stop, found by the
// push, with the estimate it began with.
TEST(StopWatchTest, ThePushTestCatchesAnEdgeAndAGrazedFloorOrCeilingThatConvergeOtherwise) {
  const Eigen::Vector3d diagonal = Eigen::Vector3d(1.0, 0.0, -1.0).normalized();
  const std::vector<StopCase> cases = {
      {"edge", {kFace_m - 1.5e-3, 0.002, -(kFace_m + 0.03e-3)}, diagonal, diagonal},
      {"grazing_floor",
       {0.003, 0.004, -(kFace_m + kGrazing_m)},
       {0, 0, -1},
       Eigen::Vector3d::Zero()},
      {"grazing_ceiling",
       {0.003, -0.002, kFace_m + kGrazing_m},
       {0, 0, 1},
       Eigen::Vector3d::Zero()},
  };
  for (const sim::FrictionLevel friction :
       {sim::FrictionLevel::kTypical, sim::FrictionLevel::kHigh}) {
    for (const double stop_n_per_m : {1000.0, 3000.0}) {
      for (const StopCase& c : cases) {
        SCOPED_TRACE(::testing::Message()
                     << c.name << ", " << stop_n_per_m << " N/m, " << sim::toString(friction));
        sim::PointMassDevice device = openBox(friction, stop_n_per_m, 1);
        const Eigen::Vector3d point_m = device.workspaceCenter_m() + c.offset_m;
        // A start 40 mN short of the truth toward the stop: eq. (12) then moves the estimate
        // toward it, by more than kPushTrigger eps_G once the stop's reaction adds.
        const Eigen::Vector3d push = (c.push.squaredNorm() > 0.0 ? c.push : c.outward).normalized();
        const Eigen::Vector3d start_error_n = Eigen::Vector3d(0.01, -0.02, 0.0) - 0.04 * push;
        const Eigen::Vector3d start_n = device.trueGravity(point_m) + start_error_n;
        const Held held = hold(device, point_m, c.outward, c.push, start_error_n);
        EXPECT_EQ(held.status, VertexEstimator::Status::kUnreachable);
        EXPECT_TRUE(held.stop);
        EXPECT_EQ(held.push_tests, 1);
        EXPECT_GT(held.contact_direction.dot(push), 0.999);
        EXPECT_LT((held.gravity_n - start_n).norm(), 1e-12);
      }
    }
  }
}

// 1000 free holds 1.5-5 mm from a face or an edge of the box, at typical and high friction,
// from start errors of up to 40 mN per axis, on 1000 seeds: not one is taken for a stop. The
// push test runs on 351 of them (the rest converge without their estimate moving toward the
// stop by kPushTrigger eps_G): they follow the outward push by 0.90-1.0 of it, sideways by at
// most 0.06. About 6 s in a release build.
TEST(StopWatchTest, AFreeHoldIsNeverTakenForAStopIn1000Holds) {
  sim::Random random(11);
  int stops = 0, pushes = 0, converged = 0;
  for (int index = 0; index < 1000; ++index) {
    const FreeCase c = freeCase(index, random);
    sim::PointMassDevice device =
        openBox(c.friction, 2000.0, 100 + static_cast<std::uint64_t>(index));
    const Eigen::Vector3d point_m = device.workspaceCenter_m() + c.offset_m;
    const Held held = hold(device, point_m, c.outward, c.push, c.start_error_n);
    pushes += held.push_tests;
    if (held.stop) {
      ++stops;
      ADD_FAILURE() << "hold " << index << " at " << c.offset_m.transpose()
                    << " m from the centre taken for a stop; pushed "
                    << held.outward_moved_m.transpose() << " m, back "
                    << held.inward_moved_m.transpose() << " m";
    }
    if (held.status == VertexEstimator::Status::kConverged) ++converged;
  }
  EXPECT_EQ(stops, 0);
  EXPECT_EQ(converged, 1000);
  EXPECT_GE(pushes, 300) << "the push test no longer runs on the free holds";
}

// The push test is part of the servo path: it allocates nothing either.
TEST(StopWatchTest, APushTestAllocatesNothing) {
  sim::PointMassDevice device = openBox(sim::FrictionLevel::kTypical, 2000.0, 3);
  const Eigen::Vector3d point_m =
      device.workspaceCenter_m() + Eigen::Vector3d(0.0, 0.0, -(kFace_m + kGrazing_m));
  device.resetState(point_m);
  VertexEstimator estimator(EstimationParameters{}, device.specifications().max_linear_force_n);
  estimator.start(point_m, device.trueGravity(point_m) + Eigen::Vector3d(0.03, -0.02, 0.04));
  estimator.setOutward(Eigen::Vector3d(0, 0, -1));
  testing::AllocationCounter counter;
  for (int tick = 0; tick < 60'000 && !estimator.finished(); ++tick) {
    Eigen::Vector3d force_n;
    estimator.step(readServoSample(device, kServo_s), force_n);
    device.setForce(force_n);
    device.advance(kServo_s);
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(estimator.finished());
  EXPECT_EQ(estimator.pushTests(), 1);
}

// Through AutoCalibrator: the explored cube lies 1.65 mm beyond the real stops (a probe presses
// into the rubber), so the plan's points next to the floor, the ceiling, a wall and an edge of
// the box stand 0.15 mm inside the stop. The whole 3 x 3 x 3 grid is calibrated (each point
// starts from its measured neighbours, as in a default calibration); the floor's, the
// ceiling's, a wall's and an edge's points are each found held (by whichever rule), moved back
// a millimetre from the stop and measured there within a few eps_G of the truth.
TEST(StopWatchTest, PointsOnTheFloorTheCeilingAWallAndAnEdgeAreMovedBackAndMeasuredClear) {
  sim::PointMassDevice device = openBox(sim::FrictionLevel::kTypical, 3000.0, 5);
  const Eigen::Vector3d centre_m = device.workspaceCenter_m();
  const double explored_m = kHalfWidth_m + kBoundaryMargin_m + kInto_m;
  const WorkspaceGrid grid(centre_m, 2.0 * explored_m, 3);
  const EstimationParameters parameters;
  AutoCalibrator calibrator(grid, parameters, device.specifications().max_linear_force_n);
  calibrator.setPlan(planMeasurements(grid, testing::probedCube(explored_m, centre_m)));
  const std::vector<int> visits = {grid.vertexIndex(1, 1, 0), grid.vertexIndex(1, 1, 2),
                                   grid.vertexIndex(2, 1, 1), grid.vertexIndex(2, 1, 0)};
  device.resetState(centre_m);
  calibrator.start(centre_m, device.trueGravity(centre_m));
  AutoCalibrator::Status status = AutoCalibrator::Status::kIdle;
  for (long tick = 0; tick < 2'000'000 && status != AutoCalibrator::Status::kFinished; ++tick) {
    Eigen::Vector3d force_n;
    status = calibrator.step(readServoSample(device, kServo_s), force_n);
    device.setForce(force_n);
    device.advance(kServo_s);
  }
  ASSERT_EQ(status, AutoCalibrator::Status::kFinished);
  EXPECT_GE(calibrator.stopRetreats(), 4);
  for (int index : visits) {
    const VertexEstimate& vertex = calibrator.vertices()[static_cast<std::size_t>(index)];
    SCOPED_TRACE(::testing::Message() << "vertex " << index);
    ASSERT_EQ(vertex.outcome, VertexOutcome::kConverged);
    const Eigen::Vector3d at_m = vertex.measuredAt_m(grid.vertexPosition(index));
    // Clear of every face by at least half the retreat.
    EXPECT_LT((at_m - centre_m).cwiseAbs().maxCoeff(),
              kHalfWidth_m - 0.5 * AutoCalibrator::kStopRetreat_m);
    EXPECT_LT((vertex.measuredGravity_n() - device.trueGravity(at_m)).norm(),
              3.0 * parameters.eps_g_n);
  }
}

}  // namespace
}  // namespace autograv
