#include "autograv/sim/scripted_wizard_user.h"

#include "autograv/estimation/initialization_estimator.h"
#include "autograv/sim/simulated_hand.h"

namespace autograv::sim {

void ScriptedWizardUser::update(const WizardStatus& status) {
  SimulatedHand& hand = device_.hand();
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
      if (hand.holding() && status.release_status != InitializationEstimator::Status::kRampingIn) {
        hand.release();
      }
      break;
    default:
      if (hand.holding() && status.step != WizardStep::kCheck) hand.release();
      break;
  }
}

}  // namespace autograv::sim
