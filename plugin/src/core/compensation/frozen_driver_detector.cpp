#include "core/compensation/frozen_driver_detector.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace autograv {

namespace {

// Resolution assumed until the first step between two readings is seen: coarser than any
// supported device's. Unit: [m]
constexpr double kUnknownResolution_m = 1e-4;
// Encoder counts a hand must move by before a push can be blamed on a frozen driver.
constexpr double kHandCounts = 3.0;
// cos^2(45 degrees): a push counts along an axis when within 45 degrees of it.
constexpr double kAxisConeCos2 = 0.5;

bool bitwiseEqual(const Eigen::Vector3d& a, const Eigen::Vector3d& b) noexcept {
  return std::memcmp(a.data(), b.data(), 3 * sizeof(double)) == 0;
}

}  // namespace

FrozenDriverDetector::FrozenDriverDetector(const CompensationOptions& options) noexcept
    : window_s_(options.frozen_window_s),
      force_floor_n_(options.frozen_force_floor_n),
      hand_stiffness_n_per_m_(options.frozen_hand_stiffness_n_per_m),
      filter_time_constant_s_(options.frozen_filter_time_constant_s),
      resolution_m_(kUnknownResolution_m) {}

bool FrozenDriverDetector::learnResolution(const Eigen::Vector3d& position_m) noexcept {
  bool finer = false;
  if (has_last_position_) {
    // Squared first: the square root is paid only on the rare tick that finds a finer step.
    const double step_m2 = (position_m - last_position_m_).squaredNorm();
    if (step_m2 > 0.0 && step_m2 < resolution_m_ * resolution_m_) {
      resolution_m_ = std::sqrt(step_m2);
      finer = true;
    }
  }
  last_position_m_ = position_m;
  has_last_position_ = true;
  return finer;
}

bool FrozenDriverDetector::frozen(const Eigen::Vector3d& position_m, const Eigen::Vector3d& push_n,
                                  double dt_s) noexcept {
  if (window_s_ <= 0.0) return false;
  if (!tracking_ || !bitwiseEqual(position_m, run_position_m_)) {
    // A new run of identical readings starts: the filter starts from the push of its first tick.
    tracking_ = true;
    detected_ = false;
    run_position_m_ = position_m;
    run_s_ = 0.0;
    push_stage_n_ = push_n;
    push_filtered_n_ = push_n;
    pushed_up_axes_ = 0;
    pushed_down_axes_ = 0;
    return false;
  }
  if (detected_) return true;  // lasts while the readings stay frozen
  run_s_ += dt_s;
  // Bilinear (Tustin) discretisation of the first-order low-pass, 1 - exp(-x) ~ 2x / (2 + x):
  // the same response at any rate to within 0.5 % for ticks up to 4 ms (2.7 % at the 10 ms
  // clamp), at the cost of a division instead of an exponential on every still tick.
  const double time_constant_s = filter_time_constant_s_;
  const double alpha = time_constant_s > 0.0 ? 2.0 * dt_s / (2.0 * time_constant_s + dt_s) : 1.0;
  push_stage_n_ += alpha * (push_n - push_stage_n_);
  push_filtered_n_ += alpha * (push_stage_n_ - push_filtered_n_);

  const double threshold_n =
      std::max(force_floor_n_, 0.5 * hand_stiffness_n_per_m_ * kHandCounts * resolution_m_);
  const double cone_n2 = kAxisConeCos2 * push_filtered_n_.squaredNorm();
  for (int axis = 0; axis < 3; ++axis) {
    const double component_n = push_filtered_n_[axis];
    if (component_n * component_n < cone_n2) continue;
    if (component_n >= threshold_n) pushed_up_axes_ |= static_cast<std::uint8_t>(1U << axis);
    if (component_n <= -threshold_n) pushed_down_axes_ |= static_cast<std::uint8_t>(1U << axis);
  }
  detected_ = (pushed_up_axes_ & pushed_down_axes_) != 0 && run_s_ >= window_s_;
  return detected_;
}

}  // namespace autograv
