#include "autograv/estimation/steady_state_detector.h"

#include <cmath>

#include "autograv/error.h"

namespace autograv {

SteadyStateDetector::SteadyStateDetector(int required_samples, double speed_threshold_m_per_s,
                                         double min_duration_s, double period_s)
    : required_samples_(required_samples),
      speed_threshold_m_per_s_(speed_threshold_m_per_s),
      min_ticks_(std::lround(min_duration_s / period_s)),
      period_s_(period_s) {
  if (required_samples < 1) throw Error("steady-state detector: n_S must be at least 1");
  if (!(speed_threshold_m_per_s > 0.0)) {
    throw Error("steady-state detector: eps_S must be a positive speed in m/s");
  }
  if (!(period_s > 0.0) || !(min_duration_s >= 0.0)) {
    throw Error("steady-state detector: servo period must be positive, minimum duration >= 0");
  }
}

void SteadyStateDetector::reset() noexcept {
  elapsed_ticks_ = 0;
  consecutive_ = 0;
  settled_ = false;
  position_sum_m_.setZero();
}

bool SteadyStateDetector::update(const Eigen::Vector3d& position_m,
                                 const Eigen::Vector3d& velocity_m_per_s) noexcept {
  if (settled_) return true;
  ++elapsed_ticks_;
  if (velocity_m_per_s.allFinite() && velocity_m_per_s.norm() <= speed_threshold_m_per_s_) {
    ++consecutive_;
    position_sum_m_ += position_m;
  } else {
    consecutive_ = 0;
    position_sum_m_.setZero();
  }
  settled_ = consecutive_ >= required_samples_ && elapsed_ticks_ >= min_ticks_;
  return settled_;
}

Eigen::Vector3d SteadyStateDetector::settledPosition_m() const noexcept {
  if (consecutive_ == 0) return Eigen::Vector3d::Constant(NAN);
  return position_sum_m_ / consecutive_;
}

}  // namespace autograv
