#pragma once

// The simulated user of `autograv wizard --auto-hand` (and of the wizard's tests): it does the
// manual step of the paper's Sec. III-A the way a person does, reacting to what the wizard shows.
// Header-only so that tests can use the very same script.

#include <Eigen/Core>

#include "autograv/sim/simulated_device.h"
#include "autograv/wizard/calibration_wizard.h"

namespace autograv::cli {

class WizardAutoHand {
 public:
  /// `speed_m_per_s`: how fast the hand carries the end-effector; `hold_still_s`: how long it
  /// holds still at the centre before pressing the stylus button. Units: [m/s], [s]
  explicit WizardAutoHand(sim::SimulatedDevice& device, double speed_m_per_s = 0.05,
                          double hold_still_s = 0.5)
      : device_(device), speed_m_per_s_(speed_m_per_s), hold_still_s_(hold_still_s) {}

  /// Reacts to the wizard's latest status; call once per UI frame. Not real-time safe.
  void update(const WizardStatus& status) {
    sim::SimulatedHand& hand = device_.hand();
    const double now_s = device_.time_s();
    if (switch_down_) {  // a press lasts one frame: the wizard sees the rising edge
      device_.setUserSwitch(0, false);
      switch_down_ = false;
    }
    switch (status.step) {
      case WizardStep::kCentre:
        if (!hand.holding()) {
          hand.grab(device_.truePosition_m());
          arrived_s_ = -1.0;
        }
        hand.moveTo(status.centre_m, speed_m_per_s_);
        if (!hand.atGoal()) {
          arrived_s_ = -1.0;
        } else if (arrived_s_ < 0.0) {
          arrived_s_ = now_s;
        } else if (now_s - arrived_s_ >= hold_still_s_ && now_s >= next_press_s_) {
          device_.setUserSwitch(0, true);
          switch_down_ = true;
          ++presses_;
          next_press_s_ = now_s + 1.0;  // press again later if the wizard did not take it
        }
        break;
      case WizardStep::kRelease:
        // Let go once the field is fully on, as the prompt asks.
        if (hand.holding() &&
            status.release_status != InitializationEstimator::Status::kRampingIn) {
          hand.release();
        }
        break;
      default:
        if (hand.holding() && status.step != WizardStep::kCheck) hand.release();
        break;
    }
  }

  /// Stylus button presses so far.
  int presses() const noexcept { return presses_; }

 private:
  sim::SimulatedDevice& device_;
  double speed_m_per_s_;
  double hold_still_s_;
  double arrived_s_ = -1.0;
  double next_press_s_ = 0.0;
  bool switch_down_ = false;
  int presses_ = 0;
};

}  // namespace autograv::cli
