#pragma once

#include <vector>

#include <Eigen/Core>

#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

/// How measureFriction probes a device.
struct FrictionMeasurementOptions {
  /// Rate of the force ramp that looks for the breakaway. Slow, so that the force at which the
  /// end-effector starts to move is not inflated by the ramp. Unit: [N/s]
  double ramp_rate_n_per_s = 0.05;
  /// The ramp gives up (and reports this force) if nothing moved by then. Unit: [N]
  double max_force_n = 1.0;
  /// Motion that counts as "started to move": a few encoder counts of the measured position (two
  /// of the Omni's, ten of the omega's), well beyond the tens of micrometres of pre-sliding.
  /// Unit: [m]
  double motion_threshold_m = 1e-4;
  /// Speed at which the Coulomb (sliding) level is measured, and twice that: above the Stribeck
  /// speeds, low enough to stay well inside the workspace. Unit: [m/s]
  double sliding_speed_m_per_s = 0.005;
  /// Stiffness and damping of the tracking servo that drives the end-effector at that speed.
  /// Units: [N/m], [N s/m]
  double tracking_stiffness_n_per_m = 300.0;
  /// Damping of the tracking servo. Unit: [N s/m]
  double tracking_damping_n_s_per_m = 2.0;
};

/// What measureFriction found. Breakaway: per direction, the ramped force at which the
/// end-effector started to move from rest at the workspace centre.
struct FrictionMeasurement {
  /// Largest breakaway over the directions: the force that surely starts it moving. Unit: [N]
  double breakaway_force_n = 0.0;
  /// Smallest breakaway over the directions. Unit: [N]
  double min_breakaway_force_n = 0.0;
  /// Coulomb (sliding) friction: mean over +-x, +-y, +-z of the force along the motion it takes
  /// to keep the end-effector sliding, at v and 2 v extrapolated to zero speed (2 F(v) - F(2 v)),
  /// so that the viscous part drops out. Unit: [N]
  double coulomb_force_n = 0.0;
  /// The probed unit directions and each one's breakaway force. Unit: [N]
  std::vector<Eigen::Vector3d> directions;
  /// Breakaway force along directions[k]. Unit: [N]
  std::vector<double> breakaway_n;
  /// Simulated time the measurement took. Unit: [s]
  double simulated_seconds = 0.0;
};

/// The 14 directions measureFriction probes: +-x, +-y, +-z and the 8 cube diagonals.
std::vector<Eigen::Vector3d> frictionProbeDirections();

/// Measures a simulated device's friction as one would on a bench: from rest at the workspace
/// centre with gravity cancelled by the device's true gravity, a force ramped slowly along each
/// probe direction until the measured position moves by `motion_threshold_m`; then the force a
/// tracking servo needs to drive it at two slow constant speeds. Opens nothing: `device` must be
/// open and calibrated; it is left at rest at the centre with zero force. Throws autograv::Error
/// when the device stops answering. Not real-time safe.
FrictionMeasurement measureFriction(SimulatedDevice& device,
                                    const FrictionMeasurementOptions& options = {});

}  // namespace autograv::sim
