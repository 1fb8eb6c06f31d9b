#include "autograv/device/gravity_compensated_device.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>
#include <utility>

#include "autograv/error.h"

namespace autograv {

namespace {

constexpr std::array<const char*, kServoFaultKinds> kFaultNames{
    "none",           "read_failed", "non_finite_position", "stale_position", "non_finite_force",
    "no_force_limit", "write_failed"};

// The frozen-driver check's assumptions (see the class comment). Resolution assumed until the
// first step between two readings is seen: coarser than any supported device's. Unit: [m]
constexpr double kUnknownResolution_m = 1e-4;
// Encoder counts a hand must move by before a push can be blamed on a frozen driver.
constexpr double kHandCounts = 3.0;
// cos^2(45 degrees): a push counts along an axis when within 45 degrees of it.
constexpr double kAxisConeCos2 = 0.5;

bool bitwiseEqual(const Eigen::Vector3d& a, const Eigen::Vector3d& b) noexcept {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

// A cheap identity of the calling thread: the address of a thread-local object, distinct for
// every live thread. std::this_thread::get_id() costs a call into the C library on every tick.
const void* currentThreadToken() noexcept {
  static thread_local char token = 0;
  return &token;
}

// Counters have a single writer (the servo thread): a relaxed load and store is enough and avoids
// the locked read-modify-write of fetch_add.
void increment(std::atomic<std::uint64_t>& counter) noexcept {
  counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

}  // namespace

const char* toString(ServoFault fault) noexcept {
  const auto index = static_cast<std::size_t>(fault);
  return index < kFaultNames.size() ? kFaultNames[index] : "unknown";
}

GravityCompensatedDevice::GravityCompensatedDevice(std::shared_ptr<HapticDevice> inner,
                                                   const CompensationOptions& options)
    : ForwardingDevice(std::move(inner), "GravityCompensatedDevice"),
      options_(options),
      clock_(options.clock ? options.clock : std::make_shared<SteadyServoClock>()),
      resolution_m_(kUnknownResolution_m),
      enabled_(options.enabled),
      resolution_status_m_(kUnknownResolution_m) {
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
  options_.clock = clock_;
}

GravityCompensatedDevice::~GravityCompensatedDevice() = default;

// --- Forwarded methods ------------------------------------------------------------------------

bool GravityCompensatedDevice::open() {
  const bool ok = inner().open();
  resetServoState();
  return ok;
}

bool GravityCompensatedDevice::close() {
  const bool ok = inner().close();
  resetServoState();
  return ok;
}

bool GravityCompensatedDevice::getPosition(Eigen::Vector3d& position_m) {
  const bool ok = inner().getPosition(position_m);
  // Only the servo thread's reading may stand for "the latest position" in setForce: a graphics
  // thread reading the device must neither race with it nor feed it an older sample.
  if (servo_thread_.load(std::memory_order_relaxed) == currentThreadToken()) {
    cached_position_m_ = position_m;
    cached_ok_ = ok;
    cached_fresh_ = true;
  }
  return ok;
}

// --- Servo path -------------------------------------------------------------------------------

bool GravityCompensatedDevice::setForce(const Eigen::Vector3d& force_n) {
  const void* const self = currentThreadToken();
  if (servo_thread_.load(std::memory_order_relaxed) != self) {
    servo_thread_.store(self, std::memory_order_relaxed);
    cached_fresh_ = false;  // a reading from before this thread became the servo thread
  }
  increment(tick_count_);
  const double dt_s = tickInterval();
  // Out of line only when there is something to do: a new publication or a fade in progress.
  if (blend_ < 1.0 || published_sequence_.load(std::memory_order_acquire) != taken_sequence_) {
    takeNewMap(dt_s);
  }

  Eigen::Vector3d position_m;
  bool read_ok;
  if (cached_fresh_) {
    position_m = cached_position_m_;
    read_ok = cached_ok_;
  } else {
    read_ok = inner().getPosition(position_m);
  }
  cached_fresh_ = false;

  if (!read_ok) return fault(ServoFault::kReadFailed);
  if (!position_m.allFinite()) return fault(ServoFault::kNonFinitePosition);
  if (!force_n.allFinite()) return fault(ServoFault::kNonFiniteForce);
  const double max_force_n = inner().specifications().max_linear_force_n;
  if (!(std::isfinite(max_force_n) && max_force_n > 0.0)) return fault(ServoFault::kNoForceLimit);
  learnResolution(position_m);

  const bool enabled = enabled_.load(std::memory_order_relaxed);
  double level = level_.load(std::memory_order_relaxed);
  const double ramp_s = options_.ramp_duration_s;
  if (enabled && level < 1.0) {
    level = ramp_s > 0.0 ? std::min(1.0, level + dt_s / ramp_s) : 1.0;
  } else if (!enabled && level > 0.0) {
    level = ramp_s > 0.0 ? std::max(0.0, level - dt_s / ramp_s) : 0.0;
  }
  level_.store(level, std::memory_order_relaxed);
  watchFade(blend_ < 1.0 || (enabled && level < 1.0 && current_ != nullptr));

  // The map is looked up even while compensation is off: the frozen-driver check weighs the push
  // against the full gravity, and outsideMap() reports the position either way.
  bool inside = true;
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();
  if (blend_ >= 1.0) {  // the usual case inline: no fade in progress
    if (current_ != nullptr) {
      gravity_n = current_->gravityAt(position_m, options_.outside_margin_m, inside);
    }
  } else {
    gravity_n = compensation(position_m, inside);
  }
  outside_map_.store(!inside, std::memory_order_relaxed);
  if (!inside) increment(outside_map_ticks_);

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
  if (frozen(position_m, commanded_n - gravity_n, dt_s)) return fault(ServoFault::kStalePosition);
  if (clamped) increment(clamp_count_);
  if (!inner().setForce(commanded_n)) {
    // The force did not reach the actuators: whatever they do now, restart the ramp so that the
    // compensation does not arrive as a step when writes work again.
    level_.store(0.0, std::memory_order_relaxed);
    countTick(ServoFault::kWriteFailed);
    return false;
  }
  countTick(ServoFault::kNone);
  return true;
}

double GravityCompensatedDevice::tickInterval() noexcept {
  const double now_s = clock_->now_s();
  // The first tick has nothing to measure from; a clock going backwards (or NaN) counts as 0.
  double dt_s = has_last_time_ ? now_s - last_time_s_ : 0.0;
  last_time_s_ = now_s;
  has_last_time_ = true;
  if (!(dt_s >= 0.0)) dt_s = 0.0;
  return std::min(dt_s, options_.max_tick_interval_s);
}

void GravityCompensatedDevice::watchFade(bool fading) noexcept {
  if (!fading || fade_stalled_.load(std::memory_order_relaxed)) {
    stall_watching_ = false;
    return;
  }
  const std::uint64_t tick = tick_count_.load(std::memory_order_relaxed);
  // last_time_s_ is this tick's clock reading (tickInterval ran first): no second read.
  if (!stall_watching_ || !(last_time_s_ - stall_start_s_ < kStalledFadeSpan_s)) {
    // A new span begins whenever the clock has moved on by the span: a real loop never gathers
    // kStalledFadeTicks in one.
    stall_watching_ = true;
    stall_start_tick_ = tick;
    stall_start_s_ = last_time_s_;
    return;
  }
  if (tick - stall_start_tick_ >= static_cast<std::uint64_t>(kStalledFadeTicks)) {
    fade_stalled_.store(true, std::memory_order_relaxed);
  }
}

void GravityCompensatedDevice::takeNewMap(double dt_s) noexcept {
  // A new map is taken only between fades, so at most two maps are ever in use. The first map
  // fades in from none, and a null map fades the last one out, like any other swap.
  if (blend_ >= 1.0) {
    const std::uint64_t sequence = published_sequence_.load(std::memory_order_acquire);
    if (sequence != taken_sequence_) {
      // Read after the sequence number: this is the map of that publication or a newer one.
      const GravityMap* map = published_.load(std::memory_order_acquire);
      taken_sequence_ = sequence;
      if (map != current_) {
        previous_ = current_;
        current_ = map;
        blend_ = 0.0;
      }
    }
  }
  if (blend_ < 1.0) {
    const double ramp_s = options_.ramp_duration_s;
    blend_ = ramp_s > 0.0 ? std::min(1.0, blend_ + dt_s / ramp_s) : 1.0;
  }
  if (blend_ >= 1.0) {
    previous_ = nullptr;
    if (acknowledged_local_ != taken_sequence_) {
      // Release: every read of the older maps happened before this store.
      acknowledged_sequence_.store(taken_sequence_, std::memory_order_release);
      acknowledged_local_ = taken_sequence_;
    }
  }
}

Eigen::Vector3d GravityCompensatedDevice::compensation(const Eigen::Vector3d& position_m,
                                                       bool& inside) const noexcept {
  inside = true;
  Eigen::Vector3d gravity_n = Eigen::Vector3d::Zero();
  if (previous_ != nullptr) {
    gravity_n =
        (1.0 - blend_) * previous_->gravityAt(position_m, options_.outside_margin_m, inside);
  }
  if (current_ != nullptr) {
    bool inside_current = true;
    gravity_n +=
        blend_ * current_->gravityAt(position_m, options_.outside_margin_m, inside_current);
    inside = inside && inside_current;
  }
  return gravity_n;
}

void GravityCompensatedDevice::learnResolution(const Eigen::Vector3d& position_m) noexcept {
  if (has_last_position_) {
    // Squared first: the square root is paid only on the rare tick that finds a finer step.
    const double step_m2 = (position_m - last_position_m_).squaredNorm();
    if (step_m2 > 0.0 && step_m2 < resolution_m_ * resolution_m_) {
      resolution_m_ = std::sqrt(step_m2);
      resolution_status_m_.store(resolution_m_, std::memory_order_relaxed);
    }
  }
  last_position_m_ = position_m;
  has_last_position_ = true;
}

bool GravityCompensatedDevice::frozen(const Eigen::Vector3d& position_m,
                                      const Eigen::Vector3d& push_n, double dt_s) noexcept {
  if (options_.frozen_window_s <= 0.0) return false;
  if (!frozen_tracking_ || !bitwiseEqual(position_m, frozen_position_m_)) {
    // A new run of identical readings starts: the filter starts from the push of its first tick.
    frozen_tracking_ = true;
    frozen_detected_ = false;
    frozen_position_m_ = position_m;
    frozen_run_s_ = 0.0;
    push_stage_n_ = push_n;
    push_filtered_n_ = push_n;
    pushed_up_axes_ = 0;
    pushed_down_axes_ = 0;
    return false;
  }
  if (frozen_detected_) return true;  // lasts while the readings stay frozen
  frozen_run_s_ += dt_s;
  // Bilinear (Tustin) discretisation of the first-order low-pass, 1 - exp(-x) ~ 2x / (2 + x):
  // the same response at any rate to within 0.5 % for ticks up to 4 ms (2.7 % at the 10 ms
  // clamp), at the cost of a division instead of an exponential on every still tick.
  const double time_constant_s = options_.frozen_filter_time_constant_s;
  const double alpha = time_constant_s > 0.0 ? 2.0 * dt_s / (2.0 * time_constant_s + dt_s) : 1.0;
  push_stage_n_ += alpha * (push_n - push_stage_n_);
  push_filtered_n_ += alpha * (push_stage_n_ - push_filtered_n_);

  const double threshold_n =
      std::max(options_.frozen_force_floor_n,
               0.5 * options_.frozen_hand_stiffness_n_per_m * kHandCounts * resolution_m_);
  const double cone_n2 = kAxisConeCos2 * push_filtered_n_.squaredNorm();
  for (int axis = 0; axis < 3; ++axis) {
    const double component_n = push_filtered_n_[axis];
    if (component_n * component_n < cone_n2) continue;
    if (component_n >= threshold_n) pushed_up_axes_ |= static_cast<std::uint8_t>(1U << axis);
    if (component_n <= -threshold_n) pushed_down_axes_ |= static_cast<std::uint8_t>(1U << axis);
  }
  frozen_detected_ =
      (pushed_up_axes_ & pushed_down_axes_) != 0 && frozen_run_s_ >= options_.frozen_window_s;
  return frozen_detected_;
}

bool GravityCompensatedDevice::fault(ServoFault kind) noexcept {
  inner().setForce(Eigen::Vector3d::Zero());
  level_.store(0.0, std::memory_order_relaxed);
  // A frozen driver stays caught while its readings stay frozen; any other fault restarts the
  // tracking, since the readings in between were not usable.
  if (kind != ServoFault::kStalePosition) frozen_tracking_ = false;
  countTick(kind);
  return false;
}

void GravityCompensatedDevice::countTick(ServoFault kind) noexcept {
  active_fault_.store(kind, std::memory_order_relaxed);
  if (kind == ServoFault::kNone) return;
  last_fault_.store(kind, std::memory_order_relaxed);
  increment(fault_counts_[static_cast<std::size_t>(kind)]);
}

void GravityCompensatedDevice::resetServoState() noexcept {
  level_.store(0.0, std::memory_order_relaxed);
  frozen_tracking_ = false;
  has_last_time_ = false;
  stall_watching_ = false;
  has_last_position_ = false;
  outside_map_.store(false, std::memory_order_relaxed);
  cached_fresh_ = false;
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
  {
    const std::lock_guard<std::mutex> lock(publish_mutex_);
    const std::uint64_t sequence = next_sequence_++;
    const GravityMap* raw = map.get();
    retained_.push_back(RetainedMap{sequence, std::move(map)});
    published_.store(raw, std::memory_order_release);
    published_sequence_.store(sequence, std::memory_order_release);
  }
  reclaimRetiredMaps();
}

std::shared_ptr<const GravityMap> GravityCompensatedDevice::publishedMap() const {
  const std::lock_guard<std::mutex> lock(publish_mutex_);
  if (retained_.empty()) return nullptr;
  return retained_.back().map;
}

std::size_t GravityCompensatedDevice::reclaimRetiredMaps() {
  std::vector<RetainedMap> released;
  {
    const std::lock_guard<std::mutex> lock(publish_mutex_);
    // Acquire: pairs with the servo thread's release, so its last reads of these maps are done.
    const std::uint64_t acknowledged = acknowledged_sequence_.load(std::memory_order_acquire);
    auto keep = retained_.begin();
    for (auto it = retained_.begin(); it != retained_.end(); ++it) {
      if (it->sequence < acknowledged) {
        released.push_back(std::move(*it));
      } else {
        if (keep != it) *keep = std::move(*it);
        ++keep;
      }
    }
    retained_.erase(keep, retained_.end());
  }
  // The maps are destroyed here, outside the lock.
  return released.size();
}

std::size_t GravityCompensatedDevice::retainedMapCount() const {
  const std::lock_guard<std::mutex> lock(publish_mutex_);
  return retained_.size();
}

bool GravityCompensatedDevice::latestMapInUse() const noexcept {
  return acknowledged_sequence_.load(std::memory_order_acquire) ==
         published_sequence_.load(std::memory_order_acquire);
}

// --- Switch and status ------------------------------------------------------------------------

void GravityCompensatedDevice::setCompensationEnabled(bool enabled) noexcept {
  enabled_.store(enabled, std::memory_order_relaxed);
}

bool GravityCompensatedDevice::compensationEnabled() const noexcept {
  return enabled_.load(std::memory_order_relaxed);
}

double GravityCompensatedDevice::compensationLevel() const noexcept {
  return level_.load(std::memory_order_relaxed);
}

ServoFault GravityCompensatedDevice::activeFault() const noexcept {
  return active_fault_.load(std::memory_order_relaxed);
}

ServoFault GravityCompensatedDevice::lastFault() const noexcept {
  return last_fault_.load(std::memory_order_relaxed);
}

std::uint64_t GravityCompensatedDevice::faultCount() const noexcept {
  std::uint64_t total = 0;
  for (std::size_t i = 1; i < fault_counts_.size(); ++i) {
    total += fault_counts_[i].load(std::memory_order_relaxed);
  }
  return total;
}

std::uint64_t GravityCompensatedDevice::faultCount(ServoFault fault) const noexcept {
  const auto index = static_cast<std::size_t>(fault);
  return index < fault_counts_.size() ? fault_counts_[index].load(std::memory_order_relaxed) : 0;
}

std::uint64_t GravityCompensatedDevice::clampCount() const noexcept {
  return clamp_count_.load(std::memory_order_relaxed);
}

std::uint64_t GravityCompensatedDevice::tickCount() const noexcept {
  return tick_count_.load(std::memory_order_relaxed);
}

bool GravityCompensatedDevice::outsideMap() const noexcept {
  return outside_map_.load(std::memory_order_relaxed);
}

std::uint64_t GravityCompensatedDevice::outsideMapTickCount() const noexcept {
  return outside_map_ticks_.load(std::memory_order_relaxed);
}

bool GravityCompensatedDevice::fadeStalled() const noexcept {
  return fade_stalled_.load(std::memory_order_relaxed);
}

double GravityCompensatedDevice::positionResolution_m() const noexcept {
  return resolution_status_m_.load(std::memory_order_relaxed);
}

}  // namespace autograv
