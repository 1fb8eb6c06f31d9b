#pragma once

// Child processes for the fault tests: run a program and capture what it prints, start one and
// kill it, and run code in a child whose view of the file system is changed (a read-only folder,
// a full disk) without touching the machine the tests run on.

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace autograv::testing {

/// The `autograv` program of this build; absent when the demo programs are not built.
inline const std::string kAutogravProgram = AUTOGRAV_BINARY_DIR "/demo/autograv";

/// How a child process ended.
struct ProgramRun {
  int exit_code = -1;  ///< -1 when it did not exit normally
  int signal = 0;      ///< the signal that ended it, 0 when none
  std::string output;  ///< standard output and standard error together
};

inline std::string readAll(int fd) {
  std::string text;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

inline std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << text;
}

/// A program started with its output on a pipe. The destructor kills and reaps it.
class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& argv) {
    int pipe_fds[2];
    if (::pipe2(pipe_fds, O_CLOEXEC) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(pipe_fds[1], STDOUT_FILENO);
      ::dup2(pipe_fds[1], STDERR_FILENO);
      std::vector<char*> args;
      for (const std::string& arg : argv) args.push_back(const_cast<char*>(arg.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      _exit(127);
    }
    ::close(pipe_fds[1]);
    output_fd_ = pipe_fds[0];
  }
  ~ChildProcess() {
    if (pid_ > 0 && !reaped_) {
      ::kill(pid_, SIGKILL);
      wait();
    }
    if (output_fd_ >= 0) ::close(output_fd_);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  bool started() const { return pid_ > 0; }
  /// Reads the output up to and including the next newline; false at the end of the output.
  bool readLine(std::string& line) {
    line.clear();
    char c;
    while (::read(output_fd_, &c, 1) == 1) {
      output_ += c;
      if (c == '\n') return true;
      line += c;
    }
    return !line.empty();
  }
  void kill(int signal_number) {
    if (!reaped_) ::kill(pid_, signal_number);
  }
  /// True once the program has ended (it is then reaped; wait() returns at once).
  bool exited() {
    if (!reaped_ && ::waitpid(pid_, &status_, WNOHANG) == pid_) reaped_ = true;
    return reaped_;
  }
  /// Waits for the end, reading the rest of the output.
  ProgramRun wait() {
    ProgramRun run;
    output_ += readAll(output_fd_);
    while (!reaped_ && ::waitpid(pid_, &status_, 0) < 0 && errno == EINTR) {
    }
    reaped_ = true;
    const int status = status_;
    run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    run.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
    run.output = output_;
    return run;
  }

 private:
  pid_t pid_ = -1;
  int output_fd_ = -1;
  bool reaped_ = false;
  int status_ = 0;
  std::string output_;
};

/// Runs a program to its end and captures what it printed.
inline ProgramRun runProgram(const std::vector<std::string>& argv) {
  ChildProcess child(argv);
  return child.wait();
}

/// Splits "a b c" at spaces (no quoting: the tests' paths have no spaces).
inline std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream in(text);
  for (std::string word; in >> word;) result.push_back(word);
  return result;
}

/// Runs `autograv <arguments>`.
inline ProgramRun runAutograv(const std::string& arguments) {
  std::vector<std::string> argv = words(arguments);
  argv.insert(argv.begin(), kAutogravProgram);
  return runProgram(argv);
}

/// Findings a child reports to the test process, by name.
using Findings = std::map<std::string, std::string>;

/// How a folder is made unwritable for the code under test.
enum class Confinement {
  kReadOnlyBindMount,  ///< a read-only bind mount in a private mount namespace
  kNoWritePermission,  ///< mode 0555 and, as root, the child runs as user nobody
};

/// Result of runConfined: the child's findings, or why it could not run.
struct ConfinedRun {
  bool ran = false;
  std::string why_not;  ///< when !ran
  Confinement confinement = Confinement::kReadOnlyBindMount;
  Findings findings;
};

namespace detail {

inline std::string escape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c == '\\') {
      out += "\\\\";
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

inline std::string unescape(const std::string& text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '\\' && i + 1 < text.size()) {
      out += text[i + 1] == 'n' ? '\n' : text[i + 1];
      ++i;
    } else {
      out += text[i];
    }
  }
  return out;
}

/// In a fresh child: a private mount namespace, so that mounts made here vanish with the child.
inline bool enterPrivateMountNamespace(std::string& why_not) {
  if (::unshare(CLONE_NEWNS) != 0) {
    why_not = std::string("unshare(CLONE_NEWNS): ") + std::strerror(errno);
    return false;
  }
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) {
    why_not = std::string("making / private: ") + std::strerror(errno);
    return false;
  }
  return true;
}

