#include "core/estimation/minimum_jerk_move.h"

#include <algorithm>
#include <cmath>

namespace autograv {

namespace {
// Peak |s''| of s(tau) = 10 tau^3 - 15 tau^4 + 6 tau^5 is 10 / sqrt(3) = 5.7735.
constexpr double kPeakAccelerationFactor = 5.773502691896258;
}  // namespace

void MinimumJerkMove::start(const Eigen::Vector3d& from_m, const Eigen::Vector3d& to_m,
                            double duration_s) noexcept {
  from_m_ = from_m;
  delta_m_ = to_m - from_m;
  duration_s_ = duration_s > 0.0 ? duration_s : 1e-3;
}

void MinimumJerkMove::sample(double t_s, Eigen::Vector3d& position_m,
                             Eigen::Vector3d& velocity_m_per_s,
                             Eigen::Vector3d& acceleration_m_per_s2) const noexcept {
  const double tau = std::clamp(t_s / duration_s_, 0.0, 1.0);
  const double tau2 = tau * tau;
  const double tau3 = tau2 * tau;
  const double s = tau3 * (10.0 - 15.0 * tau + 6.0 * tau2);
  const double ds = 30.0 * tau2 * (1.0 - tau) * (1.0 - tau) / duration_s_;
  const double dds = 60.0 * tau * (1.0 - 3.0 * tau + 2.0 * tau2) / (duration_s_ * duration_s_);
  position_m = from_m_ + s * delta_m_;
  velocity_m_per_s = ds * delta_m_;
  acceleration_m_per_s2 = dds * delta_m_;
}

double MinimumJerkMove::durationFor(double distance_m, double max_acceleration_m_per_s2,
                                    double min_duration_s) noexcept {
  const double needed = std::sqrt(kPeakAccelerationFactor * std::abs(distance_m) /
                                  std::max(max_acceleration_m_per_s2, 1e-6));
  return std::max(needed, min_duration_s);
}

}  // namespace autograv
