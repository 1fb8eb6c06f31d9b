#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"
#include "autograv/device/forwarding_device.h"
#include "autograv/device/haptic_device.h"
#include "autograv/device/servo_clock.h"

namespace autograv {

class GravityMap;

/// Why the decorator did not send the application's force plus compensation on a servo tick.
/// Only a position that cannot be trusted, a force that cannot be sent or a device without a
/// force limit is a fault; being outside the map is not (see GravityCompensatedDevice::outsideMap).
enum class ServoFault : std::uint8_t {
  kNone,               ///< The tick was normal.
  kReadFailed,         ///< The inner getPosition returned false.
  kNonFinitePosition,  ///< The position had a NaN or Inf component.
  kStalePosition,      ///< The driver's readings froze (see the class comment for the rule).
  kNonFiniteForce,     ///< The application asked for a NaN or Inf force.
  kNoForceLimit,       ///< specifications().max_linear_force_n is not a positive number.
  kWriteFailed,        ///< The inner setForce returned false.
};
inline constexpr int kServoFaultKinds = 7;

/// Stable lower-case name ("none", "read_failed", "stale_position", ...).
const char* toString(ServoFault fault) noexcept;

/// Settings of GravityCompensatedDevice, fixed at construction. Durations are in seconds of the
/// clock, whatever the loop's rate.
struct CompensationOptions {
  /// Read once per setForce to measure the tick's duration. Null: a SteadyServoClock (wall
  /// time). Loops that run in simulated time give a FixedPeriodServoClock or their own.
  std::shared_ptr<ServoClock> clock;
  /// A tick counts for at most this long: the first tick counts for nothing, and a loop that
  /// paused (debugger, swapped out) resumes its ramps where they were. Unit: [s]
  double max_tick_interval_s = 0.01;
  /// Time over which compensation fades in after enable, a fault or open(), out after disable,
  /// and from one map to the next after publishMap (the first map fades in from none).
  /// 0 switches at once. Unit: [s]
  double ramp_duration_s = 0.5;
  /// How far outside the map's grid a position must be to be reported by outsideMap(). Only a
  /// status: compensation and the application's force go on there (see the class comment).
  /// Unit: [m]
  double outside_margin_m = 0.01;
  /// The frozen-driver check raises kStalePosition no earlier than this long into a run of
  /// bit-identical readings. 0 disables the check. Unit: [s]
  double frozen_window_s = 0.1;
  /// Smallest push that counts as evidence of a frozen driver. Unit: [N]
  double frozen_force_floor_n = 0.2;
  /// The stiffest grip a hand holding the end-effector still can have. Unit: [N/m]
  double frozen_hand_stiffness_n_per_m = 5000.0;
  /// Time constant of each of the two low-pass stages the push is filtered by, so that a
  /// vibration the application plays is not taken for a sustained push. Unit: [s]
  double frozen_filter_time_constant_s = 0.015;
  /// Whether compensation starts enabled (it still ramps in).
  bool enabled = true;
  /// Thermal time constant of the device's motors, over which thermalLoad() averages the heat
  /// of the forces sent. The default is a small DC motor's (kDefaultMotorTimeConstant_s); a
  /// larger motor heats more slowly. The calibration counts its load with the same default.
  /// Unit: [s]
  double motor_time_constant_s = kDefaultMotorTimeConstant_s;
  /// Whether the compensation follows the motors' warming by the map's thermal correction
  /// (MapMetadata::thermal_drift at thermalLoad()). Off sends the map as measured, cold.
  bool correct_thermal_drift = true;
  /// The motors' thermal load when the decorator is made (thermalLoad() starts there): 0, motors
  /// at room temperature, unless the application knows better, as right after a calibration on
  /// the same motors (AutoCalibrator::thermalLoad at its end, or the map's
  /// thermal_drift.again_load). In [0, 10].
  double initial_thermal_load = 0.0;
};

/// The drop-in wrapper: a HapticDevice that forwards every call to an inner device and, in
/// setForce(F), sends F + G_hat(X), G_hat being the trilinear interpolation of the published
/// gravity map at the latest position X, scaled by the map's thermal correction at the motors'
/// present load (thermalScale of MapMetadata::thermal_drift at thermalLoad(): motors that warm
/// give less torque per command, and the calibration measured how much less).
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
/// Faults: only when the position cannot be trusted (a failed read, NaN/Inf, a frozen driver),
/// the application's force is NaN/Inf or the device has no force limit, the wrapper sends ZERO
/// force (not the last force) and returns false. Zero is what an unpowered device does and every
/// device tolerates; a held force on an end-effector whose position is unknown can push it into
/// its stops or the user's hand. After the fault clears, the application force passes at once
/// and compensation ramps in again from zero, so recovery does not jolt either.
///
/// Outside the map: the application's force always passes, and compensation goes on with the
/// map extended linearly from its boundary cell for one cell, and held at the value reached
/// there further out (GravityMap::gravityAt). That value is continuous across the boundary (no
/// step when the hand leaves or re-enters the map) and bounded by a combination of measured
/// estimates (an unlimited extrapolation grows with the distance and would push the end-effector
/// off); the slope of a smooth field makes it a better guess than the boundary value. Fading
/// compensation out over a band would drop the stylus, the very jolt a user notices.
/// outsideMap() and outsideMapTickCount() tell the application, which may show it.
///
/// Frozen driver (kStalePosition). Bit-identical readings alone prove nothing: an encoder at
/// rest reads the same count forever, in a dock, on a stop or in a still hand. The check uses the
/// physics of what can hold an end-effector still. The push P = (force sent) - G_hat(X), the net
/// force on the end-effector once the map's gravity is accounted for, is low-passed (two stages
/// of frozen_filter_time_constant_s, so a vibration the application plays is not a push). Over a
/// run of bit-identical readings the check notes, for each axis, whether the filtered push
/// pointed within 45 degrees of +axis with a component >= D, and of -axis likewise. Both on one
/// axis, after frozen_window_s of the run, is a frozen driver:
///  - a single end stop (or dock floor) resists only pushes into a friction cone around its
///    normal: with a friction coefficient below 1 that cone is narrower than 90 degrees, and the
///    two pushes are at least 90 degrees apart;
///  - a hand is a spring of at most frozen_hand_stiffness_n_per_m (k): the push changed by at
///    least 2 D, and D = max(frozen_force_floor_n, k * 3 counts * resolution / 2) moves the hand
///    by 3 encoder counts at least, and some count would have changed.
/// The encoder resolution is learned online, as the smallest nonzero step between two
/// successive readings (1e-4 m, coarser than any supported device, until a step is seen).
/// Bounds: a free end-effector whose push swings both ways by D is caught frozen_window_s after
/// the readings froze at the earliest, as soon as the filtered push has swung (e.g. within
/// 0.3 s for a +-1 N push at 5 Hz); a push that only changes in size, or a constant one, is never
/// evidence. It can fire on an end-effector clamped both ways (a vice, a two-sided dock) while
/// the application pushes it back and forth, and, without a map, the device's own weight is
/// counted in the push.
///
/// Timing: every ramp and window is in seconds of options().clock, read once per setForce; a
/// tick counts for the time since the previous one, clamped to max_tick_interval_s.
///
/// Map publication: publishMap stores a raw pointer in an atomic and bumps a sequence number. The
/// servo thread picks the new map up at the start of a tick (never during a fade), fades from the
/// old map (or from none, for the first) to the new one over ramp_duration_s, then acknowledges the
/// sequence number it took. Maps published before the acknowledged one are released by publishMap
/// or reclaimRetiredMaps on the publishing thread; the servo thread never frees, locks or
/// allocates.
class GravityCompensatedDevice final : public ForwardingDevice {
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
  // calibrate, getLinearVelocity, getUserSwitch and specifications are ForwardingDevice's: passed
  // to the inner device unchanged, real-time safe when the inner device's are.

