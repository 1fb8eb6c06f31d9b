#include "core/compensation/map_handoff.h"

#include <utility>

namespace autograv {

void MapHandoff::publish(std::shared_ptr<const GravityMap> map) {
  const std::lock_guard<std::mutex> lock(mutex_);
  const std::uint64_t sequence = next_sequence_++;
  const GravityMap* raw = map.get();
  retained_.push_back(RetainedMap{sequence, std::move(map)});
  published_.store(raw, std::memory_order_release);
  published_sequence_.store(sequence, std::memory_order_release);
}

std::shared_ptr<const GravityMap> MapHandoff::latest() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  if (retained_.empty()) return nullptr;
  return retained_.back().map;
}

std::size_t MapHandoff::reclaimRetired() {
  std::vector<RetainedMap> released;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
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

std::size_t MapHandoff::retainedCount() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return retained_.size();
}

}  // namespace autograv
