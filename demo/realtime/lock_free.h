#pragma once

// The two lock-free channels between the demo's UI thread and its servo thread: commands go to
// the servo thread through a bounded queue, the latest state comes back through a triple buffer.
// Neither allocates, locks or blocks after construction.

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>

namespace autograv::demo {

/// A bounded single-producer single-consumer queue. push and pop never block: a full queue
/// refuses the push, an empty one the pop.
template <typename T, std::size_t Capacity>
class SpscQueue {
  static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "power-of-two capacity");

 public:
  /// Producer thread only. Returns false when full. Real-time safe.
  bool push(const T& item) noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail - head_.load(std::memory_order_acquire) == Capacity) return false;
    items_[tail & (Capacity - 1)] = item;
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }
  /// Consumer thread only. Returns false when empty. Real-time safe.
  bool pop(T& item) noexcept {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    if (head == tail_.load(std::memory_order_acquire)) return false;
    item = items_[head & (Capacity - 1)];
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

 private:
  std::array<T, Capacity> items_{};
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
};

/// Latest-value channel from one writer to one reader: the writer fills a private slot and swaps
/// it with the shared middle slot; the reader swaps the middle slot with its own when a new value
/// was published. Each side only ever touches a slot it owns, so there is no torn read.
template <typename T>
class TripleBuffer {
 public:
  /// The writer's slot, to fill before publish(). Writer thread only. Real-time safe.
  T& writeSlot() noexcept { return slots_[write_]; }
  /// Makes the write slot the latest value. Writer thread only. Real-time safe.
  void publish() noexcept {
    const std::uint8_t previous =
        middle_.exchange(static_cast<std::uint8_t>(write_ | kFresh), std::memory_order_acq_rel);
    write_ = previous & kIndexMask;
  }
  /// The latest published value (the previous one when nothing new came). Reader thread only.
  /// Real-time safe.
  const T& read() noexcept {
    if (middle_.load(std::memory_order_relaxed) & kFresh) {
      const std::uint8_t previous = middle_.exchange(read_, std::memory_order_acq_rel);
      read_ = previous & kIndexMask;
    }
    return slots_[read_];
  }

 private:
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;
  std::array<T, 3> slots_{};
  std::uint8_t write_ = 0;
  std::uint8_t read_ = 1;
  std::atomic<std::uint8_t> middle_{2};
};

}  // namespace autograv::demo
