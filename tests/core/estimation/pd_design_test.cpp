#include "autograv/estimation/pd_design.h"

#include <gtest/gtest.h>

#include "autograv/error.h"

namespace autograv {
namespace {

// The paper (Sec. V) read alpha = 40, beta = 700 off its design plots for T_s = 200 ms, 5 %.
TEST(PdDesignTest, PaperExampleAlphaMatchesExactlyBetaWithinTwentyPercent) {
  const PdGains gains = designPdGains({0.2, 5.0});
  // zeta * omega_n = 4 / T_s = 20 1/s, so alpha = 40 1/s exactly, as in the paper.
  EXPECT_NEAR(gains.alpha_per_s, 40.0, 1e-9);
  // zeta(5 %) = 0.690 gives omega_n = 28.98 rad/s and beta = 840 1/s^2: 20 % above the paper's
  // 700, which is what a curve read by eye with 2.66 % overshoot instead of 5 % gives (below).
  EXPECT_NEAR(gains.beta_per_s2, 840.0, 1.0);
  const StepResponseSpec paper = analyzePdGains({40.0, 700.0});
  EXPECT_NEAR(paper.settling_time_s, 0.2, 1e-12);    // same envelope: T_s is met
  EXPECT_NEAR(paper.overshoot_percent, 2.66, 0.01);  // less overshoot than asked: safe side
}

TEST(PdDesignTest, DesignAndAnalysisAreInverse) {
  for (double settling : {0.1, 0.2, 0.5}) {
    for (double overshoot : {1.0, 5.0, 20.0}) {
      const StepResponseSpec spec = analyzePdGains(designPdGains({settling, overshoot}));
      EXPECT_NEAR(spec.settling_time_s, settling, 1e-9);
      EXPECT_NEAR(spec.overshoot_percent, overshoot, 1e-9);
    }
  }
}

TEST(PdDesignTest, SimulatedStepResponseMeetsTheSpec) {
  // The classic T_s = 4 / (zeta omega_n) rule (the one that gives the paper's alpha = 40) is an
  // approximation: the true 2 % settling time of the designed loop is 0.207 s (+3.4 %), the
  // paper's (40, 700) settle in 0.215 s (+7.4 %). The overshoot is exact.
  const PdGains gains = designPdGains({0.2, 5.0});
  const StepResponseSpec simulated = simulateStepResponse(gains);
  EXPECT_NEAR(simulated.overshoot_percent, 5.0, 0.01);
  EXPECT_NEAR(simulated.settling_time_s, 0.207, 0.001);
  const StepResponseSpec paper = simulateStepResponse({40.0, 700.0});
  EXPECT_NEAR(paper.overshoot_percent, 2.66, 0.01);
  EXPECT_NEAR(paper.settling_time_s, 0.215, 0.001);
}

TEST(PdDesignTest, RejectsImpossibleSpecs) {
  EXPECT_THROW(designPdGains({0.0, 5.0}), Error);
  EXPECT_THROW(designPdGains({0.2, 0.0}), Error);
  EXPECT_THROW(designPdGains({0.2, 100.0}), Error);
  EXPECT_THROW(analyzePdGains({-1.0, 700.0}), Error);
}

TEST(PdDesignTest, ConvergenceCheckNamesTheBetaToUse) {
  // Omega at the paper's point: |G| = 2.1 N; c = 20 N/m needs beta >= 2*20*9.81/2.1 = 187.
  EXPECT_TRUE(checkConvergence(700.0, 2.1, 20.0).ok);
  const FeasibilityCheck check = checkConvergence(100.0, 2.1, 20.0);
  EXPECT_FALSE(check.ok);
  EXPECT_NE(check.message.find("raise beta to at least 187"), std::string::npos) << check.message;
}

TEST(PdDesignTest, SaturationCheckNamesTheCellSizeAndBetaToUse) {
  // K_P = 700 * 2.1 / 9.81 = 149.8 N/m; over a 20 mm cell 3.0 N + 2.1 N = 5.1 N < 0.9 * 12 N.
  EXPECT_TRUE(checkSaturation(700.0, 2.1, 0.02, 12.0).ok);
  // Omni-like: |G| = 1 N, 3.3 N limit, 40 mm cells: 71.4 * 0.04 + 1 = 3.85 N > 2.97 N.
  const FeasibilityCheck check = checkSaturation(700.0, 1.0, 0.04, 3.3);
  EXPECT_FALSE(check.ok);
  EXPECT_NE(check.message.find("at most 27.6"), std::string::npos) << check.message;
  EXPECT_NE(check.message.find("lower EstimationParameters::beta_per_s2 to at most 483"),
            std::string::npos)
      << check.message;
}

}  // namespace
}  // namespace autograv
