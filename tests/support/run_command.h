#pragma once

// Runs a program the way a user's shell does, for tests that drive the real `autograv` binary.

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace autograv::testing {

struct CommandResult {
  int exit_code = -1;
  std::string output;
};

/// Runs a shell command without a terminal (stdin from /dev/null), capturing stdout and stderr.
inline CommandResult runCommand(const std::string& command) {
  CommandResult result;
  FILE* pipe = ::popen((command + " < /dev/null 2>&1").c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[4096];
  std::size_t count;
  while ((count = std::fread(buffer, 1, sizeof buffer, pipe)) > 0)
    result.output.append(buffer, count);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace autograv::testing
