#pragma once

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "autograv/sim/simulated_device.h"

namespace autograv::testing {

/// Spring constants of the script's PD toward a moving target, and the lift that carries most of
/// the device's weight. Units: [N/m], [N s/m], [N]
struct ScriptGains {
  double stiffness_n_per_m;
  double damping_n_s_per_m;
  double lift_n;
};

/// 1.2 s of a scripted run on an open device: the hand carries the end-effector, lets go at
/// 0.4 s, and a PD follows a slow sine. Returns the true and the measured position of every tick,
/// for bit-for-bit determinism checks.
inline std::vector<Eigen::Vector3d> scriptedTrajectory(sim::SimulatedDevice& device,
                                                       const ScriptGains& gains) {
  constexpr double kServo_s = 0.001;
  std::vector<Eigen::Vector3d> trajectory;
  device.hand().grab(device.truePosition_m());
  device.hand().moveTo(Eigen::Vector3d(0.03, 0.02, -0.02), 0.05);
  for (int ms = 0; ms < 1200; ++ms) {
    if (ms == 400) device.hand().release();
    Eigen::Vector3d x, v;
    EXPECT_TRUE(device.getPosition(x));
    EXPECT_TRUE(device.getLinearVelocity(v));
    const Eigen::Vector3d target(0.02 * std::sin(ms * 0.005), 0.0, 0.01);
    device.setForce(gains.stiffness_n_per_m * (target - x) - gains.damping_n_s_per_m * v +
                    Eigen::Vector3d(0, 0, gains.lift_n));
    device.advance(kServo_s);
    trajectory.push_back(device.truePosition_m());
    trajectory.push_back(x);
  }
  return trajectory;
}

/// `same` must equal `reference` bit for bit, and `other_seed` must differ from it somewhere.
inline void expectSameSeedSameBitsOtherSeedDiffers(const std::vector<Eigen::Vector3d>& reference,
                                                   const std::vector<Eigen::Vector3d>& same,
                                                   const std::vector<Eigen::Vector3d>& other_seed) {
  bool identical = reference.size() == same.size(), differs = false;
  for (std::size_t i = 0; i < reference.size() && identical; ++i) {
    identical = (reference[i].array() == same[i].array()).all();
  }
  for (std::size_t i = 0; i < reference.size() && i < other_seed.size(); ++i) {
    differs = differs || (reference[i].array() != other_seed[i].array()).any();
  }
  EXPECT_TRUE(identical);
  EXPECT_TRUE(differs);
}

}  // namespace autograv::testing
