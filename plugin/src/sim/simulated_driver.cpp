#include "autograv/sim/simulated_driver.h"

#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"

namespace autograv::sim {

namespace {

std::uint64_t splitMix64(std::uint64_t& state) noexcept {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t rotateLeft(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }

bool finitePositive(double value) { return std::isfinite(value) && value > 0.0; }

// Largest share of the force limit a payload's weight may take (see setPayload_kg).
constexpr double kMaxPayloadForceShare = 0.25;

}  // namespace

// ---------------------------------------------------------------------------------------------
// Random

Random::Random(std::uint64_t seed) noexcept {
  std::uint64_t state = seed;
  for (auto& word : state_) word = splitMix64(state);
}

std::uint64_t Random::nextBits() noexcept {
  const std::uint64_t result = rotateLeft(state_[1] * 5, 7) * 9;
  const std::uint64_t t = state_[1] << 17;
  state_[2] ^= state_[0];
  state_[3] ^= state_[1];
  state_[1] ^= state_[2];
  state_[0] ^= state_[3];
  state_[2] ^= t;
  state_[3] = rotateLeft(state_[3], 45);
  return result;
}

double Random::uniform() noexcept {
  // The top 53 bits fill a double's mantissa exactly.
  return static_cast<double>(nextBits() >> 11) * 0x1.0p-53;
}

double Random::gaussian() noexcept {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  constexpr double kTwoPi = 6.283185307179586476925286766559;
  const double u1 = 1.0 - uniform();  // (0, 1]: the logarithm stays finite
  const double u2 = uniform();
  const double radius = std::sqrt(-2.0 * std::log(u1));
  spare_ = radius * std::sin(kTwoPi * u2);
  has_spare_ = true;
  return radius * std::cos(kTwoPi * u2);
}

// ---------------------------------------------------------------------------------------------
// VelocityEstimator

VelocityEstimator::VelocityEstimator(double window_s, double time_constant_s) noexcept
    : window_s_(window_s), time_constant_s_(time_constant_s) {}

void VelocityEstimator::reset() noexcept {
  oldest_ = 0;
  count_ = 0;
  filtered_.setZero();
}

const Eigen::Vector3d& VelocityEstimator::update(double time_s,
                                                 const Eigen::Vector3d& position_m) noexcept {
  const double previous_time_s =
      count_ > 0 ? times_[static_cast<std::size_t>((oldest_ + count_ - 1) % kCapacity)] : time_s;
  if (count_ == kCapacity) {  // Full: the window shrinks to what the history holds.
    oldest_ = (oldest_ + 1) % kCapacity;
    --count_;
  }
  const int newest = (oldest_ + count_) % kCapacity;
  positions_[static_cast<std::size_t>(newest)] = position_m;
  times_[static_cast<std::size_t>(newest)] = time_s;
  ++count_;
  // Keep exactly one sample at least a window old: the difference spans the whole window.
  // (The tolerance keeps a sample exactly one window old despite rounding of the clock.)
  while (count_ > 2 &&
         time_s - times_[static_cast<std::size_t>((oldest_ + 1) % kCapacity)] >= window_s_ - 1e-9) {
    oldest_ = (oldest_ + 1) % kCapacity;
    --count_;
  }
  if (count_ < 2) {
    filtered_.setZero();
    return filtered_;
  }
  const Eigen::Vector3d& old_position = positions_[static_cast<std::size_t>(oldest_)];
  const double span_s = time_s - times_[static_cast<std::size_t>(oldest_)];
  if (!(span_s > 0.0) || position_m == old_position) {
    // No encoder change over the window: a driver reports exactly zero, not a decaying tail.
    filtered_.setZero();
    return filtered_;
  }
  const Eigen::Vector3d raw = (position_m - old_position) / span_s;
  const double dt_s = time_s - previous_time_s;
  const double gain = time_constant_s_ > 0.0 ? dt_s / (time_constant_s_ + dt_s) : 1.0;
  filtered_ += gain * (raw - filtered_);
  return filtered_;
}

// ---------------------------------------------------------------------------------------------
// SimulatedDriver

SimulatedDriver::SimulatedDriver(DeviceSpecifications specifications,
                                 const DriverParameters& parameters, std::uint64_t seed)
    : specifications_(std::move(specifications)),
      step_s_(1.0 / parameters.internal_rate_hz),
      random_(seed),
      noise_sigma_counts_(parameters.noise_sigma_counts),
      noise_correlation_time_s_(parameters.noise_correlation_time_s),
      uncalibrated_offset_m_(parameters.uncalibrated_offset_m),
      velocity_(parameters.velocity_window_s, parameters.velocity_time_constant_s),
      motor_limit_(parameters.motor_limit),
      dac_step_(Eigen::Vector3d::Zero()),
      actuator_gain_(parameters.actuator_gain),
      thermal_enabled_(parameters.thermal.enabled),
      homing_offset_counts_(parameters.homing_offset_counts),
      homing_offset_(!parameters.homing_offset_counts.isZero(0.0)) {
  validateSpecifications(specifications_);
  const std::string name = specifications_.model_name;
  if (!finitePositive(parameters.internal_rate_hz) || parameters.internal_rate_hz < 1000.0) {
    throw Error(name + ": internal_rate_hz must be at least 1000 Hz (servo loops run at 1 kHz)");
  }
  if (!std::isfinite(parameters.noise_sigma_counts) || parameters.noise_sigma_counts < 0.0) {
    throw Error(name + ": noise_sigma_counts must be finite and >= 0");
  }
  if (!finitePositive(parameters.noise_correlation_time_s)) {
    throw Error(name + ": noise_correlation_time_s must be finite and > 0");
  }
  if (!finitePositive(parameters.velocity_window_s)) {
    throw Error(name + ": velocity_window_s must be finite and > 0");
  }
  if (!std::isfinite(parameters.velocity_time_constant_s) ||
      parameters.velocity_time_constant_s < 0.0) {
    throw Error(name + ": velocity_time_constant_s must be finite and >= 0");
  }
  if (!parameters.uncalibrated_offset_m.allFinite()) {
    throw Error(name + ": uncalibrated_offset_m must be finite");
  }
  if ((parameters.motor_limit.array().isNaN()).any() ||
      (parameters.motor_limit.array() <= 0.0).any()) {
    throw Error(name + ": motor_limit must be > 0 on every motor");
  }
  if (parameters.dac_bits < 0 || parameters.dac_bits > 24 ||
      (parameters.dac_bits > 0 && !parameters.motor_limit.allFinite())) {
    throw Error(name + ": dac_bits must be in [0, 24], and > 0 only with a finite motor_limit");
  }
  if (parameters.dac_bits > 0) {
    dac_step_ = parameters.motor_limit * (2.0 / std::ldexp(1.0, parameters.dac_bits));
  }
  if (!std::isfinite(parameters.transport_delay_s) || parameters.transport_delay_s < 0.0 ||
      parameters.transport_delay_s > 0.01) {
    throw Error(name + ": transport_delay_s must be in [0, 0.01] s");
  }
  delay_steps_ = static_cast<std::uint64_t>(std::llround(parameters.transport_delay_s / step_s_));
  // A motor that delivers less than half or more than twice its command is broken, not off
  // nominal.
  if (!parameters.actuator_gain.allFinite() || (parameters.actuator_gain.array() < 0.5).any() ||
      (parameters.actuator_gain.array() > 2.0).any()) {
    throw Error(name + ": actuator_gain must lie in [0.5, 2] on every motor");
  }
  if (!parameters.homing_offset_counts.allFinite()) {
    throw Error(name + ": homing_offset_counts must be finite");
  }
  if (thermal_enabled_) {
    // Each motor's share of its range at the continuous rating is the device's: the rated
    // command heats a motor to its rated rise.
    const double share =
        continuousForceRating_n(specifications_) / specifications_.max_linear_force_n;
    if (!parameters.motor_limit.allFinite()) {
      throw Error(name + ": motors that warm need a finite motor_limit (their rated current)");
    }
    thermal_ = MotorThermalModel(parameters.motor_thermal, parameters.motor_limit * share,
                                 parameters.thermal);
  }
  // Start the noise in its stationary distribution so that the first samples are typical.
  for (int axis = 0; axis < 3; ++axis)
    noise_counts_[axis] = noise_sigma_counts_ * random_.gaussian();
}

bool SimulatedDriver::open() {
  open_ = true;
  return true;
}

bool SimulatedDriver::close() {
  zeroActuators();
  open_ = false;
  return true;
}

bool SimulatedDriver::calibrate(bool force) {
  if (!open_ || fault_ == DeviceFault::kStopsAnswering) return false;
  if (force) {
    calibrated_ = true;
    has_sample_ = false;  // The offset changes: the velocity history is no longer comparable.
    velocity_.reset();
  }
  return calibrated_;
}

void SimulatedDriver::sampleEncoders() noexcept {
  if (has_sample_ && last_sample_step_ == steps_) return;
  // Gauss-Markov noise, exact discretization over the time since the last sample.
  const double since_s =
      has_sample_ ? static_cast<double>(steps_ - last_sample_step_) * step_s_ : step_s_;
  const double decay = std::exp(-since_s / noise_correlation_time_s_);
  const double drive = noise_sigma_counts_ * std::sqrt(1.0 - decay * decay);
  for (int axis = 0; axis < 3; ++axis) {
    noise_counts_[axis] = decay * noise_counts_[axis] + drive * random_.gaussian();
  }
  measured_position_m_ = readEncoders(
      homing_offset_ ? Eigen::Vector3d(noise_counts_ + homing_offset_counts_) : noise_counts_);
  if (!calibrated_) measured_position_m_ += uncalibrated_offset_m_;
  velocity_.update(time_s(), measured_position_m_);
  last_sample_step_ = steps_;
  has_sample_ = true;
}

bool SimulatedDriver::getPosition(Eigen::Vector3d& position_m) {
  if (!open_ || fault_ == DeviceFault::kStopsAnswering) return false;
  if (fault_ == DeviceFault::kNanPosition) {
    position_m.setConstant(std::numeric_limits<double>::quiet_NaN());
    return true;
  }
  if (fault_ == DeviceFault::kFrozenPosition) {
    position_m = frozen_position_m_;
    return true;
  }
  sampleEncoders();
  position_m = measured_position_m_;
  return true;
}

bool SimulatedDriver::getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) {
  if (!open_ || fault_ == DeviceFault::kStopsAnswering) return false;
  if (fault_ == DeviceFault::kNanPosition) {
    velocity_m_per_s.setConstant(std::numeric_limits<double>::quiet_NaN());
    return true;
  }
  if (fault_ == DeviceFault::kFrozenPosition) {
    velocity_m_per_s = frozen_velocity_m_per_s_;
    return true;
  }
  sampleEncoders();
  velocity_m_per_s = velocity_.estimate_m_per_s();
  return true;
}

bool SimulatedDriver::getUserSwitch(int index, bool& pressed) {
  if (!open_ || fault_ == DeviceFault::kStopsAnswering) return false;
  if (index < 0 || index >= kSwitchCount) return false;
  pressed = switches_[static_cast<std::size_t>(index)];
  return true;
}

void SimulatedDriver::zeroActuators() noexcept {
  active_motor_command_.setZero();
  pending_count_ = 0;
}

bool SimulatedDriver::setForce(const Eigen::Vector3d& force_n) {
  if (!open_ || fault_ == DeviceFault::kStopsAnswering || !force_n.allFinite()) {
    zeroActuators();
    return false;
  }
  const double max_n = specifications_.max_linear_force_n;
  const double norm_n = force_n.norm();
  bool saturated = norm_n > max_n;
  Eigen::Vector3d motor =
      cartesianToMotor(saturated ? Eigen::Vector3d(force_n * (max_n / norm_n)) : force_n);
  for (int j = 0; j < 3; ++j) {
    if (std::abs(motor[j]) > motor_limit_[j]) {
      motor[j] = std::copysign(motor_limit_[j], motor[j]);
      saturated = true;
    }
    if (dac_step_[j] > 0.0) motor[j] = std::round(motor[j] / dac_step_[j]) * dac_step_[j];
  }
  if (saturated) ++saturation_count_;

  const std::uint64_t due = steps_ + delay_steps_;
  if (delay_steps_ == 0) {
    active_motor_command_ = motor;
    return true;
  }
  if (pending_count_ > 0) {
    PendingCommand& last = pending_[static_cast<std::size_t>((pending_first_ + pending_count_ - 1) %
                                                             kPendingCapacity)];
    if (last.step == due) {  // the later command of the same step wins
      last.motor = motor;
      return true;
    }
  }
  if (pending_count_ == kPendingCapacity) {  // never advanced: the oldest command is lost
    pending_first_ = (pending_first_ + 1) % kPendingCapacity;
    --pending_count_;
  }
  const int slot = (pending_first_ + pending_count_) % kPendingCapacity;
  pending_[static_cast<std::size_t>(slot)] = {due, motor};
  ++pending_count_;
  return true;
}

void SimulatedDriver::advance(double dt_s) noexcept {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s)) return;
  pending_s_ += dt_s;
  // The tolerance absorbs the rounding of sums like 10 x 0.0001 s.
  const double whole = std::floor(pending_s_ / step_s_ + 1e-6);
  if (whole < 1.0) return;
  const auto steps = static_cast<std::uint64_t>(whole);
  pending_s_ = std::max(0.0, pending_s_ - whole * step_s_);
  for (std::uint64_t i = 0; i < steps; ++i) {
    Eigen::Vector3d hand_n = Eigen::Vector3d::Zero();
    if (hand_.holding()) {
      hand_n = hand_.update(step_s_, truePosition_m(), trueVelocity_m_per_s());
    } else if (!hand_.atGoal()) {  // a released hand's target may still be gliding
      hand_.update(step_s_, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    }
    // A tilted base turns the mechanism's gravity: one more external force on the end-effector.
    // Each motor delivers its command times its own gain.
    if (thermal_enabled_) thermal_.step(step_s_, active_motor_command_);
    integrateStep(deliveredGains().cwiseProduct(active_motor_command_),
                  tilted_ ? Eigen::Vector3d(hand_n + tiltForce_n()) : hand_n, step_s_);
    ++steps_;
    // Commands due now act from here on (and show in appliedForce_n from this time).
    while (pending_count_ > 0 &&
           pending_[static_cast<std::size_t>(pending_first_)].step <= steps_) {
      active_motor_command_ = pending_[static_cast<std::size_t>(pending_first_)].motor;
      pending_first_ = (pending_first_ + 1) % kPendingCapacity;
      --pending_count_;
    }
  }
}

