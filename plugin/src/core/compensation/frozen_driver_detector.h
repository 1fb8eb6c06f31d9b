#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "autograv/compensation/gravity_compensated_device.h"

namespace autograv {

/// Tells a driver whose readings froze from an end-effector merely held still: the check behind
/// ServoFault::kStalePosition. Internal to core; the servo thread's only. Real-time safe
/// throughout. The rule and its bounds are in the comment of GravityCompensatedDevice.
///
/// Over a run of bit-identical readings, the push (force sent minus the map's gravity) is
/// low-passed by two first-order stages; a filtered push within 45 degrees of both +axis and
/// -axis of one axis, each at least the threshold D, after frozen_window_s of the run, is a
/// frozen driver. The encoder resolution that D depends on is learned from the readings.
class FrozenDriverDetector {
 public:
  /// Takes the frozen_* settings of `options` (already checked by the decorator).
  explicit FrozenDriverDetector(const CompensationOptions& options) noexcept;

  /// Learns the encoder resolution from the step between this reading and the previous one.
  /// Returns true when the resolution became finer. Unit: [m]
  bool learnResolution(const Eigen::Vector3d& position_m) noexcept;
  /// The smallest nonzero step seen between two successive readings (an assumption coarser
  /// than any supported device until one is seen). Unit: [m]
  double resolution_m() const noexcept { return resolution_m_; }

  /// One servo tick of `dt_s` at `position_m` with `push_n` on the end-effector: true when the
  /// driver is frozen (and for as long as the readings stay frozen after that). Always false
  /// when frozen_window_s is 0. Units: [m], [N], [s]
  bool frozen(const Eigen::Vector3d& position_m, const Eigen::Vector3d& push_n,
              double dt_s) noexcept;

  /// Ends the current run of identical readings: the readings in between were not usable.
  void restartRun() noexcept { tracking_ = false; }
  /// Forgets the run and the previous reading (the resolution learned so far stays).
  void reset() noexcept {
    tracking_ = false;
    has_last_position_ = false;
  }

 private:
  // Settings (see CompensationOptions).
  double window_s_;
  double force_floor_n_;
  double hand_stiffness_n_per_m_;
  double filter_time_constant_s_;
  // Resolution learning.
  double resolution_m_;
  Eigen::Vector3d last_position_m_ = Eigen::Vector3d::Zero();
  bool has_last_position_ = false;
  // The current run of identical readings.
  bool tracking_ = false;
  bool detected_ = false;
  double run_s_ = 0.0;
  Eigen::Vector3d run_position_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d push_stage_n_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d push_filtered_n_ = Eigen::Vector3d::Zero();
  std::uint8_t pushed_up_axes_ = 0;    ///< Bit a: the filtered push pointed along +axis a.
  std::uint8_t pushed_down_axes_ = 0;  ///< Bit a: the filtered push pointed along -axis a.
};

}  // namespace autograv
