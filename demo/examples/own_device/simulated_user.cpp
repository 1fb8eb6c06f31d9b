#include "simulated_user.h"

namespace example {

namespace {
/// Slower than this, the end-effector counts as held still (the wizard asks for 20 mm/s at
/// most before it takes the centre). Unit: [m/s]
constexpr double kStill_m_per_s = 0.01;
}  // namespace

void SimulatedUser::act(const autograv::WizardStatus& status) {
  using autograv::WizardStep;
  if (device_.buttonPressed()) {
    device_.setButton(false);  // a click: down for one frame, up the next
    return;
  }
  switch (status.step) {
    case WizardStep::kCentre:
      if (!device_.handHolding()) {
        device_.grab();
        device_.moveHandTo(status.centre_m);
      } else if (device_.handArrived() && status.within_tolerance &&
                 status.speed_m_per_s < kStill_m_per_s) {
        device_.setButton(true);
      }
      return;
    case WizardStep::kRelease:
      if (device_.handHolding() &&
          status.release_status != autograv::InitializationEstimator::Status::kRampingIn) {
        device_.release();
      }
      return;
    default:
      if (device_.handHolding()) device_.release();
      return;
  }
}

}  // namespace example