double SimulatedDriver::time_s() const noexcept { return static_cast<double>(steps_) * step_s_; }

void SimulatedDriver::injectFault(DeviceFault fault) noexcept {
  if (fault == DeviceFault::kFrozenPosition && fault_ != DeviceFault::kFrozenPosition) {
    sampleEncoders();
    frozen_position_m_ = measured_position_m_;
    frozen_velocity_m_per_s_ = velocity_.estimate_m_per_s();
  }
  if (fault == DeviceFault::kStopsAnswering) zeroActuators();
  fault_ = fault;
}

void SimulatedDriver::setUserSwitch(int index, bool pressed) noexcept {
  if (index < 0 || index >= kSwitchCount) return;
  switches_[static_cast<std::size_t>(index)] = pressed;
}

void SimulatedDriver::resetState(const Eigen::Vector3d& position_m) {
  if (!position_m.allFinite()) {
    throw Error(specifications_.model_name + ": resetState needs a finite position");
  }
  resetMechanism(position_m);
  end_stop_hit_ = false;
  has_sample_ = false;
  velocity_.reset();
}

void SimulatedDriver::setPayload_kg(double payload_kg) {
  const std::string& name = specifications_.model_name;
  if (!std::isfinite(payload_kg) || payload_kg < 0.0) {
    throw Error(name + ": the payload must be finite and >= 0 kg");
  }
  if (payload_kg * kStandardGravity > kMaxPayloadForceShare * specifications_.max_linear_force_n) {
    throw Error(name + ": a payload of " + std::to_string(payload_kg * 1e3) +
                " g weighs more than a quarter of the device's force: it could not hold it up "
                "and do anything else");
  }
  applyPayload_kg(payload_kg);
}

