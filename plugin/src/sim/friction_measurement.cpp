#include "autograv/sim/friction_measurement.h"

#include <algorithm>

#include "autograv/device/servo_sample.h"
#include "autograv/error.h"

namespace autograv::sim {

namespace {

constexpr double kServo_s = 0.001;
// The end-effector settles this long at the centre before each probe (the commanded force
// reaches the actuators one servo period late). Unit: [s]
constexpr double kSettle_s = 0.05;
// Sliding probe: time to reach steady sliding, then time averaged. Units: [s]
constexpr double kSlideSettle_s = 0.3;
constexpr double kSlideAverage_s = 0.4;

ServoSample readOrThrow(SimulatedDevice& device) {
  const ServoSample sample = readServoSample(device);
  if (!sample.valid) throw Error("friction measurement: the device stopped answering");
  return sample;
}

void command(SimulatedDevice& device, const Eigen::Vector3d& force_n) {
  if (!device.setForce(force_n)) {
    throw Error("friction measurement: the device refused a force");
  }
  device.advance(kServo_s);
}

void settleAtCentre(SimulatedDevice& device) {
  const Eigen::Vector3d centre_m = device.workspaceCenter_m();
  // The force reaches the actuators one servo period after setForce: the gravity must be acting
  // when the end-effector is put at rest, or it falls for a period and slides on.
  device.resetState(centre_m);
  command(device, device.trueGravity(centre_m));
  device.resetState(centre_m);
  for (double t = 0.0; t < kSettle_s; t += kServo_s) {
    readOrThrow(device);
    command(device, device.trueGravity(device.truePosition_m()));
  }
}

double breakawayAlong(SimulatedDevice& device, const Eigen::Vector3d& direction,
                      const FrictionMeasurementOptions& options) {
  settleAtCentre(device);
  const Eigen::Vector3d start_m = readOrThrow(device).position_m;
  double ramp_n = 0.0;
  while (ramp_n < options.max_force_n) {
    const ServoSample sample = readOrThrow(device);
    if ((sample.position_m - start_m).norm() > options.motion_threshold_m) break;
    ramp_n += options.ramp_rate_n_per_s * kServo_s;
    command(device, device.trueGravity(device.truePosition_m()) + ramp_n * direction);
  }
  // The force that moved it reached the actuators one period before the motion was seen.
  return std::min(ramp_n, options.max_force_n);
}

double slidingForceAlong(SimulatedDevice& device, const Eigen::Vector3d& direction,
                         double speed_m_per_s, const FrictionMeasurementOptions& options) {
  settleAtCentre(device);
  const Eigen::Vector3d start_m = readOrThrow(device).position_m;
  const Eigen::Vector3d velocity_m_per_s = speed_m_per_s * direction;
  double sum_n = 0.0;
  int samples = 0;
  for (double t = 0.0; t < kSlideSettle_s + kSlideAverage_s; t += kServo_s) {
    const ServoSample sample = readOrThrow(device);
    const Eigen::Vector3d tracking_n =
        options.tracking_stiffness_n_per_m * (start_m + t * velocity_m_per_s - sample.position_m) +
        options.tracking_damping_n_s_per_m * (velocity_m_per_s - sample.velocity_m_per_s);
    if (t >= kSlideSettle_s) {
      sum_n += tracking_n.dot(direction);
      ++samples;
    }
    command(device, device.trueGravity(device.truePosition_m()) + tracking_n);
  }
  return samples > 0 ? sum_n / samples : 0.0;
}

}  // namespace

std::vector<Eigen::Vector3d> frictionProbeDirections() {
  std::vector<Eigen::Vector3d> directions;
  for (int axis = 0; axis < 3; ++axis) {
    directions.push_back(Eigen::Vector3d::Unit(axis));
    directions.push_back(-Eigen::Vector3d::Unit(axis));
  }
  for (int sx = -1; sx <= 1; sx += 2) {
    for (int sy = -1; sy <= 1; sy += 2) {
      for (int sz = -1; sz <= 1; sz += 2) {
        directions.push_back(Eigen::Vector3d(sx, sy, sz).normalized());
      }
    }
  }
  return directions;
}

FrictionMeasurement measureFriction(SimulatedDevice& device,
                                    const FrictionMeasurementOptions& options) {
  if (!(options.ramp_rate_n_per_s > 0.0) || !(options.max_force_n > 0.0) ||
      !(options.motion_threshold_m > 0.0) || !(options.sliding_speed_m_per_s > 0.0) ||
      !(options.tracking_stiffness_n_per_m > 0.0) || !(options.tracking_damping_n_s_per_m >= 0.0)) {
    throw Error("friction measurement: every option must be > 0 (tracking damping >= 0)");
  }
  const double start_s = device.time_s();
  FrictionMeasurement result;
  result.directions = frictionProbeDirections();
  result.min_breakaway_force_n = options.max_force_n;
  for (const Eigen::Vector3d& direction : result.directions) {
    const double breakaway_n = breakawayAlong(device, direction, options);
    result.breakaway_n.push_back(breakaway_n);
    result.breakaway_force_n = std::max(result.breakaway_force_n, breakaway_n);
    result.min_breakaway_force_n = std::min(result.min_breakaway_force_n, breakaway_n);
  }
  // The sliding force is Fc + b v: at v and 2 v, 2 F(v) - F(2 v) leaves Fc alone.
  double coulomb_sum_n = 0.0;
  for (int i = 0; i < 6; ++i) {
    const Eigen::Vector3d& direction = result.directions[static_cast<std::size_t>(i)];
    const double slow_n =
        slidingForceAlong(device, direction, options.sliding_speed_m_per_s, options);
    const double fast_n =
        slidingForceAlong(device, direction, 2.0 * options.sliding_speed_m_per_s, options);
    coulomb_sum_n += 2.0 * slow_n - fast_n;
  }
  result.coulomb_force_n = coulomb_sum_n / 6.0;
  device.resetState(device.workspaceCenter_m());
  device.setForce(Eigen::Vector3d::Zero());
  result.simulated_seconds = device.time_s() - start_s;
  return result;
}

}  // namespace autograv::sim
