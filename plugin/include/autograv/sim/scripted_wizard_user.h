#pragma once

// The simulated user of `autograv wizard --auto-hand` and of the wizard's tests: it does the
// manual step of the paper's Sec. III-A the way a person does, reacting to what the wizard shows.

#include "autograv/sim/simulated_device.h"
#include "autograv/wizard/wizard_types.h"

namespace autograv::sim {

/// A scripted user of CalibrationWizard on a simulated device: in Centre its hand carries the
/// end-effector to the centre, holds it still and presses the stylus button; in Release it lets
/// go once the spring field is fully on; afterwards it keeps its hand off.
class ScriptedWizardUser {
 public:
  /// `speed_m_per_s`: how fast the hand carries the end-effector; `hold_still_s`: how long it
  /// holds still at the centre before pressing the stylus button. Units: [m/s], [s]
  explicit ScriptedWizardUser(SimulatedDevice& device, double speed_m_per_s = 0.05,
                              double hold_still_s = 0.5)
      : device_(device), speed_m_per_s_(speed_m_per_s), hold_still_s_(hold_still_s) {}

  /// Reacts to the wizard's latest status; call once per UI frame. Not real-time safe.
  void update(const WizardStatus& status);

  /// Stylus button presses so far.
  int presses() const noexcept { return presses_; }

 private:
  SimulatedDevice& device_;
  double speed_m_per_s_;
  double hold_still_s_;
  double arrived_s_ = -1.0;
  double next_press_s_ = 0.0;
  bool switch_down_ = false;
  int presses_ = 0;
};

}  // namespace autograv::sim