  /// Forwards; compensation will ramp in from zero. Not real-time safe.
  bool open() override;
  /// Forwards (the inner device sends zero force); compensation restarts from zero on the next
  /// tick. Not real-time safe.
  bool close() override;
  /// Forwards, and on the servo thread remembers the reading for the next setForce.
  /// Real-time safe when the inner device's is.
  bool getPosition(Eigen::Vector3d& position_m) override;
  /// Sends force_n + G_hat(X), clamped to max_linear_force_n keeping its direction; zero on a
  /// fault (see the class comment). One call is one servo tick. Returns false on a fault.
  /// Real-time safe: no allocation, no lock, no throw (when the inner device's calls are).
  /// Unit: [N]
  bool setForce(const Eigen::Vector3d& force_n) override;

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
  /// Whether compensation is switched on (it may still be ramping).
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
  /// True when the latest tick's position was farther than outside_margin_m outside the grid of
  /// a map in use: compensation there is extrapolated from the boundary, a less certain estimate
  /// the application may want to show. Not a fault.
  bool outsideMap() const noexcept;
  /// Ticks whose position was outside the map (see outsideMap).
  std::uint64_t outsideMapTickCount() const noexcept;
  /// The encoder resolution the frozen-driver check has learned so far. Unit: [m]
  double positionResolution_m() const noexcept;
  /// How hard the forces sent work the motors: the square of the force sent over the device's
  /// continuous force rating (continuousForceRating_n), averaged over
  /// CompensationOptions::motor_time_constant_s. A motor's heat goes with the square of its
  /// force, and the rating is the force whose heat brings it to its largest allowed
  /// temperature: near 1 for minutes, the motors run near that temperature; above 1, hotter
  /// than rated. A warm motor holds less torque per command: the map's thermal correction
  /// (MapMetadata::thermal_drift) scales the compensation by this load. Forces the device never
  /// delivered (a failed write, a fault's zero) count as zero. Starts at
  /// CompensationOptions::initial_thermal_load (0: motors at room temperature), and is kept
  /// across close() and open(), as the motors keep their heat.
  /// Any thread; real-time safe.
  double thermalLoad() const noexcept;
  /// True once a fade (a map fading in or out, compensation ramping) made no real progress:
  /// kStalledFadeTicks ticks passed within less than kStalledFadeSpan_s of options().clock, a
  /// loop faster than 50 kHz. That is a loop in simulated time with the default
  /// SteadyServoClock: its fades last ramp_duration_s of wall time, so its first seconds of
  /// simulated time get almost no compensation. Pass a FixedPeriodServoClock (or the loop's own
  /// clock) in CompensationOptions::clock. A real loop at 1 to 10 kHz, jittery or not, never sets
  /// it; only a loop catching up 500 ticks in one burst could. Stays set. A status only:
  /// compensation goes on as before. Any thread; real-time safe.
  bool fadeStalled() const noexcept;
  /// Ticks of a fade in a row, within kStalledFadeSpan_s of the clock, that set fadeStalled().
  static constexpr int kStalledFadeTicks = 500;
  /// See kStalledFadeTicks. Unit: [s]
  static constexpr double kStalledFadeSpan_s = 0.01;

  /// The options given at construction. Any thread; real-time safe.
  const CompensationOptions& options() const noexcept { return options_; }
  /// The wrapped device. Not real-time safe to use from a thread other than the servo thread.
  HapticDevice& innerDevice() noexcept { return inner(); }

 private:
  /// The units the decorator is made of, private to core: the map hand-off, the maps in use and
  /// their fade, the tick timer, the fade-stall watch, the position cache, the frozen-driver
  /// detector and the status block (plugin/src/core/compensation/).
  struct Impl;

  /// Sends zero force, restarts the ramp and counts `fault`; returns false. Real-time safe.
  bool fault(ServoFault fault) noexcept;
  /// What open() and close() restart: ramps, timing, the frozen-driver run, the cached reading.
  void resetServoState() noexcept;

  CompensationOptions options_;
  std::unique_ptr<Impl> impl_;  ///< Created by the constructor, never null.
};

}  // namespace autograv