inline bool bindReadOnly(const std::string& folder, std::string& why_not) {
  if (::mount(folder.c_str(), folder.c_str(), nullptr, MS_BIND, nullptr) != 0 ||
      ::mount(nullptr, folder.c_str(), nullptr, MS_REMOUNT | MS_BIND | MS_RDONLY, nullptr) != 0) {
    why_not = "read-only bind mount of " + folder + ": " + std::strerror(errno);
    return false;
  }
  return true;
}

/// Forks; the child runs `prepare` then `body` and sends the findings back through a pipe.
inline ConfinedRun inChild(const std::function<bool(std::string&)>& prepare,
                           const std::function<Findings()>& body) {
  ConfinedRun result;
  int pipe_fds[2];
  if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
    result.why_not = std::string("pipe: ") + std::strerror(errno);
    return result;
  }
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::close(pipe_fds[0]);
    std::string why_not;
    std::string message;
    if (!prepare(why_not)) {
      message = "!" + escape(why_not) + "\n";
    } else {
      for (const auto& [key, value] : body()) message += escape(key) + "=" + escape(value) + "\n";
    }
    const char* data = message.data();
    std::size_t left = message.size();
    while (left > 0) {
      const ssize_t n = ::write(pipe_fds[1], data, left);
      if (n <= 0) break;
      data += n;
      left -= static_cast<std::size_t>(n);
    }
    _exit(0);
  }
  ::close(pipe_fds[1]);
  const std::string message = readAll(pipe_fds[0]);
  ::close(pipe_fds[0]);
  int status = 0;
  ::waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    result.why_not = "the child process died";
    return result;
  }
  if (!message.empty() && message[0] == '!') {
    result.why_not = unescape(message.substr(1, message.size() - 2));
    return result;
  }
  std::istringstream lines(message);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t equals = line.find('=');
    result.findings[unescape(line.substr(0, equals))] = unescape(line.substr(equals + 1));
  }
  result.ran = true;
  return result;
}

}  // namespace detail

/// Runs `body` in a child process that cannot write into `folder` (nor create files there),
/// while the test process can. Tests run as root in CI, for whom mode bits do not count: the
/// child first tries a read-only bind mount in its own mount namespace; where that is not
/// allowed (a container without CAP_SYS_ADMIN), it takes write permission away from the folder
/// and, as root, becomes user nobody. `body` runs in the child: it must not use gtest assertions
/// but report what it saw as findings.
inline ConfinedRun runWithReadOnlyFolder(const std::string& folder,
                                         const std::function<Findings()>& body) {
  ConfinedRun run = detail::inChild(
      [&](std::string& why_not) {
        return detail::enterPrivateMountNamespace(why_not) && detail::bindReadOnly(folder, why_not);
      },
      body);
  if (run.ran) return run;
  const std::string namespace_failure = run.why_not;
  struct stat before {};
  ::stat(folder.c_str(), &before);
  ::chmod(folder.c_str(), 0555);
  run = detail::inChild(
      [&](std::string& why_not) {
        if (::geteuid() != 0) return true;
        constexpr uid_t kNobody = 65534;
        if (::setresgid(kNobody, kNobody, kNobody) != 0 ||
            ::setresuid(kNobody, kNobody, kNobody) != 0) {
          why_not = std::string("becoming user nobody: ") + std::strerror(errno);
          return false;
        }
        return true;
      },
      body);
  ::chmod(folder.c_str(), before.st_mode & 07777);
  run.confinement = Confinement::kNoWritePermission;
  if (!run.ran) {
    run.why_not = "no way to make a folder read-only for this process here (" + namespace_failure +
                  "; " + run.why_not + ")";
  }
  return run;
}

/// Runs `body` in a child process in whose view `folder` is a file system of `size_bytes` whose
/// every byte is taken, except that the files `keep` (name -> content) were written first. Needs
/// a private mount namespace (root or CAP_SYS_ADMIN).
inline ConfinedRun runWithFullDisk(const std::string& folder, std::size_t size_bytes,
                                   const std::map<std::string, std::string>& keep,
                                   const std::function<Findings()>& body) {
  return detail::inChild(
      [&](std::string& why_not) {
        if (!detail::enterPrivateMountNamespace(why_not)) return false;
        const std::string options = "size=" + std::to_string(size_bytes);
        if (::mount("tmpfs", folder.c_str(), "tmpfs", 0, options.c_str()) != 0) {
          why_not = "mounting a small tmpfs on " + folder + ": " + std::strerror(errno);
          return false;
        }
        for (const auto& [name, content] : keep) writeFile(folder + "/" + name, content);
        // Fill what is left, one page at a time, until the file system refuses.
        const int fd = ::open((folder + "/filler").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const std::string page(4096, 'x');
        while (fd >= 0 && ::write(fd, page.data(), page.size()) > 0) {
        }
        ::close(fd);
        return true;
      },
      body);
}

}  // namespace autograv::testing
