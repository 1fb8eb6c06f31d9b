#include "core/compensation/compensation_status.h"

namespace autograv {

std::uint64_t CompensationStatus::faultTotal() const noexcept {
  std::uint64_t total = 0;
  for (std::size_t i = 1; i < fault_counts.size(); ++i) {
    total += fault_counts[i].load(std::memory_order_relaxed);
  }
  return total;
}

}  // namespace autograv
