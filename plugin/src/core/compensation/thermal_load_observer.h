#pragma once

#include <algorithm>

#include <Eigen/Core>

namespace autograv {

/// How hard the forces sent work a device's motors: the square of the force sent over the
/// continuous force rating, low-passed over the motors' thermal time constant, as a motor's
/// temperature follows its I^2 R heat. 1 held for long is the rated temperature rise. Used by
/// GravityCompensatedDevice (thermalLoad, the map's thermal correction) and by AutoCalibrator
/// (the load each measurement was made at), so that both count the same heat. Internal to core;
/// real-time safe throughout.
class ThermalLoadObserver {
 public:
  /// `rating_n`: the continuous force rating; 0 or less leaves the load at 0. `time_constant_s`
  /// must be positive. Units: [N], [s]
  void configure(double rating_n, double time_constant_s) noexcept {
    inverse_rating_n2_ = rating_n > 0.0 ? 1.0 / (rating_n * rating_n) : 0.0;
    inverse_time_constant_per_s_ = 1.0 / time_constant_s;
  }
  /// Starts again from `load` (motors at room temperature: 0).
  void reset(double load = 0.0) noexcept {
    load_ = load;
    last_force_n2_ = 0.0;
  }
  /// Moves the load on by `dt_s`, over which the force last sent acted. Unit: [s]
  void advance(double dt_s) noexcept {
    if (inverse_rating_n2_ > 0.0 && dt_s > 0.0) {
      const double share = std::min(1.0, dt_s * inverse_time_constant_per_s_);
      load_ += share * (last_force_n2_ * inverse_rating_n2_ - load_);
    }
  }
  /// `force_n` acts from now until the next advance (zero: the device delivered nothing).
  /// Unit: [N]
  void sent(const Eigen::Vector3d& force_n) noexcept { last_force_n2_ = force_n.squaredNorm(); }
  /// The same as sent() for no force at all.
  void sentNothing() noexcept { last_force_n2_ = 0.0; }
  /// The load now (see the class comment).
  double load() const noexcept { return load_; }

 private:
  double inverse_rating_n2_ = 0.0;            ///< 1 / rating^2; 0: unknown. Unit: [1/N^2]
  double inverse_time_constant_per_s_ = 1.0;  ///< 1 / the time constant. Unit: [1/s]
  double last_force_n2_ = 0.0;  ///< Squared force acting since the last tick. Unit: [N^2]
  double load_ = 0.0;
};

}  // namespace autograv
