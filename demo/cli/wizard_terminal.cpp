#include "wizard_terminal.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>

#include "autograv/error.h"

namespace autograv::cli {

std::atomic<int> g_interrupts{0};

namespace {

// Escape sequences: alternate screen + hidden cursor on entry, the reverse on exit.
constexpr char kEnterScreen[] = "\033[?1049h\033[?25l\033[H\033[2J";
constexpr char kLeaveScreen[] = "\033[?25h\033[?1049l";

// State the fatal-signal handler needs: plain globals, read with async-signal-safe calls only.
termios g_saved_termios{};
volatile std::sig_atomic_t g_raw_active = 0;

constexpr int kFatalSignals[] = {SIGSEGV, SIGABRT, SIGBUS, SIGFPE, SIGILL, SIGQUIT};

void writeAll(const char* text, std::size_t size) noexcept {
  while (size > 0) {
    const ssize_t written = ::write(STDOUT_FILENO, text, size);
    if (written <= 0) return;
    text += written;
    size -= static_cast<std::size_t>(written);
  }
}

// Async-signal-safe: tcsetattr and write only.
void restoreTerminal() noexcept {
  if (!g_raw_active) return;
  g_raw_active = 0;
  ::tcsetattr(STDIN_FILENO, TCSAFLUSH, &g_saved_termios);
  writeAll(kLeaveScreen, sizeof kLeaveScreen - 1);
}

extern "C" void onFatalSignal(int signal_number) {
  restoreTerminal();
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

extern "C" void onInterrupt(int) { g_interrupts.fetch_add(1); }

}  // namespace

void KeyDecoder::feed(const std::string& bytes, std::vector<Key>& keys) {
  pending_ += bytes;
  std::size_t i = 0;
  while (i < pending_.size()) {
    const char c = pending_[i];
    if (c != '\033') {
      switch (c) {
        case '\r':
        case '\n':
        case ' ':
          keys.push_back(Key::kEnter);
          break;
        case 'p':
        case 'P':
          keys.push_back(Key::kPause);
          break;
        case 'q':
        case 'Q':
        case '\003':
          keys.push_back(Key::kQuit);
          break;
        case 'r':
        case 'R':
          keys.push_back(Key::kRedo);
          break;
        case 'g':
        case 'G':
          keys.push_back(Key::kGrab);
          break;
        default:
          break;
      }
      ++i;
      continue;
    }
    // ESC [ A..D (arrows), ESC O A..D (application cursor mode), ESC [ 5 ~ / ESC [ 6 ~ (pages).
    if (i + 1 >= pending_.size()) break;  // wait for the rest
    const char kind = pending_[i + 1];
    if (kind != '[' && kind != 'O') {  // a lone Escape key
      ++i;
      continue;
    }
    std::size_t end = i + 2;
    while (end < pending_.size() &&
           ((pending_[end] >= '0' && pending_[end] <= '9') || pending_[end] == ';')) {
      ++end;
    }
    if (end >= pending_.size()) break;  // incomplete
    const std::string parameters = pending_.substr(i + 2, end - i - 2);
    switch (pending_[end]) {
      case 'A':
        keys.push_back(Key::kUp);
        break;
      case 'B':
        keys.push_back(Key::kDown);
        break;
      case 'C':
        keys.push_back(Key::kRight);
        break;
      case 'D':
        keys.push_back(Key::kLeft);
        break;
      case '~':
        if (parameters == "5") keys.push_back(Key::kPageUp);
        if (parameters == "6") keys.push_back(Key::kPageDown);
        break;
      default:
        break;
    }
    i = end + 1;
  }
  pending_.erase(0, i);
}

RawTerminal::RawTerminal() {
  if (!::isatty(STDIN_FILENO)) throw Error("the wizard's keyboard needs a terminal on stdin");
  if (::tcgetattr(STDIN_FILENO, &g_saved_termios) != 0) {
    throw Error(std::string("cannot read the terminal settings: ") + std::strerror(errno));
  }
  termios raw = g_saved_termios;
  raw.c_lflag &= static_cast<tcflag_t>(~(ICANON | ECHO | IEXTEN));  // ISIG stays: Ctrl-C
  raw.c_iflag &= static_cast<tcflag_t>(~(IXON | ICRNL));
  raw.c_cc[VMIN] = 0;
  raw.c_cc[VTIME] = 0;
  for (int signal_number : kFatalSignals) std::signal(signal_number, onFatalSignal);
  if (::tcsetattr(STDIN_FILENO, TCSAFLUSH, &raw) != 0) {
    throw Error(std::string("cannot put the terminal in raw mode: ") + std::strerror(errno));
  }
  g_raw_active = 1;
  writeAll(kEnterScreen, sizeof kEnterScreen - 1);
}

RawTerminal::~RawTerminal() {
  restoreTerminal();
  for (int signal_number : kFatalSignals) std::signal(signal_number, SIG_DFL);
}

std::string RawTerminal::readAvailable() {
  std::string bytes;
  char buffer[256];
  pollfd input{STDIN_FILENO, POLLIN, 0};
  while (::poll(&input, 1, 0) > 0 && (input.revents & POLLIN) != 0) {
    const ssize_t count = ::read(STDIN_FILENO, buffer, sizeof buffer);
    if (count <= 0) break;
    bytes.append(buffer, static_cast<std::size_t>(count));
  }
  return bytes;
}

bool interactiveTerminal() { return ::isatty(STDIN_FILENO) == 1 && ::isatty(STDOUT_FILENO) == 1; }

void terminalSize(int& columns, int& rows) {
  winsize size{};
  if (::ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0 && size.ws_row > 0) {
    columns = size.ws_col;
    rows = size.ws_row;
    return;
  }
  columns = 80;
  rows = 24;
}

void installInterruptHandlers() {
  g_interrupts.store(0);
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  std::signal(SIGHUP, onInterrupt);
}

void removeInterruptHandlers() {
  std::signal(SIGINT, SIG_DFL);
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGHUP, SIG_DFL);
}

}  // namespace autograv::cli
