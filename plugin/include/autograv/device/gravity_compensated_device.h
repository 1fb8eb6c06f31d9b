#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"
#include "autograv/map/gravity_map.h"

namespace autograv {

/// Why the decorator did not send the application's force plus compensation on a servo tick.
enum class ServoFault : std::uint8_t {
  kNone,               ///< The tick was normal.
  kReadFailed,         ///< The inner getPosition returned false.
  kNonFinitePosition,  ///< The position had a NaN or Inf component.
  kStalePosition,      ///< Bit-identical positions while the commanded force kept changing.
  kOutsideMap,         ///< Farther than the margin outside the grid of the map in use.
  kNonFiniteForce,     ///< The application asked for a NaN or Inf force.
  kNoForceLimit,       ///< specifications().max_linear_force_n is not a positive number.
  kWriteFailed,        ///< The inner setForce returned false.
};
inline constexpr int kServoFaultKinds = 8;

/// Stable lower-case name ("none", "read_failed", "stale_position", ...).
const char* toString(ServoFault fault) noexcept;

/// Settings of GravityCompensatedDevice, fixed at construction.
struct CompensationOptions {
  /// Period of the servo loop that calls setForce, once per tick. Ramps are counted in ticks of
  /// this period (deterministic, no clock read in the servo path). Unit: [s]
  double servo_period_s = 1.0e-3;
  /// Time over which compensation fades in after enable, a fault or open(), out after disable,
  /// and from one map to the next after publishMap. 0 switches at once. Unit: [s]
  double ramp_duration_s = 0.5;
  /// Positions up to this far outside the map's grid get the boundary value (interpolation
  /// clamps); farther out is a kOutsideMap fault. Checked only while compensation is enabled.
  /// Unit: [m]
  double outside_margin_m = 0.01;
  /// A position identical bit for bit on more than this many consecutive ticks while the
  /// commanded force moved by more than stale_force_change_n is a kStalePosition fault (a frozen
  /// driver). 0 disables the check.
  int stale_tick_limit = 200;
  /// See stale_tick_limit. Unit: [N]
  double stale_force_change_n = 0.5;
  /// Whether compensation starts enabled (it still ramps in).
  bool enabled = true;
};

/// The drop-in wrapper: a HapticDevice that forwards every call to an inner device and, in
/// setForce(F), sends F + G_hat(X), G_hat being the trilinear interpolation of the published
/// gravity map at the latest position X.
///
/// Ownership: the inner device is held by std::shared_ptr, so the wrapper can never outlive it
/// (CHAI3D shares devices the same way, cGenericHapticDevicePtr). Maps are shared too: the
/// application may drop its own reference right after publishMap().
///
/// Threads: the servo thread calls setForce, getPosition, getLinearVelocity and getUserSwitch;
/// any other thread may call publishMap, setCompensationEnabled and the status getters while it
/// runs. open, close and calibrate are called while no servo loop runs.
///
/// Position used by setForce: if the servo thread called getPosition since the previous setForce,
/// that reading (success flag included) is used, so a usual loop (read, compute, write) costs no
/// extra driver call; otherwise setForce reads the inner device itself. Readings by other threads
/// are forwarded but never used for compensation.
///
/// Faults: on a failed read, a NaN/Inf or stale position, a position far outside the map, a
/// NaN/Inf application force or a missing force limit, the wrapper sends ZERO force (not the last
/// force) and returns false. Zero is what an unpowered device does and every device tolerates;
/// a held force on an end-effector whose position is unknown can push it into its stops or the
/// user's hand. After the fault clears, the application force passes at once and compensation
/// ramps in again from zero, so recovery does not jolt either.
///
/// Stale position: bit-identical readings on more than stale_tick_limit consecutive ticks while
/// the commanded force (F + G_hat, before clamping) moved by more than stale_force_change_n from
/// its value at the start of the run. A free end-effector moves by at least an encoder count when
/// its force changes that much; a device held rigidly or pushed against its stops can fool the
/// check, which is why both thresholds are options.
///
/// Map publication: publishMap stores a raw pointer in an atomic and bumps a sequence number. The
/// servo thread picks the new map up at the start of a tick (never during a fade), fades from the
/// old map to the new one over ramp_duration_s, then acknowledges the sequence number it took.
/// Maps published before the acknowledged one are released by publishMap or reclaimRetiredMaps on
/// the publishing thread; the servo thread never frees, locks or allocates.
class GravityCompensatedDevice final : public HapticDevice {
 public:
  /// Throws autograv::Error for a null device or unusable options. No compensation until a map
  /// is published (after open(), since maps are checked against the device's model name).
  /// Not real-time safe.
  explicit GravityCompensatedDevice(std::shared_ptr<HapticDevice> inner,
                                    const CompensationOptions& options = {});
  /// The servo loop must have stopped. Not real-time safe.
  ~GravityCompensatedDevice() override;
  GravityCompensatedDevice(const GravityCompensatedDevice&) = delete;
  GravityCompensatedDevice& operator=(const GravityCompensatedDevice&) = delete;