void SimulatedDriver::setTilt_rad(double tilt_rad) {
  if (!std::isfinite(tilt_rad)) {
    throw Error(specifications_.model_name + ": the tilt must be a finite angle");
  }
  tilt_ = Eigen::AngleAxisd(tilt_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  tilted_ = tilt_rad != 0.0;
}

Eigen::Vector3d SimulatedDriver::loadedGravity_n(
    const Eigen::Vector3d& mechanism_gravity_n) const noexcept {
  return tilted_ ? Eigen::Vector3d(tilt_ * mechanism_gravity_n) : mechanism_gravity_n;
}

Eigen::Vector3d SimulatedDriver::commandDelivering_n(
    const Eigen::Matrix3d& motor_per_force, const Eigen::Vector3d& delivered_n) const noexcept {
  const Eigen::Vector3d motor = motor_per_force * delivered_n;
  return motor_per_force.inverse() * motor.cwiseQuotient(deliveredGains());
}

Eigen::Vector3d SimulatedDriver::tiltForce_n() const noexcept {
  // The mechanism integrates M a = F - G; with this force it integrates M a = F - R G.
  const Eigen::Vector3d own_gravity_n = mechanismGravity_n();
  return own_gravity_n - tilt_ * own_gravity_n;
}

}  // namespace autograv::sim
