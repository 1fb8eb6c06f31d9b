#include "autograv/device/real_time_priority.h"

#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace autograv {
namespace {

struct ThreadPolicy {
  int policy = -1;
  int priority = -1;
};

ThreadPolicy currentPolicy() {
  ThreadPolicy current;
  sched_param parameter{};
  if (pthread_getschedparam(pthread_self(), &current.policy, &parameter) == 0) {
    current.priority = parameter.sched_priority;
  }
  return current;
}

// Whether this machine grants SCHED_FIFO or not (root in a container usually does, a user
// without an rtprio limit does not), the answer is what the thread now runs under.
TEST(RealTimePriorityTest, TheThreadRunsUnderWhatTheAnswerSays) {
  ThreadPolicy before, after;
  RealTimePriority answer;
  std::thread servo([&] {
    before = currentPolicy();
    answer = enterRealTimePriority();
    after = currentPolicy();
  });
  servo.join();
  if (answer.granted) {
    EXPECT_EQ(after.policy, SCHED_FIFO);
    EXPECT_EQ(after.priority, std::min(kServoThreadPriority, sched_get_priority_max(SCHED_FIFO)));
    EXPECT_EQ(answer.priority, after.priority);
    EXPECT_EQ(answer.error, 0);
    EXPECT_EQ(describe(answer), "SCHED_FIFO priority " + std::to_string(answer.priority));
  } else {
    EXPECT_NE(answer.error, 0);
    EXPECT_EQ(after.policy, before.policy);
    EXPECT_EQ(after.priority, before.priority);
    EXPECT_NE(describe(answer).find("normal priority"), std::string::npos);
  }
  EXPECT_FALSE(answer.memory_locked);  // not asked for
}

// What a user reads when the system refuses: the reason, and what would make it grant.
TEST(RealTimePriorityTest, ARefusalSaysWhyAndWhatToDo) {
  RealTimePriority refused;
  refused.error = EPERM;
  const std::string text = describe(refused);
  EXPECT_NE(text.find("normal priority"), std::string::npos) << text;
  EXPECT_NE(text.find("not permitted"), std::string::npos) << text;  // strerror(EPERM)
  EXPECT_NE(text.find("CAP_SYS_NICE"), std::string::npos) << text;
  EXPECT_NE(text.find("limits.conf"), std::string::npos) << text;
}

}  // namespace
}  // namespace autograv
