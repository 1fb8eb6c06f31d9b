#pragma once

// Terminal plumbing of `autograv wizard`: raw keyboard mode restored on every exit path, key
// decoding, terminal size, and the interrupt flag set by Ctrl-C.

#include <atomic>
#include <string>
#include <vector>

namespace autograv::cli {

/// Keys the wizard understands.
enum class Key {
  kEnter,  ///< Enter or space: confirm.
  kPause,  ///< p
  kQuit,   ///< q (or Ctrl-C delivered as a byte)
  kRedo,   ///< r
  kGrab,   ///< g: the simulated hand grabs or lets go
  kUp,
  kDown,
  kLeft,
  kRight,
  kPageUp,
  kPageDown,
};

/// Decodes bytes read from a terminal into keys (arrows and PageUp/PageDown arrive as escape
/// sequences, possibly split across reads). Unknown bytes and sequences are dropped.
class KeyDecoder {
 public:
  /// Appends the keys completed by `bytes` to `keys`.
  void feed(const std::string& bytes, std::vector<Key>& keys);

 private:
  std::string pending_;
};

/// Puts the terminal on standard input in raw mode (no echo, no line editing; Ctrl-C still
/// raises SIGINT) and standard output on the alternate screen with the cursor hidden, for the
/// lifetime of the object. Everything is restored by the destructor, and by a handler of fatal
/// signals (SIGSEGV, SIGABRT, ...) that restores the terminal and re-raises, so a crash never
/// leaves the user's shell without echo. One instance at a time. Throws autograv::Error when
/// standard input is not a terminal.
class RawTerminal {
 public:
  RawTerminal();
  ~RawTerminal();
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;

  /// Bytes available on standard input now (never waits).
  std::string readAvailable();
};

/// True when both standard input and standard output are terminals.
bool interactiveTerminal();
/// Size of the terminal on standard output; 80 x 24 when unknown.
void terminalSize(int& columns, int& rows);

/// Counts SIGINT/SIGTERM/SIGHUP received since installInterruptHandlers().
extern std::atomic<int> g_interrupts;
/// Routes SIGINT, SIGTERM and SIGHUP to g_interrupts (instead of killing the process), so that
/// the wizard can checkpoint and restore the terminal before it exits.
void installInterruptHandlers();
/// Back to the default actions.
void removeInterruptHandlers();

}  // namespace autograv::cli
