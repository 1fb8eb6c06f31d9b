#pragma once

#include <string>

namespace autograv {

/// What enterRealTimePriority obtained for the calling thread.
struct RealTimePriority {
  bool granted = false;        ///< The thread runs under SCHED_FIFO.
  int priority = 0;            ///< Its SCHED_FIFO priority when granted.
  bool memory_locked = false;  ///< mlockall succeeded (only when asked for).
  int error = 0;               ///< errno of the refused request (EPERM without the right), or 0.
};

/// The SCHED_FIFO priority a servo thread asks for: above interrupt threads' default (50) and
/// the system's housekeeping, below the kernel's own watchdogs (99).
constexpr int kServoThreadPriority = 80;

/// Raises the calling thread to SCHED_FIFO at kServoThreadPriority (or the system's highest below
/// it), where the system permits it (root, CAP_SYS_NICE or an rtprio limit), and touches the stack
/// a servo loop uses so that its pages are resident. With `lock_memory` also locks the process's
/// memory (mlockall): no page fault waits on the disk, but under a small RLIMIT_MEMLOCK later
/// allocations may fail, so only a program that allocates up front should ask. A refusal leaves
/// the thread as it was: a loop at normal priority on a busy desktop ticks up to milliseconds
/// late, which costs the field next to the stops (README, "Real-time priority").
/// Call once from the servo thread, before its loop. Not real-time safe.
RealTimePriority enterRealTimePriority(bool lock_memory = false) noexcept;

/// One line for a terminal or a report: "SCHED_FIFO priority 80" or why not, and what to do.
std::string describe(const RealTimePriority& priority);

}  // namespace autograv
