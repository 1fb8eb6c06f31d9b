#pragma once

namespace autograv {

/// Paces a servo loop: a real device waits for the wall clock, a simulated one advances its
/// physics by one period (as fast as the CPU allows, or in real time for demos).
class TickSource {
 public:
  virtual ~TickSource() = default;
  /// Blocks until the next servo tick is due (or advances simulated time by one period).
  /// Returns false when the source has stopped.
  virtual bool waitForNextTick() = 0;
  /// Servo period. Unit: [s]
  virtual double period_s() const = 0;
  /// Time since the source started. Unit: [s]
  virtual double now_s() const = 0;
  /// Servo time between the two latest ticks, what ServoSample::interval_s carries; the nominal
  /// period where the source does not measure it. Unit: [s]
  virtual double lastInterval_s() const { return period_s(); }
};

}  // namespace autograv
