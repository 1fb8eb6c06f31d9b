#pragma once
// The user switches of a simulated device as CHAI3D packs them: bit i set while switch i is
// pressed. Shared by the stand-in's simulated device and its hardware stand-in.
#include "autograv/sim/simulated_device.h"
#include "chai3d.h"

namespace autograv::chai3d_mock {

/// Switches 0-3 of `simulation` into `bits`; C_ERROR when the simulation does not answer.
inline bool readSwitchBits(autograv::sim::SimulatedDevice& simulation, unsigned int& bits) {
  bits = 0;
  for (int index = 0; index < 4; ++index) {
    bool pressed = false;
    if (!simulation.getUserSwitch(index, pressed)) return ::chai3d::C_ERROR;
    if (pressed) bits |= 1u << index;
  }
  return ::chai3d::C_SUCCESS;
}

}  // namespace autograv::chai3d_mock
