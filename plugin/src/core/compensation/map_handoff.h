#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace autograv {

class GravityMap;

/// Hands gravity maps from publishing threads to one servo thread. Internal to core: the
/// publication protocol behind GravityCompensatedDevice::publishMap.
///
/// A publisher stores the map's raw pointer in an atomic and bumps a sequence number; the servo
/// thread takes the pointer after reading the sequence number, and acknowledges the sequence
/// number once it has stopped reading older maps. The shared references stay here, on the
/// publishing side: maps published before the acknowledged one are released by reclaimRetired(),
/// so the servo thread never frees, locks or allocates.
class MapHandoff {
 public:
  // --- Publishing side: any thread, not real-time safe ----------------------------------------
  /// Makes `map` (null: no map) the latest publication and keeps a reference to it.
  void publish(std::shared_ptr<const GravityMap> map);
  /// The latest published map (null when none or null was published).
  std::shared_ptr<const GravityMap> latest() const;
  /// Drops the references to maps the servo thread no longer reads; returns how many it dropped.
  std::size_t reclaimRetired();
  /// Publications still referenced, the latest one included.
  std::size_t retainedCount() const;
  /// True once the servo thread has acknowledged the latest publication. Real-time safe.
  bool latestAcknowledged() const noexcept {
    return acknowledged_sequence_.load(std::memory_order_acquire) ==
           published_sequence_.load(std::memory_order_acquire);
  }

  // --- Servo side: the servo thread only, real-time safe --------------------------------------
  /// True when a publication newer than the last one taken is waiting.
  bool hasNewPublication() const noexcept {
    return published_sequence_.load(std::memory_order_acquire) != taken_sequence_;
  }
  /// Takes the latest publication if it is newer than the last one taken: sets `map` to it (null
  /// when null was published) and returns true. Otherwise returns false and leaves `map` alone.
  bool take(const GravityMap*& map) noexcept {
    const std::uint64_t sequence = published_sequence_.load(std::memory_order_acquire);
    if (sequence == taken_sequence_) return false;
    // Read after the sequence number: this is the map of that publication or a newer one.
    map = published_.load(std::memory_order_acquire);
    taken_sequence_ = sequence;
    return true;
  }
  /// Tells the publishers that no map published before the last one taken is read any more.
  void acknowledgeTaken() noexcept {
    if (acknowledged_local_ == taken_sequence_) return;
    // Release: every read of the older maps happened before this store.
    acknowledged_sequence_.store(taken_sequence_, std::memory_order_release);
    acknowledged_local_ = taken_sequence_;
  }

 private:
  struct RetainedMap {
    std::uint64_t sequence;
    std::shared_ptr<const GravityMap> map;  // null when null was published
  };

  // Publishing side, under mutex_ (never taken by the servo thread).
  mutable std::mutex mutex_;
  std::vector<RetainedMap> retained_;
  std::uint64_t next_sequence_ = 1;
  // Shared between the two sides.
  std::atomic<const GravityMap*> published_{nullptr};
  std::atomic<std::uint64_t> published_sequence_{0};
  std::atomic<std::uint64_t> acknowledged_sequence_{0};
  // Servo side.
  std::uint64_t taken_sequence_ = 0;
  std::uint64_t acknowledged_local_ = 0;
};

}  // namespace autograv
