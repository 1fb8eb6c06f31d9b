#pragma once

#include <cstddef>

namespace autograv::testing {

/// Counts operator new calls made by the current thread while alive. Used to prove that servo
/// paths allocate nothing:
///   AllocationCounter counter;
///   for (...) device.setForce(force);
///   EXPECT_EQ(counter.count(), 0u);
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  /// Allocations by this thread since construction.
  std::size_t count() const;

 private:
  std::size_t start_;
};

}  // namespace autograv::testing
