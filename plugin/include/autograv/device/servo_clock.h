#pragma once

namespace autograv {

/// The time base of a servo loop, read once per tick by GravityCompensatedDevice so that its
/// ramps and windows last the same number of seconds whatever the loop's rate. Injectable so that
/// tests and simulated loops can run at exact, jittery or faster-than-real-time rates.
class ServoClock {
 public:
  virtual ~ServoClock() = default;
  /// Monotonic time; only differences between readings matter. Real-time safe in every
  /// implementation: no allocation, no lock, no throw. Unit: [s]
  virtual double now_s() noexcept = 0;
};

/// std::chrono::steady_clock: monotonic, and on Linux a vDSO read (no system call, no lock, no
/// allocation). The default clock of GravityCompensatedDevice.
class SteadyServoClock final : public ServoClock {
 public:
  double now_s() noexcept override;
};

/// A clock that advances by a fixed period on every reading: one reading per servo tick gives a
/// loop at exactly 1 / period_s, independent of the wall clock. For loops that run in simulated
/// time (calibration on a simulated device, tests). Every reading advances it: give each
/// decorator its own. Throws autograv::Error for a period that is not finite and positive.
/// Unit: [s]
class FixedPeriodServoClock final : public ServoClock {
 public:
  /// Throws autograv::Error unless `period_s` is finite and positive.
  /// Not real-time safe.
  explicit FixedPeriodServoClock(double period_s);
  double now_s() noexcept override;
  /// The time every reading advances. Unit: [s]
  double period_s() const noexcept { return period_s_; }

 private:
  double period_s_;
  long long ticks_ = 0;
};

}  // namespace autograv
