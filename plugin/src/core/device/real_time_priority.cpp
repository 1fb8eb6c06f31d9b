#include "autograv/device/real_time_priority.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <algorithm>
#include <cstddef>
#include <cstring>

namespace autograv {

namespace {
// What a servo loop's calls may use of its stack; touched once so that it is resident. Unit: [B]
constexpr std::size_t kServoStack_bytes = 256 * 1024;
constexpr std::size_t kPage_bytes = 4096;

void touchStack() noexcept {
  volatile unsigned char stack[kServoStack_bytes];
  for (std::size_t i = 0; i < sizeof stack; i += kPage_bytes) stack[i] = 0;
}
}  // namespace

RealTimePriority enterRealTimePriority(bool lock_memory) noexcept {
  RealTimePriority result;
  sched_param parameter{};
  parameter.sched_priority = std::min(kServoThreadPriority, sched_get_priority_max(SCHED_FIFO));
  result.error = pthread_setschedparam(pthread_self(), SCHED_FIFO, &parameter);
  result.granted = result.error == 0;
  if (result.granted) result.priority = parameter.sched_priority;
  if (lock_memory) result.memory_locked = mlockall(MCL_CURRENT | MCL_FUTURE) == 0;
  touchStack();
  return result;
}

std::string describe(const RealTimePriority& priority) {
  if (priority.granted) {
    return "SCHED_FIFO priority " + std::to_string(priority.priority) +
           (priority.memory_locked ? ", memory locked" : "");
  }
  return std::string("normal priority (SCHED_FIFO refused: ") + std::strerror(priority.error) +
         "; run as root, with CAP_SYS_NICE, or with an rtprio limit in "
         "/etc/security/limits.conf)";
}

}  // namespace autograv
