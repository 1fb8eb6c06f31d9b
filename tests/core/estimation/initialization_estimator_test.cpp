#include "autograv/estimation/initialization_estimator.h"

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"
#include "ideal_point_mass.h"

namespace autograv {
namespace {

constexpr double kPeriod = 1e-3;

TEST(InitializationEstimatorTest, SpringSagGivesEquation7) {
  testing::IdealPointMass device;
  device.gradient_n_per_m.setZero();  // uniform field: eq. (7) is then exact
  EstimationParameters parameters;    // k0 = 0.5 N/mm
  InitializationEstimator estimator(parameters, 12.0);
  estimator.start(device.position_m);
  InitializationEstimator::Status status = InitializationEstimator::Status::kRampingIn;
  Eigen::Vector3d force;
  for (int tick = 0; tick < 20000 && status != InitializationEstimator::Status::kDone; ++tick) {
    status = estimator.step(device.sample(), force);
    device.advance(force, kPeriod);
  }
  ASSERT_EQ(status, InitializationEstimator::Status::kDone);
  EXPECT_LT((estimator.gravityEstimate_n() - device.gravity_at_origin_n).norm(), 2e-3);
  // The sag is |G| / k0 = 2.13 N / 500 N/m = 4.3 mm.
  EXPECT_NEAR(estimator.sag_m(), device.gravity_at_origin_n.norm() / 500.0, 1e-4);
}

TEST(InitializationEstimatorTest, AHandThatNeverLetsGoIsReported) {
  EstimationParameters parameters;
  InitializationEstimator estimator(parameters, 12.0);
  estimator.start(Eigen::Vector3d::Zero());
  // The hand holds the end-effector exactly at the centre: no sag, so no estimate.
  const ServoSample held{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), true};
  bool reported = false;
  Eigen::Vector3d force;
  for (int tick = 0; tick < 5000; ++tick) {
    const auto status = estimator.step(held, force);
    EXPECT_NE(status, InitializationEstimator::Status::kDone);
    reported |= status == InitializationEstimator::Status::kStillHeld;
  }
  EXPECT_TRUE(reported);
}

TEST(InitializationEstimatorTest, FieldIsRampedIn) {
  EstimationParameters parameters;
  InitializationEstimator estimator(parameters, 12.0, 0.3);
  estimator.start(Eigen::Vector3d::Zero());
  const ServoSample offset{Eigen::Vector3d(0, 0, -0.004), Eigen::Vector3d::Zero(), true};
  Eigen::Vector3d force;
  EXPECT_EQ(estimator.step(offset, force), InitializationEstimator::Status::kRampingIn);
  EXPECT_NEAR(force.z(), 500.0 * 0.004 / 300.0, 1e-9);  // 1/300 of the field after one tick
  for (int tick = 0; tick < 299; ++tick) estimator.step(offset, force);
  EXPECT_NEAR(force.z(), 2.0, 1e-9);
}

TEST(InitializationEstimatorTest, DeadDeviceIsAFaultAndStepAllocatesNothing) {
  InitializationEstimator estimator(EstimationParameters{}, 12.0);
  estimator.start(Eigen::Vector3d::Zero());
  Eigen::Vector3d force;
  testing::AllocationCounter counter;
  InitializationEstimator::Status status = InitializationEstimator::Status::kWaiting;
  for (int tick = 0; tick < 100; ++tick) status = estimator.step(ServoSample{}, force);
  EXPECT_EQ(status, InitializationEstimator::Status::kDeviceFault);
  EXPECT_EQ(force, Eigen::Vector3d::Zero());
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_THROW(InitializationEstimator(EstimationParameters{}, 0.0), Error);
}

}  // namespace
}  // namespace autograv
