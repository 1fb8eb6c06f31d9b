#pragma once

#include <Eigen/Core>

#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

/// The driver of a simulated preset: amplifiers of `motor_limit` per motor ([N] or [N m])
/// through a `dac_bits` DAC, and a velocity estimated over `velocity_window_s` ([s]). The encoder
/// noise (0.05 counts, correlated over 10 ms) and the 1 ms low-pass on the velocity are the same
/// on every preset, so that a preset differs from another only by what its device does.
inline DriverParameters presetDriver(double motor_limit, int dac_bits, double velocity_window_s) {
  DriverParameters driver;
  driver.motor_limit = Eigen::Vector3d::Constant(motor_limit);
  driver.dac_bits = dac_bits;
  driver.velocity_window_s = velocity_window_s;
  driver.velocity_time_constant_s = 0.001;
  driver.noise_sigma_counts = 0.05;
  driver.noise_correlation_time_s = 0.01;
  return driver;
}

}  // namespace autograv::sim
