#include "autograv/compensation/gravity_compensated_device.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <utility>

#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/map/gravity_map.h"
#include "core/compensation/compensation_status.h"
#include "core/compensation/frozen_driver_detector.h"
#include "core/compensation/map_fade.h"
#include "core/compensation/map_handoff.h"
#include "core/compensation/ramp.h"
#include "core/compensation/servo_position_cache.h"
#include "core/compensation/servo_tick_timer.h"
#include "core/compensation/thermal_load_observer.h"

namespace autograv {

namespace {

constexpr std::array<const char*, kServoFaultKinds> kFaultNames{
    "none",           "read_failed", "non_finite_position", "stale_position", "non_finite_force",
    "no_force_limit", "write_failed"};

}  // namespace

struct GravityCompensatedDevice::Impl {
  explicit Impl(const CompensationOptions& options)
      : timer(options.clock, options.max_tick_interval_s),
        frozen(options),
        status(options.enabled, frozen.resolution_m()) {
    thermal.reset(options.initial_thermal_load);
    status.thermal_load.store(options.initial_thermal_load, std::memory_order_relaxed);
  }

  // Publication: written by publishers, read by the servo thread.
  MapHandoff handoff;
  // Servo-thread state.
  MapFade maps;
  ServoTickTimer timer;
  FadeStallWatch stall_watch;
  ServoPositionCache reading;
  FrozenDriverDetector frozen;
  /// The motors' load from the forces sent; its rating is read at open() (none: no load).
  ThermalLoadObserver thermal;
  // Shared status: the servo thread writes, anyone reads.
  CompensationStatus status;
};

const char* toString(ServoFault fault) noexcept {
  const auto index = static_cast<std::size_t>(fault);
  return index < kFaultNames.size() ? kFaultNames[index] : "unknown";
}

GravityCompensatedDevice::GravityCompensatedDevice(std::shared_ptr<HapticDevice> inner,
                                                   const CompensationOptions& options)
    : ForwardingDevice(std::move(inner), "GravityCompensatedDevice"), options_(options) {
  const auto check = [](bool ok, const char* field, double value, const char* expected) {
    if (ok) return;
    std::ostringstream message;
    message << "GravityCompensatedDevice: CompensationOptions::" << field << " must be " << expected
            << ", got " << value;
    throw Error(message.str());
  };
  const auto nonNegative = [](double value) { return std::isfinite(value) && value >= 0.0; };
  check(std::isfinite(options.max_tick_interval_s) && options.max_tick_interval_s > 0.0,
        "max_tick_interval_s", options.max_tick_interval_s, "a positive time in seconds");
  check(nonNegative(options.ramp_duration_s), "ramp_duration_s", options.ramp_duration_s,
        "a time >= 0 in seconds");
  check(nonNegative(options.outside_margin_m), "outside_margin_m", options.outside_margin_m,
        "a length >= 0 in metres");
  check(nonNegative(options.frozen_window_s), "frozen_window_s", options.frozen_window_s,
        "a time >= 0 in seconds (0 disables the check)");
  check(nonNegative(options.frozen_force_floor_n), "frozen_force_floor_n",
        options.frozen_force_floor_n, "a force >= 0 in newtons");
  check(nonNegative(options.frozen_hand_stiffness_n_per_m), "frozen_hand_stiffness_n_per_m",
        options.frozen_hand_stiffness_n_per_m, "a stiffness >= 0 in N/m");
  check(nonNegative(options.frozen_filter_time_constant_s), "frozen_filter_time_constant_s",
        options.frozen_filter_time_constant_s, "a time >= 0 in seconds");
  check(std::isfinite(options.motor_time_constant_s) && options.motor_time_constant_s > 0.0,
        "motor_time_constant_s", options.motor_time_constant_s, "a positive time in seconds");
  check(nonNegative(options.initial_thermal_load) && options.initial_thermal_load <= 10.0,
        "initial_thermal_load", options.initial_thermal_load,
        "a load in [0, 10] (1: the motors at their rated temperature rise)");
  if (!options_.clock) options_.clock = std::make_shared<SteadyServoClock>();
  impl_ = std::make_unique<Impl>(options_);
}

GravityCompensatedDevice::~GravityCompensatedDevice() = default;

// --- Forwarded methods ------------------------------------------------------------------------

bool GravityCompensatedDevice::open() {
  const bool ok = inner().open();
  resetServoState();
  const double max_force_n = inner().specifications().max_linear_force_n;
  const bool rated = ok && std::isfinite(max_force_n) && max_force_n > 0.0;
  impl_->thermal.configure(rated ? continuousForceRating_n(inner().specifications()) : 0.0,
                           options_.motor_time_constant_s);
  return ok;
}

bool GravityCompensatedDevice::close() {
  const bool ok = inner().close();
  resetServoState();
  return ok;
}

bool GravityCompensatedDevice::getPosition(Eigen::Vector3d& position_m) {
  const bool ok = inner().getPosition(position_m);
  impl_->reading.offer(position_m, ok);
  return ok;
}

// --- Servo path -------------------------------------------------------------------------------

bool GravityCompensatedDevice::setForce(const Eigen::Vector3d& force_n) {
  Impl& s = *impl_;
  s.reading.claimForCallingThread();
  CompensationStatus::increment(s.status.tick_count);
  const double dt_s = s.timer.tick();
  s.thermal.advance(dt_s);
  const double load = s.thermal.load();
  s.status.thermal_load.store(load, std::memory_order_relaxed);
  // Out of line only when there is something to do: a new publication or a fade in progress.
  if (s.maps.needsAdvance(s.handoff)) s.maps.advance(s.handoff, dt_s, options_.ramp_duration_s);
  s.maps.setThermalLoad(options_.correct_thermal_drift ? load : 0.0);

  Eigen::Vector3d position_m;
  const bool read_ok = s.reading.take(inner(), position_m);
  if (!read_ok) return fault(ServoFault::kReadFailed);
  if (!position_m.allFinite()) return fault(ServoFault::kNonFinitePosition);
  if (!force_n.allFinite()) return fault(ServoFault::kNonFiniteForce);
  const double max_force_n = inner().specifications().max_linear_force_n;
  if (!(std::isfinite(max_force_n) && max_force_n > 0.0)) return fault(ServoFault::kNoForceLimit);
  if (s.frozen.learnResolution(position_m)) {
    s.status.resolution_m.store(s.frozen.resolution_m(), std::memory_order_relaxed);
  }

  const bool enabled = s.status.enabled.load(std::memory_order_relaxed);
  double level = s.status.level.load(std::memory_order_relaxed);
  const double ramp_s = options_.ramp_duration_s;
  if (enabled && level < 1.0) {
    level = rampUp(level, dt_s, ramp_s);
  } else if (!enabled && level > 0.0) {
    level = rampDown(level, dt_s, ramp_s);
  }
  s.status.level.store(level, std::memory_order_relaxed);
  const bool fading = s.maps.fading() || (enabled && level < 1.0 && s.maps.hasMap());
  if (s.stall_watch.stalled(fading && !s.status.fade_stalled.load(std::memory_order_relaxed),
                            s.status.tick_count.load(std::memory_order_relaxed), s.timer.now_s(),
                            kStalledFadeTicks, kStalledFadeSpan_s)) {
    s.status.fade_stalled.store(true, std::memory_order_relaxed);
  }

  // The map is looked up even while compensation is off: the frozen-driver check weighs the push
  // against the full gravity, and outsideMap() reports the position either way.
  bool inside = true;
  const Eigen::Vector3d gravity_n = s.maps.gravityAt(position_m, options_.outside_margin_m, inside);
  s.status.outside_map.store(!inside, std::memory_order_relaxed);
  if (!inside) CompensationStatus::increment(s.status.outside_map_ticks);

  Eigen::Vector3d commanded_n = force_n + level * gravity_n;
  // Squared norms first: the square root is paid only when the force is actually clamped.
  const double squared_n2 = commanded_n.squaredNorm();
  bool clamped = false;
  if (squared_n2 > max_force_n * max_force_n) {
    // Divided by its largest component first: a finite force whose square overflows (1e200 N)
    // is clamped along its own direction too, instead of being scaled by max / inf = 0.
    const Eigen::Vector3d direction = commanded_n / commanded_n.cwiseAbs().maxCoeff();
    commanded_n = direction * (max_force_n / direction.norm());
    clamped = true;
  }
  if (s.frozen.frozen(position_m, commanded_n - gravity_n, dt_s)) {
    return fault(ServoFault::kStalePosition);
  }
  if (clamped) CompensationStatus::increment(s.status.clamp_count);
  if (!inner().setForce(commanded_n)) {
    s.thermal.sentNothing();
    // The force did not reach the actuators: whatever they do now, restart the ramp so that the
    // compensation does not arrive as a step when writes work again.
    s.status.level.store(0.0, std::memory_order_relaxed);
    s.status.countTick(ServoFault::kWriteFailed);
    return false;
  }
  s.thermal.sent(commanded_n);
  s.status.countTick(ServoFault::kNone);
  return true;
}

bool GravityCompensatedDevice::fault(ServoFault kind) noexcept {
  inner().setForce(Eigen::Vector3d::Zero());
  impl_->thermal.sentNothing();
  impl_->status.level.store(0.0, std::memory_order_relaxed);
  // A frozen driver stays caught while its readings stay frozen; any other fault restarts the
  // tracking, since the readings in between were not usable.
  if (kind != ServoFault::kStalePosition) impl_->frozen.restartRun();
  impl_->status.countTick(kind);
  return false;
}

void GravityCompensatedDevice::resetServoState() noexcept {
  Impl& s = *impl_;
  s.status.level.store(0.0, std::memory_order_relaxed);
  s.frozen.reset();
  s.timer.restart();
  s.stall_watch.reset();
  s.status.outside_map.store(false, std::memory_order_relaxed);
  s.reading.reset();
}

// --- Publication (non-real-time side) ---------------------------------------------------------

void GravityCompensatedDevice::publishMap(std::shared_ptr<const GravityMap> map,
                                          bool allow_model_mismatch) {
  if (map && !allow_model_mismatch) {
    const std::string& device_model = inner().specifications().model_name;
    const std::string& map_model = map->metadata().device_model;
    if (device_model.empty()) {
      throw Error(
          "GravityCompensatedDevice: the device reports no model name, so the map made for '" +
          map_model + "' cannot be checked against it; open() the device first");
    }
    if (device_model != map_model) {
      throw Error("GravityCompensatedDevice: the map was calibrated on a '" + map_model +
                  "' but the device is a '" + device_model +
                  "'; calibrate this device, or allow the mismatch explicitly (publishMap's "
                  "allow_model_mismatch = true)");
    }
  }
  impl_->handoff.publish(std::move(map));
  reclaimRetiredMaps();
}

std::shared_ptr<const GravityMap> GravityCompensatedDevice::publishedMap() const {
  return impl_->handoff.latest();
}

std::size_t GravityCompensatedDevice::reclaimRetiredMaps() {
  return impl_->handoff.reclaimRetired();
}

std::size_t GravityCompensatedDevice::retainedMapCount() const {
  return impl_->handoff.retainedCount();
}

bool GravityCompensatedDevice::latestMapInUse() const noexcept {
  return impl_->handoff.latestAcknowledged();
}

// --- Switch and status ------------------------------------------------------------------------

void GravityCompensatedDevice::setCompensationEnabled(bool enabled) noexcept {
  impl_->status.enabled.store(enabled, std::memory_order_relaxed);
}

bool GravityCompensatedDevice::compensationEnabled() const noexcept {
  return impl_->status.enabled.load(std::memory_order_relaxed);
}

double GravityCompensatedDevice::compensationLevel() const noexcept {
  return impl_->status.level.load(std::memory_order_relaxed);
}

ServoFault GravityCompensatedDevice::activeFault() const noexcept {
  return impl_->status.active_fault.load(std::memory_order_relaxed);
}

ServoFault GravityCompensatedDevice::lastFault() const noexcept {
  return impl_->status.last_fault.load(std::memory_order_relaxed);
}

std::uint64_t GravityCompensatedDevice::faultCount() const noexcept {
  return impl_->status.faultTotal();
}

std::uint64_t GravityCompensatedDevice::faultCount(ServoFault fault) const noexcept {
  const auto& counts = impl_->status.fault_counts;
  const auto index = static_cast<std::size_t>(fault);
  return index < counts.size() ? counts[index].load(std::memory_order_relaxed) : 0;
}

std::uint64_t GravityCompensatedDevice::clampCount() const noexcept {
  return impl_->status.clamp_count.load(std::memory_order_relaxed);
}

std::uint64_t GravityCompensatedDevice::tickCount() const noexcept {
  return impl_->status.tick_count.load(std::memory_order_relaxed);
}

bool GravityCompensatedDevice::outsideMap() const noexcept {
  return impl_->status.outside_map.load(std::memory_order_relaxed);
}

std::uint64_t GravityCompensatedDevice::outsideMapTickCount() const noexcept {
  return impl_->status.outside_map_ticks.load(std::memory_order_relaxed);
}

bool GravityCompensatedDevice::fadeStalled() const noexcept {
  return impl_->status.fade_stalled.load(std::memory_order_relaxed);
}

double GravityCompensatedDevice::thermalLoad() const noexcept {
  return impl_->status.thermal_load.load(std::memory_order_relaxed);
}

double GravityCompensatedDevice::positionResolution_m() const noexcept {
  return impl_->status.resolution_m.load(std::memory_order_relaxed);
}

}  // namespace autograv
