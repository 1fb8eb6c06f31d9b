#include "core/estimation/vertex_estimator.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "ideal_point_mass.h"

namespace autograv {
namespace {

constexpr double kPeriod = 1e-3;

VertexEstimator::Status runToEnd(VertexEstimator& estimator, testing::IdealPointMass& device,
                                 long max_ticks = 200000) {
  VertexEstimator::Status status = VertexEstimator::Status::kSettling;
  for (long tick = 0; tick < max_ticks && !estimator.finished(); ++tick) {
    Eigen::Vector3d force;
    status = estimator.step(device.sample(), force);
    device.advance(force, kPeriod);
  }
  return status;
}

TEST(VertexEstimatorTest, ConvergesToTheApparentGravityAtTheVertex) {
  testing::IdealPointMass device;
  device.position_m = Eigen::Vector3d(0.0116, -0.0092, -0.0683) - Eigen::Vector3d(0, 0, -0.03);
  EstimationParameters parameters = EstimationParameters::paper();
  VertexEstimator estimator(parameters, 12.0);
  const Eigen::Vector3d vertex(0.0, 0.0, 0.0);
  // A 40 % wrong initial estimate, as a coarse eq. (7) might give.
  estimator.start(vertex, 0.6 * device.gravity(vertex));
  EXPECT_EQ(runToEnd(estimator, device), VertexEstimator::Status::kConverged);
  const VertexEstimate& result = estimator.estimate();
  EXPECT_EQ(result.outcome, VertexOutcome::kConverged);
  // Noise-free, the fixed point of eq. (12) is G(X_D); the stop rule leaves < eps_G.
  EXPECT_LT((result.gravity_n - device.gravity(vertex)).norm(), parameters.eps_g_n);
  EXPECT_GE(result.iterations, parameters.n_g + 1);
  ASSERT_EQ(static_cast<int>(result.history.size()), result.iterations);
  // Delta_j shrinks geometrically (paper Sec. IV): each error below the first.
  EXPECT_LT(result.history.back().position_error_m,
            1e-3 * result.history.front().position_error_m + 1e-9);
  EXPECT_NEAR(result.history.back().mass_estimate_kg, device.gravity(vertex).norm() / 9.81, 1e-3);
  for (const auto& record : result.history)
    EXPECT_GE(record.duration_s, parameters.min_step_duration_s - 1e-9);
}

TEST(VertexEstimatorTest, EachUpdateFollowsEquation12) {
  testing::IdealPointMass device;
  EstimationParameters parameters = EstimationParameters::paper();
  VertexEstimator estimator(parameters, 12.0);
  const Eigen::Vector3d vertex(0.01, 0.0, 0.0);
  const Eigen::Vector3d initial = device.gravity(vertex) + Eigen::Vector3d(0.2, 0.0, -0.3);
  estimator.start(vertex, initial);
  Eigen::Vector3d force;
  while (estimator.step(device.sample(), force) != VertexEstimator::Status::kUpdated) {
    device.advance(force, kPeriod);
  }
  // At the steady state of iteration 0 the PD force balances gravity: G_hat_1 = G(X_inf).
  const IterationRecord& first = estimator.estimate().history.front();
  EXPECT_LT((first.gravity_estimate_n - device.gravity(device.position_m)).norm(), 2e-3);
  // ... and X_inf is offset by (G - G_hat_0) / K_P with K_P = beta |G_hat_0| / g (eq. 11).
  const double stiffness = parameters.beta_per_s2 * initial.norm() / 9.81;
  EXPECT_NEAR(first.position_error_m,
              (device.gravity(device.position_m) - initial).norm() / stiffness, 2e-5);
}

TEST(VertexEstimatorTest, ConvergesWhereTheFieldChangesFasterThanTheHoldIsStiff) {
  // dG_x/dx = -0.6 K_P: eq. (12)'s steps reverse and grow by half each time (ratio
  // -0.6 / (1 - 0.6) = -1.5), as near a singular pose of a parallel arm. Relaxed, they converge.
  for (const EstimationParameters& parameters :
       {EstimationParameters{}, EstimationParameters::paper()}) {
    testing::IdealPointMass device;
    const double stiffness =
        parameters.beta_per_s2 * device.gravity_at_origin_n.norm() / kStandardGravity;
    device.gradient_n_per_m.setZero();
    device.gradient_n_per_m(0, 0) = -0.6 * stiffness;
    const Eigen::Vector3d vertex = Eigen::Vector3d::Zero();
    VertexEstimator estimator(parameters, 12.0, 12.0);
    estimator.start(vertex, device.gravity(vertex) + Eigen::Vector3d(0.15, 0.0, 0.0));
    EXPECT_EQ(runToEnd(estimator, device), VertexEstimator::Status::kConverged)
        << toString(parameters.method);
    EXPECT_LT((estimator.estimate().gravity_n - device.gravity(vertex)).norm(),
              2.0 * parameters.eps_g_n)
        << toString(parameters.method);
    EXPECT_LE(estimator.estimate().iterations, 12) << toString(parameters.method);
  }
}

TEST(VertexEstimatorTest, AStopIsRecognisedFromTheForceGrowingWhileThePositionStays) {
  // The vertex lies 1.5 mm beyond a stop along +x: each step of eq. (12) pushes harder into it.
  testing::IdealPointMass device;
  device.wall_x_m = -0.0015;
  const Eigen::Vector3d vertex = Eigen::Vector3d::Zero();
  device.position_m = Eigen::Vector3d(-0.01, 0.0, 0.0);
  VertexEstimator estimator(EstimationParameters{}, 12.0, 12.0);
  estimator.start(vertex, device.gravity(vertex));
  EXPECT_EQ(runToEnd(estimator, device), VertexEstimator::Status::kUnreachable);
  EXPECT_TRUE(estimator.stopContact());
  EXPECT_GT(estimator.contactDirection().x(), 0.95);  // into the stop
  EXPECT_NEAR(estimator.contactPosition_m().x(), device.wall_x_m, 5e-4);
  EXPECT_LE(estimator.estimate().iterations, 6);
  // The last two pushes are taken back: the estimate is the one before them, nearer G than what
  // eq. (12) had reached against the stop.
  EXPECT_EQ(estimator.estimate().gravity_n, estimator.gravityBeforeContact_n());
  const Eigen::Vector3d truth = device.gravity(device.position_m);
  EXPECT_LT((estimator.gravityBeforeContact_n() - truth).norm(),
            (estimator.estimate().history.back().gravity_estimate_n - truth).norm());

  // In free space, and where friction leaves a vertex short of X_i, no contact is reported.
  testing::IdealPointMass free_device;
  free_device.static_friction_n = 0.05;
  free_device.coulomb_friction_n = 0.03;
  VertexEstimator free_estimator(EstimationParameters{}, 12.0, 12.0);
  free_estimator.start(vertex, 0.8 * free_device.gravity(vertex));
  EXPECT_EQ(runToEnd(free_estimator, free_device), VertexEstimator::Status::kConverged);
  EXPECT_FALSE(free_estimator.stopContact());
}

TEST(VertexEstimatorTest, StopsAtTheIterationCapAndKeepsTheEstimate) {
  testing::IdealPointMass device;
  EstimationParameters parameters = EstimationParameters::paper();
  parameters.max_iterations = 6;
  parameters.eps_g_n = 1e-9;  // unreachable
  VertexEstimator estimator(parameters, 12.0);
  estimator.start(Eigen::Vector3d::Zero(), 0.5 * device.gravity(Eigen::Vector3d::Zero()));
  EXPECT_EQ(runToEnd(estimator, device), VertexEstimator::Status::kIterationCap);
  EXPECT_EQ(estimator.estimate().outcome, VertexOutcome::kIterationCap);
  EXPECT_EQ(estimator.estimate().iterations, 6);
  EXPECT_LT((estimator.estimate().gravity_n - device.gravity(Eigen::Vector3d::Zero())).norm(),
            0.01);
}

TEST(VertexEstimatorTest, DeviceThatStopsAnsweringEndsTheVertexWithZeroForce) {
  testing::IdealPointMass device;
  VertexEstimator estimator(EstimationParameters{}, 12.0);
  estimator.start(Eigen::Vector3d::Zero(), device.gravity(Eigen::Vector3d::Zero()));
  Eigen::Vector3d force;
  for (int k = 0; k < 50; ++k) {
    estimator.step(device.sample(), force);
    device.advance(force, kPeriod);
  }
  const Eigen::Vector3d held = force;
  ServoSample dead;  // valid = false
  EXPECT_EQ(estimator.step(dead, force), VertexEstimator::Status::kSettling);
  EXPECT_EQ(force, held);  // rides over a short dropout with the last force
  VertexEstimator::Status status = VertexEstimator::Status::kSettling;
  for (int k = 0; k < 30 && status == VertexEstimator::Status::kSettling; ++k) {
    status = estimator.step(dead, force);
  }
  EXPECT_EQ(status, VertexEstimator::Status::kDeviceFault);
  EXPECT_EQ(force, Eigen::Vector3d::Zero());
  EXPECT_EQ(estimator.estimate().outcome, VertexOutcome::kDeviceFault);
}

TEST(VertexEstimatorTest, PersistentSaturationIsReported) {
  testing::IdealPointMass device;
  device.gravity_at_origin_n = Eigen::Vector3d(0, 0, -5.0);
  VertexEstimator estimator(EstimationParameters{}, 3.0);  // cannot hold 5 N
  estimator.start(Eigen::Vector3d::Zero(), device.gravity(Eigen::Vector3d::Zero()));
  EXPECT_EQ(runToEnd(estimator, device, 5000), VertexEstimator::Status::kUnreachable);
  EXPECT_EQ(estimator.estimate().outcome, VertexOutcome::kUnreachable);
}

TEST(VertexEstimatorTest, ZeroInitialEstimateStillGivesAControllableLoop) {
  // Constraint (6): |G_hat| = 0 would give zero gains; the floor keeps the loop alive.
  testing::IdealPointMass device;
  VertexEstimator estimator(EstimationParameters{}, 12.0);
  Eigen::Vector3d force;
  estimator.start(Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  estimator.step(device.sample(), force);
  EXPECT_GT(estimator.stiffness_n_per_m(), 0.0);
}

// Dry friction on every axis: 60 mN to break away, 45 mN while sliding; |G| is about 2.1 N.
testing::IdealPointMass stickyPointMass() {
  testing::IdealPointMass device;
  device.static_friction_n = 0.060;
  device.coulomb_friction_n = 0.045;
  device.position_m = Eigen::Vector3d(0.004, -0.003, 0.005);
  return device;
}

double estimationError_n(const EstimationParameters& parameters, const Eigen::Vector3d& bias_n) {
  testing::IdealPointMass device = stickyPointMass();
  VertexEstimator estimator(parameters, 12.0);
  const Eigen::Vector3d vertex = Eigen::Vector3d::Zero();
  estimator.start(vertex, device.gravity(vertex) + bias_n);
  runToEnd(estimator, device);
  EXPECT_TRUE(estimator.finished());
  return (estimator.estimate().gravity_n - device.gravity(vertex)).norm();
}

TEST(VertexEstimatorTest, PaperMethodStopsAnywhereInTheFrictionDeadBand) {
  // Started 50 mN off, the paper's rule settles at once inside the dead band: eq. (12) keeps
  // the error, which only friction bounds.
  const EstimationParameters paper = EstimationParameters::paper();
  EXPECT_GT(estimationError_n(paper, Eigen::Vector3d(0.0, 0.03, -0.04)), 0.02);
}

TEST(VertexEstimatorTest, DitherMethodMeasuresBelowTheFriction) {
  const EstimationParameters dither = EstimationParameters{};
  for (const Eigen::Vector3d& bias_n :
       {Eigen::Vector3d(0.0, 0.03, -0.04), Eigen::Vector3d(-0.05, 0.0, 0.05),
        Eigen::Vector3d(0.3, -0.2, 0.4)}) {
    // A sixth of the breakaway force, whatever side the estimate started from.
    EXPECT_LT(estimationError_n(dither, bias_n), 0.010) << bias_n.transpose();
  }
}

TEST(VertexEstimatorTest, DitherIsZeroMeanOverEachWindowAndHalfWaveSymmetric) {
  testing::IdealPointMass device;
  const EstimationParameters parameters = EstimationParameters{};
  VertexEstimator estimator(parameters, 12.0, 12.0);  // a continuous rating that leaves room
  const Eigen::Vector3d vertex = Eigen::Vector3d::Zero();
  estimator.start(vertex, device.gravity(vertex));
  EXPECT_NEAR(estimator.ditherAmplitude_n(), EstimationParameters::kAutoDitherFraction * 12.0,
              1e-12);
  EXPECT_NEAR(estimator.ditherAmplitude_n(), 1.08, 1e-12);
  // Held exactly at the vertex with zero velocity, the force is G_hat plus the dither alone.
  const ServoSample at_vertex{vertex, Eigen::Vector3d::Zero(), true};
  const int period_ticks = 50;  // 20 Hz at 1 kHz
  std::vector<Eigen::Vector3d> dither;
  for (int tick = 0; tick < 2 * period_ticks; ++tick) {
    Eigen::Vector3d force;
    estimator.step(at_vertex, force);
    dither.push_back(force - device.gravity(vertex));
  }
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& d : dither) sum += d;
  EXPECT_LT(sum.norm() / dither.size(), 1e-9);
  for (int tick = 0; tick < period_ticks / 2; ++tick) {
    EXPECT_TRUE((dither[tick] + dither[tick + period_ticks / 2]).isZero(1e-9)) << tick;
  }
  double smallest_peak = 1e9;
  for (int axis = 0; axis < 3; ++axis) {
    double peak = 0.0;
    for (const auto& d : dither) peak = std::max(peak, std::abs(d[axis]));
    smallest_peak = std::min(smallest_peak, peak);
  }
  EXPECT_GT(smallest_peak, 0.9 * estimator.ditherAmplitude_n());  // every axis is driven
}

TEST(VertexEstimatorTest, AutomaticDitherKeepsWithinTheContinuousRating) {
  // sim:omega-like: 12 N peak, 3 N continuous (a quarter of the peak), |G| 1.9 N.
  const double amplitude_n = VertexEstimator::automaticDitherAmplitude_n(12.0, 3.0, 1.9);
  EXPECT_NEAR(amplitude_n, (0.95 * 3.0 - 1.9) / std::sqrt(2.0), 1e-12);
  EXPECT_LE(1.9 + std::sqrt(2.0) * amplitude_n, 3.0);
  // Plenty of room: the largest amplitude. No room at all: the smallest that still breaks the
  // friction, not zero.
  EXPECT_NEAR(VertexEstimator::automaticDitherAmplitude_n(12.0, 12.0, 2.1), 1.08, 1e-12);
  EXPECT_NEAR(VertexEstimator::automaticDitherAmplitude_n(12.0, 3.0, 2.9),
              EstimationParameters::kMinAutoDither_n, 1e-12);
  // A device so weak that the floor is above the largest amplitude: the largest.
  EXPECT_NEAR(VertexEstimator::automaticDitherAmplitude_n(2.0, 0.5, 0.4), 0.18, 1e-12);

  // The estimator picks it per vertex, from the estimate it starts with; 0 for the rating takes
  // kDefaultContinuousForceFraction of the peak.
  testing::IdealPointMass device;
  const Eigen::Vector3d vertex = Eigen::Vector3d::Zero();
  const double gravity_n = device.gravity(vertex).norm();
  VertexEstimator estimator(EstimationParameters{}, 12.0);
  estimator.start(vertex, device.gravity(vertex));
  EXPECT_NEAR(estimator.ditherAmplitude_n(),
              VertexEstimator::automaticDitherAmplitude_n(12.0, 3.0, gravity_n), 1e-12);
  // An amplitude asked for is kept as it is.
  EstimationParameters fixed;
  fixed.dither_amplitude_n = 0.2;
  VertexEstimator fixed_estimator(fixed, 12.0, 3.0);
  fixed_estimator.start(vertex, device.gravity(vertex));
  EXPECT_EQ(fixed_estimator.ditherAmplitude_n(), 0.2);
  EXPECT_THROW(VertexEstimator(EstimationParameters{}, 12.0, -1.0), Error);
}

void stepsWithoutAllocating(const EstimationParameters& parameters) {
  testing::IdealPointMass device = stickyPointMass();
  VertexEstimator estimator(parameters, 12.0);
  estimator.start(Eigen::Vector3d::Zero(), 0.7 * device.gravity(Eigen::Vector3d::Zero()));
  Eigen::Vector3d force;
  testing::AllocationCounter counter;
  for (int tick = 0; tick < 20000 && !estimator.finished(); ++tick) {
    estimator.step(device.sample(), force);
    device.advance(force, kPeriod);
  }
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(estimator.finished());
}

TEST(VertexEstimatorTest, StepAllocatesNothingWithEitherMethod) {
  for (const EstimationParameters& parameters :
       {EstimationParameters::paper(), EstimationParameters{}}) {
    SCOPED_TRACE(toString(parameters.method));
    stepsWithoutAllocating(parameters);
  }
}

TEST(VertexEstimatorTest, RejectsBadParameters) {
  EstimationParameters parameters = EstimationParameters::paper();
  parameters.beta_per_s2 = -1.0;
  EXPECT_THROW(VertexEstimator(parameters, 12.0), Error);
  EXPECT_THROW(VertexEstimator(EstimationParameters{}, 0.0), Error);
  EstimationParameters loud = EstimationParameters{};
  loud.dither_amplitude_n = 7.0;  // more than half of a 12 N device
  EXPECT_THROW(VertexEstimator(loud, 12.0), Error);
  EstimationParameters fast = EstimationParameters{};
  fast.dither_frequency_hz = 400.0;  // under 4 samples per period at 1 kHz
  EXPECT_THROW(VertexEstimator(fast, 12.0), Error);
}

}  // namespace
}  // namespace autograv
