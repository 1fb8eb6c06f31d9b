// A scripted session of application use on a compensated simulated device, scored minute by
// minute against the device's truth.
#include "autograv/sim/session_workload.h"

#include <algorithm>
#include <optional>
#include <string>

#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/maintenance/retare.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {

namespace {

/// Time between two looks at the force the hand feels along its path. Unit: [s]
constexpr double kPathSamplePeriod_s = 0.01;

void refuseOptions(const SessionWorkloadOptions& options) {
  const auto positive = [](double value) { return std::isfinite(value) && value > 0.0; };
  if (!positive(options.minutes) || options.minutes > 24.0 * 60.0) {
    throw Error("session workload: minutes must lie in (0, 1440], got " +
                std::to_string(options.minutes));
  }
  if (!positive(options.sample_period_s)) {
    throw Error("session workload: sample_period_s must be finite and > 0");
  }
  if (options.field_samples < 100) {
    throw Error("session workload: field_samples must be at least 100");
  }
  if (!std::isfinite(options.contact_force_n) || options.contact_force_n < 0.0) {
    throw Error("session workload: contact_force_n must be finite and >= 0");
  }
  if (!positive(options.hand_speed_m_per_s) || options.hand_speed_m_per_s > 1.0) {
    throw Error("session workload: hand_speed_m_per_s must lie in (0, 1] m/s");
  }
}

/// What the user and the scene do, turn by turn: carry the stylus somewhere, hold it still,
/// sometimes push against an object of the scene, then let go of it for a while.
class ScriptedSession {
 public:
  ScriptedSession(SimulatedDevice& device, const SessionWorkloadOptions& options)
      : device_(device), options_(options), random_(options.seed ^ 0x73657373696f6eULL) {
    startCarry();
  }

  /// Moves the script on to `now_s` and returns the force the scene adds now. Unit: [N]
  Eigen::Vector3d update(double now_s) {
    SimulatedHand& hand = device_.hand();
    switch (phase_) {
      case Phase::kCarry:
        if (hand.atGoal()) {
          phase_ = Phase::kHold;
          phase_end_s_ = now_s + uniform(2.0, 8.0);
        }
        break;
      case Phase::kHold:
        if (now_s >= phase_end_s_) {
          if (random_.uniform() < 0.4) {
            phase_ = Phase::kContact;
            contact_start_s_ = now_s;
            phase_end_s_ = now_s + uniform(2.0, 5.0);
            contact_direction_ = randomDirection();
            ++contacts_;
          } else {
            startFloat(now_s);
          }
        }
        break;
      case Phase::kContact:
        if (now_s >= phase_end_s_) startFloat(now_s);
        break;
      case Phase::kFloat:
        if (now_s >= phase_end_s_) startCarry();
        break;
    }
    if (phase_ != Phase::kContact) return Eigen::Vector3d::Zero();
    // The object's force rises and falls smoothly as the hand presses into it and backs off.
    const double share = (now_s - contact_start_s_) / (phase_end_s_ - contact_start_s_);
    const double rise = std::sin(3.14159265358979323846 * std::clamp(share, 0.0, 1.0));
    return contact_direction_ * (options_.contact_force_n * rise * rise);
  }

  std::uint64_t releases() const noexcept { return releases_; }
  std::uint64_t contacts() const noexcept { return contacts_; }

 private:
  enum class Phase { kCarry, kHold, kContact, kFloat };

  double uniform(double low, double high) { return low + (high - low) * random_.uniform(); }

