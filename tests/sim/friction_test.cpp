#include "autograv/sim/friction.h"

#include <cmath>

#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "autograv/error.h"

namespace autograv::sim {
namespace {

constexpr double kStep_s = 1e-4;  // the simulators' 10 kHz internal step

// One Cartesian axis: a 0.2 kg body on LuGre friction, 50 mN static, 35 mN Coulomb, 20 um of
// pre-sliding.
LuGreParameters axisParameters() {
  return makeLuGreParameters(Eigen::Vector3d::Constant(0.035), Eigen::Vector3d::Constant(0.050),
                             Eigen::Vector3d::Constant(0.002), Eigen::Vector3d::Constant(2e-5),
                             Eigen::Vector3d::Constant(0.2), 1.0, Eigen::Vector3d::Constant(0.02));
}

struct Body {
  explicit Body(const LuGreParameters& parameters) : friction(parameters) {}
  // Semi-implicit Euler, as the simulated mechanisms integrate.
  void step(const Eigen::Vector3d& force_n) {
    const Eigen::Vector3d friction_n = friction.step(velocity, kStep_s);
    velocity += kStep_s / kMass_kg * (force_n - friction_n);
    position += kStep_s * velocity;
  }
  static constexpr double kMass_kg = 0.2;
  LuGreFriction friction;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
};

TEST(FrictionLevel, NamesRoundTripAndUnknownNamesListTheValidOnes) {
  for (const auto& name : frictionLevelNames()) {
    EXPECT_EQ(name, toString(parseFrictionLevel(name)));
  }
  EXPECT_EQ(frictionLevelNames().size(), 4u);
  EXPECT_EQ(parseFrictionLevel("typical"), FrictionLevel::kTypical);
  try {
    parseFrictionLevel("sticky");
    FAIL() << "expected autograv::Error";
  } catch (const Error& error) {
    EXPECT_NE(std::string(error.what()).find("none, low, typical, high"), std::string::npos);
  }
  EXPECT_EQ(dryFrictionScale(FrictionLevel::kNone), 0.0);
  EXPECT_LT(dryFrictionScale(FrictionLevel::kLow), dryFrictionScale(FrictionLevel::kTypical));
  EXPECT_GT(dryFrictionScale(FrictionLevel::kHigh), dryFrictionScale(FrictionLevel::kTypical));
}

TEST(LuGreFriction, RejectsUnusableParameters) {
  LuGreParameters parameters = axisParameters();
  parameters.stiction[1] = 0.01;  // below Coulomb
  EXPECT_THROW(LuGreFriction{parameters}, Error);
  parameters = axisParameters();
  parameters.bristle_stiffness[2] = 0.0;
  EXPECT_THROW(LuGreFriction{parameters}, Error);
  parameters = axisParameters();
  parameters.stribeck_velocity[0] = -1.0;
  EXPECT_THROW(LuGreFriction{parameters}, Error);
}

TEST(LuGreFriction, SteadySlidingFollowsTheStribeckCurve) {
  LuGreFriction friction(axisParameters());
  const Eigen::Vector3d velocity(1e-4, 0.002, -0.05);  // m/s: well below, at, above vs
  Eigen::Vector3d force;
  for (int i = 0; i < 200000; ++i) force = friction.step(velocity, kStep_s);
  for (int j = 0; j < 3; ++j) {
    const double expected =
        std::copysign(friction.stribeckLevel(j, velocity[j]), velocity[j]) + 0.02 * velocity[j];
    EXPECT_NEAR(force[j], expected, 1e-9) << j;
  }
  EXPECT_NEAR(std::abs(force[2]), 0.035 + 0.02 * 0.05, 1e-6);  // Coulomb plus viscous
  EXPECT_NEAR(force[0], 0.050, 1e-3);                          // nearly the static level
}

TEST(LuGreFriction, StaysBoundedForAnyStepAndSpeed) {
  // The explicit Euler update of z diverges here (sigma0 |v| dt / g = 700); the exact one holds.
  LuGreFriction friction(axisParameters());
  const Eigen::Vector3d force = friction.step(Eigen::Vector3d(1.0, -3.0, 0.5), 0.01);
  for (int j = 0; j < 3; ++j) {
    EXPECT_LE(std::abs(friction.deflection()[j]), 2e-5 + 1e-12) << j;
    EXPECT_TRUE(std::isfinite(force[j]));
  }
}

TEST(LuGreFriction, ABodyUnderAForceBelowBreakawaySticksAfterPreSliding) {
  Body body(axisParameters());
  const Eigen::Vector3d force_n(0.035, -0.045, 0.0);   // 70 % and 90 % of the static level
  for (int i = 0; i < 20000; ++i) body.step(force_n);  // 2 s
  const Eigen::Vector3d after_2s = body.position;
  for (int i = 0; i < 20000; ++i) body.step(force_n);
  // Pre-sliding: a few bristle deflections (F / sigma0 = 14 and 18 um), then no more motion.
  EXPECT_GT(after_2s[0], 5e-6);
  EXPECT_LT(after_2s[0], 4e-5);
  EXPECT_LT(after_2s[1], -5e-6);
  EXPECT_GT(after_2s[1], -8e-5);
  EXPECT_EQ(body.position[2], 0.0);
  EXPECT_LT((body.position - after_2s).norm(), 1e-7);
  EXPECT_LT(body.velocity.norm(), 1e-6);

  // Letting go, the bristles spring part of the pre-sliding back (the rest stays: LuGre's
  // bristles relax while they unload, as a real contact's do).
  for (int i = 0; i < 20000; ++i) body.step(Eigen::Vector3d::Zero());
  EXPECT_LT(std::abs(body.position[0]), 0.7 * std::abs(after_2s[0]));
  EXPECT_LT(std::abs(body.position[1]), std::abs(after_2s[1]));
}

TEST(LuGreFriction, ABodyBreaksAwayAboveTheStaticLevelAndSlides) {
  Body body(axisParameters());
  const Eigen::Vector3d force_n(0.055, 0.0, -0.06);    // above the 50 mN static level
  for (int i = 0; i < 10000; ++i) body.step(force_n);  // 1 s
  EXPECT_GT(body.position[0], 0.01);
  EXPECT_LT(body.position[2], -0.01);
  EXPECT_EQ(body.position[1], 0.0);
}

TEST(LuGreFriction, ScaledToZeroLeavesOnlyTheViscousTerm) {
  LuGreFriction friction(axisParameters().scaledDry(0.0));
  const Eigen::Vector3d velocity(0.01, -0.02, 0.0);
  const Eigen::Vector3d force = friction.step(velocity, kStep_s);
  EXPECT_TRUE(force.isApprox(0.02 * velocity));
  Body body(axisParameters().scaledDry(0.0));
  body.step(Eigen::Vector3d(1e-3, 0.0, 0.0));
  EXPECT_GT(body.velocity[0], 0.0);  // the tiniest force moves it
}

TEST(LuGreFriction, StepAllocatesNothing) {
  LuGreFriction friction(axisParameters());
  const autograv::testing::AllocationCounter counter;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < 1000; ++i)
    sum += friction.step(Eigen::Vector3d(1e-3 * i, 0.0, -0.01), kStep_s);
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(sum.allFinite());
}

}  // namespace
}  // namespace autograv::sim
