#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "autograv/compensation/gravity_compensated_device.h"

namespace autograv {

/// What GravityCompensatedDevice's status getters read: written by the servo thread (and the
/// switch by any thread), read by any thread. Internal to core. Every member is a lock-free
/// atomic accessed relaxed: each is a value of its own, none orders another.
struct CompensationStatus {
  /// `enabled`: the switch's initial position; `resolution_m`: the frozen-driver check's
  /// initial resolution. Unit: [m]
  CompensationStatus(bool enabled, double resolution_m) noexcept
      : enabled(enabled), resolution_m(resolution_m) {}

  /// Counters have a single writer (the servo thread): a relaxed load and store is enough and
  /// avoids the locked read-modify-write of fetch_add. Real-time safe.
  static void increment(std::atomic<std::uint64_t>& counter) noexcept {
    counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
  }
  /// Records the end of a tick in `fault` (kNone: a normal tick). Servo thread; real-time safe.
  void countTick(ServoFault fault) noexcept {
    active_fault.store(fault, std::memory_order_relaxed);
    if (fault == ServoFault::kNone) return;
    last_fault.store(fault, std::memory_order_relaxed);
    increment(fault_counts[static_cast<std::size_t>(fault)]);
  }
  /// Ticks that ended in any fault. Any thread; real-time safe.
  std::uint64_t faultTotal() const noexcept;

  std::atomic<bool> enabled;         ///< The switch (setCompensationEnabled).
  std::atomic<double> level{0.0};    ///< Compensation gain in [0, 1], the ramp.
  std::atomic<double> resolution_m;  ///< Learned encoder resolution. Unit: [m]
  std::atomic<bool> outside_map{false};
  std::atomic<std::uint64_t> outside_map_ticks{0};
  std::atomic<ServoFault> active_fault{ServoFault::kNone};
  std::atomic<ServoFault> last_fault{ServoFault::kNone};
  std::array<std::atomic<std::uint64_t>, kServoFaultKinds> fault_counts{};
  std::atomic<std::uint64_t> clamp_count{0};
  std::atomic<std::uint64_t> tick_count{0};
  std::atomic<bool> fade_stalled{false};
  std::atomic<double> thermal_load{0.0};  ///< GravityCompensatedDevice::thermalLoad.

  static_assert(std::atomic<double>::is_always_lock_free,
                "the servo path needs a lock-free compensation level");
  static_assert(std::atomic<std::uint64_t>::is_always_lock_free,
                "the servo path needs lock-free counters");
};

}  // namespace autograv
