// The paper's Section V experiment on the simulated Omega, with the paper's parameters.
#include <gtest/gtest.h>

#include "autograv/sim/paper_frame.h"
#include "autograv/sim/procedures.h"

namespace autograv {
namespace {

TEST(PaperExperimentTest, ConvergesToTheTrueApparentMassWithinTwoPercent) {
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    auto device = sim::makeSimulatedDevice("sim:omega", seed);
    ASSERT_TRUE(device->open());
    const sim::PaperExperimentResult result =
        sim::runPaperExperiment(*device, EstimationParameters::paper());
    ASSERT_TRUE(result.initialization.ok) << result.initialization.message;
    EXPECT_EQ(result.estimate.outcome, VertexOutcome::kConverged) << "seed " << seed;
    // The simulated Omega is built so that M(X_D) is the 214 g the paper measured; what holds its
    // unit 1 is that weight through its motors' gains, as a real unit's is (the paper's estimate
    // read 217 g).
    const double gain_bound = sim::actuatorGainBound("sim:omega", sim::ActuatorTolerance::kTypical);
    EXPECT_NEAR(result.mass_true_kg, sim::kPaperMeasuredMass_kg,
                gain_bound * sim::kPaperMeasuredMass_kg + 1e-3);
    const double mass_kg = result.estimate.gravity_n.norm() / kStandardGravity;
    EXPECT_LE(std::abs(mass_kg - result.mass_true_kg) / result.mass_true_kg, 0.02)
        << "seed " << seed;
    // n_G = 5 small updates need at least 6 iterations; the paper needed 14. At typical friction
    // (a 35-58 mN breakaway) the steady states scatter more: seeds 1-3 need 7, 13 and 22.
    EXPECT_GE(result.estimate.iterations, 6);
    EXPECT_LE(result.estimate.iterations, 30);
    // Fig. 8: the first steady-state error is the largest, the last ones are at encoder level.
    ASSERT_FALSE(result.estimate.history.empty());
    EXPECT_GT(result.estimate.history.front().position_error_m, 1e-3);
    EXPECT_LT(result.estimate.history.back().position_error_m, 5e-5);
  }
}

}  // namespace
}  // namespace autograv