  // --- HapticDevice ---------------------------------------------------------------------------
  /// Forwards; compensation will ramp in from zero. Not real-time safe.
  bool open() override;
  /// Forwards (the inner device sends zero force); compensation restarts from zero on the next
  /// tick. Not real-time safe.
  bool close() override;
  /// Forwards. Not real-time safe.
  bool calibrate(bool force = false) override;
  /// Forwards, and on the servo thread remembers the reading for the next setForce.
  /// Real-time safe when the inner device's is.
  bool getPosition(Eigen::Vector3d& position_m) override;
  /// Forwards. Real-time safe when the inner device's is.
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override;
  /// Forwards. Real-time safe when the inner device's is.
  bool getUserSwitch(int index, bool& pressed) override;
  /// Sends force_n + G_hat(X), clamped to max_linear_force_n keeping its direction; zero on a
  /// fault (see the class comment). One call is one servo tick. Returns false on a fault.
  /// Real-time safe: no allocation, no lock, no throw (when the inner device's calls are).
  /// Unit: [N]
  bool setForce(const Eigen::Vector3d& force_n) override;
  /// The inner device's specifications. Real-time safe.
  const DeviceSpecifications& specifications() const override;

  // --- Maps -----------------------------------------------------------------------------------
  /// Makes `map` the map of the running servo loop (null removes compensation, fading out).
  /// Throws autograv::Error when the map's device model differs from the inner device's
  /// specifications().model_name (or the device reports none yet: open() it first), unless
  /// `allow_model_mismatch`. Also releases maps the servo thread no longer uses.
  /// Any thread; not real-time safe.
  void publishMap(std::shared_ptr<const GravityMap> map, bool allow_model_mismatch = false);
  /// The latest published map (possibly still fading in). Any thread; not real-time safe.
  std::shared_ptr<const GravityMap> publishedMap() const;
  /// Releases maps the servo thread has stopped using; returns how many references it dropped.
  /// Any thread; not real-time safe.
  std::size_t reclaimRetiredMaps();
  /// Published maps still held (the latest one included). Any thread; not real-time safe.
  std::size_t retainedMapCount() const;
  /// True once the servo thread has taken the latest published map and finished fading to it.
  /// Any thread; real-time safe.
  bool latestMapInUse() const noexcept;

  // --- Compensation switch and status (any thread, real-time safe) ---------------------------
  /// Fades compensation in or out over ramp_duration_s.
  void setCompensationEnabled(bool enabled) noexcept;
  bool compensationEnabled() const noexcept;
  /// Current compensation gain in [0, 1] (the ramp).
  double compensationLevel() const noexcept;
  /// Fault of the latest tick (kNone when it was normal).
  ServoFault activeFault() const noexcept;
  /// Latest fault ever seen (kNone if none): stays set after the fault clears.
  ServoFault lastFault() const noexcept;
  /// Ticks that ended in any fault.
  std::uint64_t faultCount() const noexcept;
  /// Ticks that ended in `fault`.
  std::uint64_t faultCount(ServoFault fault) const noexcept;
  /// Ticks whose force was scaled down to max_linear_force_n.
  std::uint64_t clampCount() const noexcept;
  /// setForce calls so far.
  std::uint64_t tickCount() const noexcept;

  const CompensationOptions& options() const noexcept { return options_; }
  /// The wrapped device. Not real-time safe to use from a thread other than the servo thread.
  HapticDevice& innerDevice() noexcept { return *inner_; }

 private:
  struct RetainedMap {
    std::uint64_t sequence;
    std::shared_ptr<const GravityMap> map;  // null when null was published
  };

  void takeNewMap() noexcept;
  /// The maps' gravity at `position_m`, blended during a fade; `inside` is false when the
  /// position is beyond the outside margin of a map in use.
  Eigen::Vector3d compensation(const Eigen::Vector3d& position_m, bool& inside) const noexcept;
  bool stale(const Eigen::Vector3d& position_m, const Eigen::Vector3d& commanded_n) noexcept;
  bool fault(ServoFault fault) noexcept;
  void countTick(ServoFault fault) noexcept;
  void resetServoState() noexcept;
  std::size_t reclaimLocked();

  std::shared_ptr<HapticDevice> inner_;
  CompensationOptions options_;
  int ramp_ticks_;

  // Publication (written by publishers under publish_mutex_, read by the servo thread).
  mutable std::mutex publish_mutex_;  // never taken by the servo thread
  std::vector<RetainedMap> retained_;
  std::uint64_t next_sequence_ = 1;
  std::atomic<const GravityMap*> published_{nullptr};
  std::atomic<std::uint64_t> published_sequence_{0};
  std::atomic<std::uint64_t> acknowledged_sequence_{0};

  // Servo-thread state.
  const GravityMap* current_ = nullptr;
  const GravityMap* previous_ = nullptr;
  std::uint64_t taken_sequence_ = 0;
  std::uint64_t acknowledged_local_ = 0;
  int blend_ticks_ = 0;
  int stale_ticks_ = 0;
  Eigen::Vector3d stale_position_m_ = Eigen::Vector3d::Constant(0.0);
  Eigen::Vector3d stale_start_force_n_ = Eigen::Vector3d::Zero();
  bool stale_tracking_ = false;
  bool stale_force_moved_ = false;
  Eigen::Vector3d cached_position_m_ = Eigen::Vector3d::Zero();
  bool cached_ok_ = false;
  bool cached_fresh_ = false;
  std::atomic<const void*> servo_thread_{nullptr};  // the servo thread's token, see the .cpp
  static_assert(std::atomic<const void*>::is_always_lock_free,
                "the servo path needs a lock-free thread token");

  // Shared status (servo thread writes, anyone reads).
  std::atomic<bool> enabled_;
  std::atomic<int> level_ticks_{0};
  std::atomic<ServoFault> active_fault_{ServoFault::kNone};
  std::atomic<ServoFault> last_fault_{ServoFault::kNone};
  std::array<std::atomic<std::uint64_t>, kServoFaultKinds> fault_counts_{};
  std::atomic<std::uint64_t> clamp_count_{0};
  std::atomic<std::uint64_t> tick_count_{0};
};

}  // namespace autograv
