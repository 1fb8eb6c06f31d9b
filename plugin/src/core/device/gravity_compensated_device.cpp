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
    "none",        "read_failed",      "non_finite_position", "stale_position",
    "outside_map", "non_finite_force", "no_force_limit",      "write_failed"};

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
    : inner_(std::move(inner)), options_(options), ramp_ticks_(1), enabled_(options.enabled) {
  if (!inner_) throw Error("GravityCompensatedDevice: the inner device is null");
  const auto check = [](bool ok, const char* field, double value, const char* expected) {
    if (ok) return;
    std::ostringstream message;
    message << "GravityCompensatedDevice: CompensationOptions::" << field << " must be " << expected
            << ", got " << value;
    throw Error(message.str());
  };
  check(std::isfinite(options.servo_period_s) && options.servo_period_s > 0.0, "servo_period_s",
        options.servo_period_s, "a positive time in seconds");
  check(std::isfinite(options.ramp_duration_s) && options.ramp_duration_s >= 0.0 &&
            options.ramp_duration_s / options.servo_period_s < 1e9,
        "ramp_duration_s", options.ramp_duration_s,
        "a time >= 0 in seconds, under 1e9 servo periods");
  check(std::isfinite(options.outside_margin_m) && options.outside_margin_m >= 0.0,
        "outside_margin_m", options.outside_margin_m, "a length >= 0 in metres");
  check(options.stale_tick_limit >= 0, "stale_tick_limit", options.stale_tick_limit,
        "a tick count >= 0 (0 disables the check)");
  check(std::isfinite(options.stale_force_change_n) && options.stale_force_change_n >= 0.0,
        "stale_force_change_n", options.stale_force_change_n, "a force >= 0 in newtons");
  // One tick at least, so that "ramp over zero time" means "full on the first tick".
  ramp_ticks_ =
      std::max(1, static_cast<int>(std::lround(options.ramp_duration_s / options.servo_period_s)));
  blend_ticks_ = ramp_ticks_;
}

GravityCompensatedDevice::~GravityCompensatedDevice() = default;

// --- Forwarded methods ------------------------------------------------------------------------

bool GravityCompensatedDevice::open() {
  const bool ok = inner_->open();
  resetServoState();
  return ok;
}

bool GravityCompensatedDevice::close() {
  const bool ok = inner_->close();
  resetServoState();
  return ok;
}

bool GravityCompensatedDevice::calibrate(bool force) { return inner_->calibrate(force); }

bool GravityCompensatedDevice::getPosition(Eigen::Vector3d& position_m) {
  const bool ok = inner_->getPosition(position_m);
  // Only the servo thread's reading may stand for "the latest position" in setForce: a graphics
  // thread reading the device must neither race with it nor feed it an older sample.
  if (servo_thread_.load(std::memory_order_relaxed) == currentThreadToken()) {
    cached_position_m_ = position_m;
    cached_ok_ = ok;
    cached_fresh_ = true;
  }
  return ok;
}

bool GravityCompensatedDevice::getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) {
  return inner_->getLinearVelocity(velocity_m_per_s);
}

bool GravityCompensatedDevice::getUserSwitch(int index, bool& pressed) {
  return inner_->getUserSwitch(index, pressed);
}

const DeviceSpecifications& GravityCompensatedDevice::specifications() const {
  return inner_->specifications();
}

// --- Servo path -------------------------------------------------------------------------------

bool GravityCompensatedDevice::setForce(const Eigen::Vector3d& force_n) {
  const void* const self = currentThreadToken();
  if (servo_thread_.load(std::memory_order_relaxed) != self) {
    servo_thread_.store(self, std::memory_order_relaxed);
    cached_fresh_ = false;  // a reading from before this thread became the servo thread
  }
  increment(tick_count_);
  // Out of line only when there is something to do: a new publication or a fade in progress.
  if (blend_ticks_ < ramp_ticks_ ||
      published_sequence_.load(std::memory_order_acquire) != taken_sequence_) {
    takeNewMap();
  }

  Eigen::Vector3d position_m;
  bool read_ok;
  if (cached_fresh_) {
    position_m = cached_position_m_;
    read_ok = cached_ok_;
  } else {
    read_ok = inner_->getPosition(position_m);
  }
  cached_fresh_ = false;

  if (!read_ok) return fault(ServoFault::kReadFailed);
  if (!position_m.allFinite()) return fault(ServoFault::kNonFinitePosition);
  if (!force_n.allFinite()) return fault(ServoFault::kNonFiniteForce);
  const double max_force_n = inner_->specifications().max_linear_force_n;
  if (!(std::isfinite(max_force_n) && max_force_n > 0.0)) return fault(ServoFault::kNoForceLimit);
  const bool enabled = enabled_.load(std::memory_order_relaxed);

  int level = level_ticks_.load(std::memory_order_relaxed);
  if (enabled && level < ramp_ticks_) {
    ++level;
  } else if (!enabled && level > 0) {
    --level;
  }
  level_ticks_.store(level, std::memory_order_relaxed);

  Eigen::Vector3d commanded_n = force_n;
  if (level > 0) {  // always the case while enabled
    bool inside = true;
    // The usual case inline: one map and no fade in progress.
    const Eigen::Vector3d gravity_n =
        previous_ == nullptr && current_ != nullptr
            ? current_->gravityAt(position_m, options_.outside_margin_m, inside)
            : compensation(position_m, inside);
    // Beyond the map, the clamped boundary value is a guess: refuse it, except while fading out.
    if (enabled && !inside) return fault(ServoFault::kOutsideMap);
    commanded_n += (static_cast<double>(level) / ramp_ticks_) * gravity_n;
  }
  if (stale(position_m, commanded_n)) return fault(ServoFault::kStalePosition);

  // Squared norms first: the square root is paid only when the force is actually clamped.
  const double squared_n2 = commanded_n.squaredNorm();
  if (squared_n2 > max_force_n * max_force_n) {
    // Divided by its largest component first: a finite force whose square overflows (1e200 N)
    // is clamped along its own direction too, instead of being scaled by max / inf = 0.
    const Eigen::Vector3d direction = commanded_n / commanded_n.cwiseAbs().maxCoeff();
    commanded_n = direction * (max_force_n / direction.norm());
    increment(clamp_count_);
  }
  if (!inner_->setForce(commanded_n)) {
    // The force did not reach the actuators: whatever they do now, restart the ramp so that the
    // compensation does not arrive as a step when writes work again.
    level_ticks_.store(0, std::memory_order_relaxed);
    countTick(ServoFault::kWriteFailed);
    return false;
  }
  countTick(ServoFault::kNone);
  return true;
}

