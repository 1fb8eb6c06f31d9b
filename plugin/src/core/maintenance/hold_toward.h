#pragma once

// Private to the maintenance folder: the PD hold that both the device's own motions
// (compensated_motion.cpp) and verifyMap (map_verification.cpp) use.

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"
#include "autograv/device/tick_source.h"
#include "autograv/maintenance/compensated_motion.h"

namespace autograv::detail {

/// What one approach saw at rest.
struct ProbeOutcome {
  Eigen::Vector3d mean_effort_n = Eigen::Vector3d::Zero();
  bool read_ok = true;
  bool settled = true;
};

/// Holds toward `target_m` for `duration_s`; averages the effort over the last `average_s`.
ProbeOutcome holdToward(HapticDevice& device, TickSource& ticks, const Eigen::Vector3d& target_m,
                        double stiffness_n_per_m, double damping_n_s_per_m,
                        const EffortLimit& limit, double duration_s, double average_s) noexcept;

}  // namespace autograv::detail
