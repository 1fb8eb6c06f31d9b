#pragma once

// The user's part of a calibration, played on the example's simulated device: on a real device
// a person does it with the end-effector in hand. Not part of what an application writes.

#include <autograv/wizard/wizard_types.h>

#include "point_mass_device.h"

namespace example {

/// What the wizard asks of a person, done by the PointMassDevice's simulated hand: in Centre it
/// carries the end-effector to the centre, holds it still and clicks the stylus button; in
/// Release it lets go once the spring field is on; afterwards it keeps its hand off.
class SimulatedUser {
 public:
  explicit SimulatedUser(PointMassDevice& device) : device_(device) {}
  /// Reacts to the wizard's latest status; call once per frame (CalibrateOptions::on_status).
  void act(const autograv::WizardStatus& status);

 private:
  PointMassDevice& device_;
};

}  // namespace example