void GravityCompensatedDevice::takeNewMap() noexcept {
  // A new map is taken only between fades, so at most two maps are ever in use.
  if (blend_ticks_ >= ramp_ticks_) {
    const std::uint64_t sequence = published_sequence_.load(std::memory_order_acquire);
    if (sequence != taken_sequence_) {
      // Read after the sequence number: this is the map of that publication or a newer one.
      const GravityMap* map = published_.load(std::memory_order_acquire);
      taken_sequence_ = sequence;
      if (map != current_) {
        previous_ = current_;
        current_ = map;
        blend_ticks_ = 0;
      }
    }
  }
  if (blend_ticks_ < ramp_ticks_) ++blend_ticks_;
  if (blend_ticks_ >= ramp_ticks_) {
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
  if (previous_ == nullptr) {
    return current_ != nullptr ? current_->gravityAt(position_m, options_.outside_margin_m, inside)
                               : Eigen::Vector3d::Zero();
  }
  const double weight = static_cast<double>(blend_ticks_) / ramp_ticks_;
  Eigen::Vector3d gravity_n =
      (1.0 - weight) * previous_->gravityAt(position_m, options_.outside_margin_m, inside);
  if (current_ != nullptr) {
    bool inside_current = true;
    gravity_n +=
        weight * current_->gravityAt(position_m, options_.outside_margin_m, inside_current);
    inside = inside && inside_current;
  }
  return gravity_n;
}

bool GravityCompensatedDevice::stale(const Eigen::Vector3d& position_m,
                                     const Eigen::Vector3d& commanded_n) noexcept {
  if (options_.stale_tick_limit <= 0) return false;
  if (!stale_tracking_ || !bitwiseEqual(position_m, stale_position_m_)) {
    stale_tracking_ = true;
    stale_position_m_ = position_m;
    stale_start_force_n_ = commanded_n;
    stale_ticks_ = 0;
    stale_force_moved_ = false;
    return false;
  }
  if (stale_ticks_ < options_.stale_tick_limit + 1) ++stale_ticks_;
  const double threshold_n = options_.stale_force_change_n;
  if ((commanded_n - stale_start_force_n_).squaredNorm() > threshold_n * threshold_n) {
    stale_force_moved_ = true;
  }
  return stale_force_moved_ && stale_ticks_ > options_.stale_tick_limit;
}

bool GravityCompensatedDevice::fault(ServoFault kind) noexcept {
  inner_->setForce(Eigen::Vector3d::Zero());
  level_ticks_.store(0, std::memory_order_relaxed);
  // A stale fault lasts while the position stays frozen; any other fault restarts the tracking.
  if (kind != ServoFault::kStalePosition) stale_tracking_ = false;
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
  level_ticks_.store(0, std::memory_order_relaxed);
  stale_tracking_ = false;
  cached_fresh_ = false;
}

// --- Publication (non-real-time side) ---------------------------------------------------------

void GravityCompensatedDevice::publishMap(std::shared_ptr<const GravityMap> map,
                                          bool allow_model_mismatch) {
  if (map && !allow_model_mismatch) {
    const std::string& device_model = inner_->specifications().model_name;
    const std::string& map_model = map->metadata().device_model;
    if (device_model.empty()) {
      throw Error(
          "GravityCompensatedDevice: the device reports no model name, so the map made for '" +
          map_model + "' cannot be checked against it; open() the device first");
    }
    if (device_model != map_model) {
      throw Error("GravityCompensatedDevice: the map was calibrated on a '" + map_model +
                  "' but the device is a '" + device_model +
                  "'; calibrate this device, or allow the mismatch explicitly");
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
  return static_cast<double>(level_ticks_.load(std::memory_order_relaxed)) / ramp_ticks_;
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

}  // namespace autograv
