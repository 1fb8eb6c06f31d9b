#pragma once

#include <atomic>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"

namespace autograv {

/// The servo thread's latest getPosition, kept for the setForce that follows so that a usual
/// loop (read, compute, write) costs no second driver call. Readings by other threads are
/// never kept. Internal to core. Real-time safe throughout.
class ServoPositionCache {
 public:
  /// setForce: the calling thread becomes the servo thread; a reading kept from before it was
  /// is dropped.
  void claimForCallingThread() noexcept {
    const void* const self = currentThreadToken();
    if (servo_thread_.load(std::memory_order_relaxed) == self) return;
    servo_thread_.store(self, std::memory_order_relaxed);
    fresh_ = false;
  }
  /// getPosition: keeps the reading (success flag included) when the calling thread is the
  /// servo thread. A graphics thread reading the device must neither race with it nor feed it
  /// an older sample. Unit: [m]
  void offer(const Eigen::Vector3d& position_m, bool ok) noexcept {
    if (servo_thread_.load(std::memory_order_relaxed) != currentThreadToken()) return;
    position_m_ = position_m;
    ok_ = ok;
    fresh_ = true;
  }
  /// setForce: the reading kept since the previous setForce, or else one read from `device`
  /// now; returns its success flag. Either way nothing stays kept. Unit: [m]
  bool take(HapticDevice& device, Eigen::Vector3d& position_m) noexcept {
    bool ok;
    if (fresh_) {
      position_m = position_m_;
      ok = ok_;
    } else {
      ok = device.getPosition(position_m);
    }
    fresh_ = false;
    return ok;
  }
  /// Drops a kept reading (after open or close).
  void reset() noexcept { fresh_ = false; }

 private:
  // A cheap identity of the calling thread: the address of a thread-local object, distinct for
  // every live thread. std::this_thread::get_id() costs a call into the C library on every tick.
  static const void* currentThreadToken() noexcept {
    static thread_local char token = 0;
    return &token;
  }

  std::atomic<const void*> servo_thread_{nullptr};  ///< The servo thread's token.
  static_assert(std::atomic<const void*>::is_always_lock_free,
                "the servo path needs a lock-free thread token");
  Eigen::Vector3d position_m_ = Eigen::Vector3d::Zero();
  bool ok_ = false;
  bool fresh_ = false;
};

}  // namespace autograv
