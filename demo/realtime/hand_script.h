#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace autograv::demo {

/// One timed action of a scripted hand.
struct HandEvent {
  enum class Kind : std::uint8_t {
    kGrab,             ///< Take hold of the end-effector where it is.
    kMove,             ///< Glide the hand's target to `position_m` at `speed_m_per_s`.
    kRelease,          ///< Let go.
    kCompensationOn,   ///< Switch gravity compensation on (it ramps in).
    kCompensationOff,  ///< Switch it off (it ramps out).
  };
  double time_s = 0.0;  ///< Servo time since the start of the run. Unit: [s]
  Kind kind = Kind::kGrab;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  ///< kMove only. Unit: [m]
  double speed_m_per_s = 0.1;                            ///< kMove only. Unit: [m/s]
  int line = 0;                                          ///< Line of the script it came from.
};

/// What a scripted hand does, read from a small text file that makes a demo run repeatable:
///
///     # comments and blank lines are ignored; times in seconds, positions in metres
///     at 0.10 grab
///     at 0.20 move 0.00 0.02 0.03        # glide at 0.1 m/s
///     at 0.20 move 0.00 0.02 0.03 0.05   # ... or at 0.05 m/s
///     at 1.00 release
///     at 1.50 compensation off
///
/// Events with the same time keep the order of the file.
class HandScript {
 public:
  HandScript() = default;
  /// Parses `text`; `source` names it in errors. Throws autograv::Error with source:line and what
  /// was expected. Not real-time safe.
  static HandScript parse(const std::string& text, const std::string& source);
  /// Reads and parses a file. Throws autograv::Error when it cannot be read or parsed.
  /// Not real-time safe.
  static HandScript load(const std::string& path);

  const std::vector<HandEvent>& events() const noexcept { return events_; }
  bool empty() const noexcept { return events_.empty(); }

 private:
  std::vector<HandEvent> events_;
};

/// Walks a script forward in time without allocating: the servo thread asks for the events that
/// fell due by now, tick after tick.
class HandScriptPlayer {
 public:
  HandScriptPlayer() = default;
  /// `script` must outlive the player. Not real-time safe.
  explicit HandScriptPlayer(const HandScript* script) noexcept : script_(script) {}
  /// The next event due at or before `time_s`, or null when none is (yet). Call repeatedly until
  /// null on each tick. Real-time safe.
  const HandEvent* nextDue(double time_s) noexcept {
    if (script_ == nullptr || next_ >= script_->events().size()) return nullptr;
    const HandEvent& event = script_->events()[next_];
    if (event.time_s > time_s + 1e-9) return nullptr;
    ++next_;
    return &event;
  }
  bool finished() const noexcept { return script_ == nullptr || next_ >= script_->events().size(); }

 private:
  const HandScript* script_ = nullptr;
  std::size_t next_ = 0;
};

}  // namespace autograv::demo
