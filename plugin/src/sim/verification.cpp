#include "autograv/sim/verification.h"

#include <utility>

#include "autograv/device/servo_clock.h"
#include "autograv/error.h"

namespace autograv::sim {

VerificationTruth truthOf(const SimulatedDevice& device) {
  VerificationTruth truth;
  truth.is_reachable = [&device](const Eigen::Vector3d& x) { return device.isReachable(x); };
  truth.gravity_n = [&device](const Eigen::Vector3d& x) { return device.trueGravity(x); };
  return truth;
}

VerificationReport verifyMapOnSimulatedDevice(const std::shared_ptr<SimulatedDevice>& device,
                                              std::shared_ptr<const GravityMap> map,
                                              const VerificationOptions& options,
                                              bool allow_model_mismatch) {
  if (!device || !map) throw Error("verify: no device or no map");
  const double period_s = map->metadata().parameters.servo_period_s;
  SimulatedTickSource ticks(*device, period_s, SimulatedTickSource::Mode::kAsFastAsPossible,
                            options.servo_timing, options.servo_timing_seed);
  autograv::VerificationOptions generic = options;
  // The decorator reads the loop's own clock; an exact loop is exactly its fixed period.
  if (options.servo_timing == ServoTiming::kExact) {
    generic.compensation.clock = std::make_shared<FixedPeriodServoClock>(period_s);
  } else {
    generic.compensation.clock = std::make_shared<ServoTimingClock>(ticks.timingModel());
  }
  const VerificationTruth truth = truthOf(*device);
  VerificationReport report;
  static_cast<autograv::VerificationReport&>(report) =
      verifyMap(device, ticks, std::move(map), generic, allow_model_mismatch, &truth);
  report.servo_loop = ticks.loopSummary();
  return report;
}

}  // namespace autograv::sim
