#pragma once

#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

/// Tells whether the end-effector rested on an end stop while a manual initialization (paper
/// eq. 7) settled: then X_inf is where the stop put it, not the k0 field, and G_hat_0 is wrong.
/// Call update() once per servo tick, on the thread that advances the simulation, with whether
/// the initialization's release phase (hand off, k0 field on) is running. The simulator's contact
/// flag, no driver's: for scoring only (what the wizard's own check,
/// initializationClearanceProblem, should have caught). Real-time safe.
class InitializationEndStopWatch {
 public:
  /// Returns true once, on the tick the release phase ends, when the stop was touched during it.
  bool update(bool releasing, SimulatedDevice& device) noexcept {
    bool hit = false;
    // Where the hand carried the end-effector does not matter; where it settles does.
    if (releasing && !was_releasing_) {
      device.clearEndStopHit();
    } else if (!releasing && was_releasing_) {
      hit = device.endStopHit();
    }
    was_releasing_ = releasing;
    return hit;
  }

 private:
  bool was_releasing_ = false;
};

}  // namespace autograv::sim
