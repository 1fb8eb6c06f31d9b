#pragma once

// verify's generic part moved to core (autograv/maintenance/map_verification.h), where a device
// with no simulation behind it can use it; this header forwards its names into autograv::sim and
// adds the simulated run.

#include <cstdint>
#include <memory>

#include "autograv/device/servo_loop_stats.h"
#include "autograv/maintenance/map_verification.h"
#include "autograv/sim/servo_timing_model.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

using autograv::CarryOptions;
using autograv::CarryOutcome;
using autograv::carryTo;
using autograv::drawVerificationPoints;
using autograv::measureRelease;
using autograv::measureResidualForce;
using autograv::Percentiles;
using autograv::percentiles;
using autograv::PointVerification;
using autograv::ReleaseMeasurement;
using autograv::ReleaseOptions;
using autograv::ResidualMeasurement;
using autograv::ResidualProbeOptions;
using autograv::VerificationTruth;

/// Settings of verifyMapOnSimulatedDevice: the generic ones, and how the servo ticks arrive.
struct VerificationOptions : autograv::VerificationOptions {
  /// How the servo ticks arrive, drawn from servo_timing_seed (README, "Servo timing").
  ServoTiming servo_timing = ServoTiming::kExact;
  std::uint64_t servo_timing_seed = 1;  ///< Seed of the timing model's draws.
};

/// What verifyMapOnSimulatedDevice measured: the generic report and the loop's timing.
struct VerificationReport : autograv::VerificationReport {
  ServoLoopStats::Summary servo_loop;  ///< What the servo loop did.
};

/// The truth of a simulated device, for scoring only: isReachable and trueGravity. The device
/// must outlive the result. Not real-time safe.
VerificationTruth truthOf(const SimulatedDevice& device);

/// autograv::verifyMap on a simulated device: its physics stepped by a tick source of the
/// options' servo timing (the decorator reads that loop's clock), and its truth used only to
/// score (VerificationTruth). No hand touches the device. Throws autograv::Error when the device
/// does not accept the map. The device must be open. Not real-time safe.
VerificationReport verifyMapOnSimulatedDevice(const std::shared_ptr<SimulatedDevice>& device,
                                              std::shared_ptr<const GravityMap> map,
                                              const VerificationOptions& options,
                                              bool allow_model_mismatch = false);

}  // namespace autograv::sim