  Eigen::Vector3d randomDirection() {
    for (;;) {
      const Eigen::Vector3d v(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      const double norm = v.norm();
      if (norm > 0.1 && norm <= 1.0) return v / norm;
    }
  }

  /// A place the hand can reach: uniform over the reachable workspace, drawn toward the centre
  /// by a tenth so that the hand does not press the stylus into a stop on the way.
  Eigen::Vector3d reachablePlace() {
    const Eigen::Vector3d centre = device_.workspaceCenter_m();
    const double reach_m = 1.5 * device_.specifications().workspace_radius_m;
    for (int attempt = 0; attempt < 100000; ++attempt) {
      const Eigen::Vector3d candidate =
          centre + reach_m * Eigen::Vector3d(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
      if (device_.isReachable(candidate)) return centre + 0.9 * (candidate - centre);
    }
    return centre;
  }

  void startCarry() {
    SimulatedHand& hand = device_.hand();
    hand.grab(device_.truePosition_m());
    hand.moveTo(reachablePlace(), options_.hand_speed_m_per_s);
    phase_ = Phase::kCarry;
  }

  void startFloat(double now_s) {
    device_.hand().release();
    ++releases_;
    phase_ = Phase::kFloat;
    phase_end_s_ = now_s + uniform(5.0, 20.0);
  }

  SimulatedDevice& device_;
  const SessionWorkloadOptions& options_;
  Random random_;
  Phase phase_ = Phase::kCarry;
  double phase_end_s_ = 0.0;
  double contact_start_s_ = 0.0;
  Eigen::Vector3d contact_direction_ = Eigen::Vector3d::UnitZ();
  std::uint64_t releases_ = 0;
  std::uint64_t contacts_ = 0;
};

/// The factor s that minimises the sum of |s G_hat - G|^2 over the map's reachable vertices.
double bestScale(const GravityMap& map, const SimulatedDevice& device) {
  double cross = 0.0, own = 0.0;
  for (int i = 0; i < map.grid().vertexCount(); ++i) {
    const Eigen::Vector3d at_m = map.grid().vertexPosition(i);
    if (!device.isReachable(at_m)) continue;
    const Eigen::Vector3d mapped_n = map.gravityAt(at_m);
    cross += mapped_n.dot(device.trueGravity(at_m));
    own += mapped_n.squaredNorm();
  }
  return own > 0.0 ? cross / own : 1.0;
}

/// The 90th percentile of `values` (0 when empty); reorders them.
double percentile90(std::vector<double>& values) {
  if (values.empty()) return 0.0;
  const auto nth = values.begin() + static_cast<std::ptrdiff_t>(0.9 * (values.size() - 1));
  std::nth_element(values.begin(), nth, values.end());
  return *nth;
}

}  // namespace

SessionWorkloadResult runSessionWorkload(
    SimulatedDevice& device, std::shared_ptr<const GravityMap> map,
    const SessionWorkloadOptions& options,
    const std::function<void(const SessionSample&)>& on_sample) {
  refuseOptions(options);
  if (!map) throw Error("session workload: no map to compensate with");
  SimulatedTickSource ticks(device, options.servo_period_s,
                            SimulatedTickSource::Mode::kAsFastAsPossible, options.servo_timing,
                            options.seed);
  CompensationOptions compensation;
  compensation.clock = std::make_shared<ServoTimingClock>(ticks.timingModel());
  compensation.correct_thermal_drift = options.thermal_correction;
  compensation.initial_thermal_load = options.initial_thermal_load;
  // The decorator drives the device it is given; this one is owned by the caller.
  GravityCompensatedDevice decorated(std::shared_ptr<HapticDevice>(&device, [](HapticDevice*) {}),
                                     compensation);
  if (!decorated.open()) throw Error("session workload: the device does not open");
  decorated.publishMap(map);

  const double continuous_n = continuousForceRating_n(device.specifications());
  ScriptedSession script(device, options);
  SessionWorkloadResult result;
  std::vector<double> path_errors;
  path_errors.reserve(static_cast<std::size_t>(options.sample_period_s / kPathSamplePeriod_s) + 8);

  // The factor the decorator scales the map by at a thermal load.
  const auto correction = [&](double load) {
    return options.thermal_correction ? thermalScale(map->metadata().thermal_drift, load) : 1.0;
  };
  const auto score = [&](double elapsed_s) {
    SessionSample sample;
    sample.minute = elapsed_s / 60.0;
    sample.thermal_scale = correction(decorated.thermalLoad());
    // The map is copied only when the correction scales it.
    std::optional<GravityMap> scaled;
    if (sample.thermal_scale != 1.0) scaled.emplace(scaledMap(*map, sample.thermal_scale));
    const GravityMap& in_use = scaled ? *scaled : *map;
    sample.field = measureFieldError(in_use, device, options.field_samples, options.seed);
    sample.best_scale = bestScale(in_use, device);
    sample.rescaled_field = measureFieldError(scaledMap(in_use, sample.best_scale), device,
                                              options.field_samples, options.seed);
    sample.path_p90_rel = percentile90(path_errors);
    path_errors.clear();
    if (const MotorThermalModel* thermal = device.motorThermal()) {
      sample.hottest_winding_c = thermal->winding_c().maxCoeff();
      sample.hottest_housing_c = thermal->housing_c().maxCoeff();
      sample.lowest_gain_factor = thermal->gainFactor().minCoeff();
      sample.highest_gain_factor = thermal->gainFactor().maxCoeff();
    }
    sample.thermal_load = decorated.thermalLoad();
    sample.seconds_above_continuous_force = result.seconds_above_continuous_force;
    result.samples.push_back(sample);
    if (on_sample) on_sample(sample);
  };

  const double start_s = device.time_s();
  const double end_s = options.minutes * 60.0;
  double next_score_s = 0.0;
  double next_path_s = 0.0;
  Eigen::Vector3d position_m;
  while (true) {
    const double elapsed_s = device.time_s() - start_s;
    if (elapsed_s + 1e-9 >= next_score_s) {
      score(elapsed_s);
      next_score_s += options.sample_period_s;
      if (next_score_s > end_s + 1e-9) break;
    }
    ticks.waitForNextTick();
    if (!decorated.getPosition(position_m)) {
      throw Error("session workload: the device stopped answering at " + std::to_string(elapsed_s) +
                  " s");
    }
    decorated.setForce(script.update(elapsed_s));
    const double applied_n = device.appliedForce_n().norm();
    result.peak_force_n = std::max(result.peak_force_n, applied_n);
    if (applied_n > continuous_n) result.seconds_above_continuous_force += ticks.lastInterval_s();
    if (elapsed_s >= next_path_s) {
      next_path_s += kPathSamplePeriod_s;
      const Eigen::Vector3d at_m = device.truePosition_m();
      const Eigen::Vector3d truth_n = device.trueGravity(at_m);
      const double in_use = correction(decorated.thermalLoad());
      path_errors.push_back((in_use * map->gravityAt(at_m) - truth_n).norm() / truth_n.norm());
    }
  }
  result.force_limit_ticks = decorated.clampCount() + device.saturationCount();
  result.releases = script.releases();
  result.contacts = script.contacts();
  decorated.setForce(Eigen::Vector3d::Zero());
  return result;
}

}  // namespace autograv::sim
