#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "autograv/device/device_specifications.h"
#include "autograv/sim/motor_thermal.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/simulated_hand.h"

namespace autograv::sim {

/// Deterministic pseudo-random numbers: xoshiro256** seeded through splitmix64, Gaussian samples
/// by the Box-Muller transform. Same seed, same sequence on every platform (no std::
/// distributions, whose output is implementation-defined). Real-time safe.
class Random {
 public:
  /// Seeds the generator (splitmix64 of `seed`).
  explicit Random(std::uint64_t seed) noexcept;
  /// 64 uniformly random bits.
  std::uint64_t nextBits() noexcept;
  /// Uniform in [0, 1).
  double uniform() noexcept;
  /// Standard normal.
  double gaussian() noexcept;

 private:
  std::array<std::uint64_t, 4> state_{};
  double spare_ = 0.0;
  bool has_spare_ = false;
};

/// Velocity estimation as device drivers do it (e.g. Force Dimension's "windowing" mode): the
/// displacement of the quantized position over a fixed time window, smoothed by a first-order
/// low-pass. It reads exactly zero when the position did not change over the window, so a device
/// at rest reports a velocity of exactly zero. Fixed-size history: real-time safe.
class VelocityEstimator {
 public:
  /// `window_s`: finite-difference window; `time_constant_s`: low-pass time constant (0 = none).
  /// Units: [s]
  VelocityEstimator(double window_s, double time_constant_s) noexcept;
  /// Forgets the history; the next estimate starts from zero. Real-time safe.
  void reset() noexcept;
  /// Adds a sample taken at `time_s` and returns the new estimate. Units: [s], [m], [m/s]
  const Eigen::Vector3d& update(double time_s, const Eigen::Vector3d& position_m) noexcept;
  /// The latest estimate. Unit: [m/s]
  const Eigen::Vector3d& estimate_m_per_s() const noexcept { return filtered_; }

 private:
  static constexpr int kCapacity = 512;
  std::array<Eigen::Vector3d, kCapacity> positions_{};
  std::array<double, kCapacity> times_{};
  int oldest_ = 0;
  int count_ = 0;
  double window_s_;
  double time_constant_s_;
  Eigen::Vector3d filtered_ = Eigen::Vector3d::Zero();
};

/// What the simulated driver and its electronics do, independently of the mechanism.
struct DriverParameters {
  /// Rate of the fixed-step integration inside advance(). Unit: [Hz]
  double internal_rate_hz = 10000.0;
  /// Encoder noise before quantization, a Gauss-Markov process (electrical and mechanical jitter
  /// is correlated in time, not white). Standard deviation in encoder counts.
  double noise_sigma_counts = 0.05;
  /// Correlation time of that noise. Unit: [s]
  double noise_correlation_time_s = 0.01;
  /// Velocity estimator window. Unit: [s]
  double velocity_window_s = 0.02;
  /// Velocity estimator low-pass time constant. Unit: [s]
  double velocity_time_constant_s = 0.001;
  /// Position offset the readings carry until the device is homed (see setCalibrated). Unit: [m]
  Eigen::Vector3d uncalibrated_offset_m = Eigen::Vector3d(0.012, -0.007, 0.021);
  /// Range of each motor's command, in the mechanism's actuator units (joint torque [N m] for an
  /// arm, axis force [N] for a Cartesian mechanism): a command beyond it saturates that motor
  /// alone, as an amplifier clips. Infinite: no per-motor saturation.
  Eigen::Vector3d motor_limit = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  /// Resolution of the force DAC, bipolar over [-motor_limit, motor_limit]; 0: an ideal DAC.
  int dac_bits = 0;
  /// Transport delay between setForce and the actuators: the driver ships a command to the
  /// device once per servo period. Unit: [s]
  double transport_delay_s = 0.001;
  /// What each motor delivers per unit of its command: its torque constant, its amplifier's gain
  /// and its transmission ratio against nominal (actuatorGains). The driver computes commands
  /// from the nominal model, as a real one does; all ones is an ideal unit.
  Eigen::Vector3d actuator_gain = Eigen::Vector3d::Ones();
  /// Whether the motors warm (MotorThermalModel), the room and where they start. Disabled: each
  /// motor delivers actuator_gain at every moment.
  ThermalConditions thermal = {};
  /// The motors' thermal figures (used when thermal.enabled). Their heat at the continuous force
  /// rating (continuousForceRating_n, each motor at that share of motor_limit) reaches the rated
  /// rise.
  MotorThermalParameters motor_thermal = {};
  /// Where this session's homing landed against the one the map was made in: added to each
  /// encoder's reading before quantization (homingOffsetCounts). Unit: [encoder counts]
  Eigen::Vector3d homing_offset_counts = Eigen::Vector3d::Zero();
};

/// The driver side shared by the simulated devices: open/close, homing, encoder sampling with
/// noise, velocity estimation, actuator saturation, faults, user switches, the hand and the
/// fixed-step clock. A mechanism subclass supplies the physics (one integration step) and its
/// encoders (quantized reading from noisy counts).
///
/// Sampling: the driver reads the encoders when the application asks for a position or a velocity,
/// at most once per internal step, as a real driver reads them on each servo-loop query; the
/// velocity estimator sees exactly those samples.
class SimulatedDriver : public SimulatedDevice {
 public:
  /// Not real-time safe.
  bool open() override;
  /// Sends zero force and closes. Not real-time safe.
  bool close() override;
  /// True once homed. A device made uncalibrated by setCalibrated(false) returns false until
  /// calibrate(true) homes it. Not real-time safe.
  bool calibrate(bool force = false) override;

  /// Measured (noisy, quantized) position. False when closed or when the device stops answering;
  /// true with NaN under kNanPosition; the last sample under kFrozenPosition. Real-time safe.
  bool getPosition(Eigen::Vector3d& position_m) override;
  /// Velocity estimated from the measured positions; same fault behaviour as getPosition (NaN
  /// under kNanPosition, the last estimate under kFrozenPosition). Real-time safe.
  bool getLinearVelocity(Eigen::Vector3d& velocity_m_per_s) override;
  /// Switches 0..kSwitchCount-1; false for other indices, when closed or not answering.
  /// Real-time safe.
  bool getUserSwitch(int index, bool& pressed) override;
  /// Commands a force, clamped to the maximum force keeping its direction (counted), then turned
  /// into motor commands that each saturate at their own limit (counted too, once per call) and
  /// are quantized by the DAC. The actuators apply them `transport_delay_s` later. A non-finite
  /// force is refused: false, and the actuators go to zero at once. False when closed or not
  /// answering (the device's watchdog then zeroes the force). Real-time safe.
  bool setForce(const Eigen::Vector3d& force_n) override;
  /// Real-time safe.
  const DeviceSpecifications& specifications() const override { return specifications_; }

  /// Real-time safe.
  void advance(double dt_s) noexcept override;
  /// Real-time safe. Unit: [s]
  double time_s() const noexcept override;
  /// The Cartesian force the motors now deliver: the commands now acting (saturated, quantized,
  /// delayed) times each motor's gain, at the current pose. Real-time safe. Unit: [N]
  Eigen::Vector3d appliedForce_n() const noexcept override {
    return motorToCartesian(deliveredGains().cwiseProduct(active_motor_command_));
  }
  /// Each motor's delivered torque (or force) per commanded one at the reference temperature
  /// (DriverParameters::actuator_gain): ground truth, for reports; an estimator never sees it.
  /// Real-time safe.
  const Eigen::Vector3d& actuatorGains() const noexcept { return actuator_gain_; }
  /// The same now, at the motors' temperatures (actuatorGains() when they do not warm).
  /// Real-time safe.
  Eigen::Vector3d deliveredGains() const noexcept {
    return thermal_enabled_ ? Eigen::Vector3d(actuator_gain_.cwiseProduct(thermal_.gainFactor()))
                            : actuator_gain_;
  }
  /// Real-time safe.
  const MotorThermalModel* motorThermal() const noexcept override {
    return thermal_enabled_ ? &thermal_ : nullptr;
  }
  /// Real-time safe.
  MotorThermalModel* motorThermal() noexcept override {
    return thermal_enabled_ ? &thermal_ : nullptr;
  }
  /// The motor commands now acting, in the mechanism's actuator units. Real-time safe.
  const Eigen::Vector3d& activeMotorCommand() const noexcept { return active_motor_command_; }
  /// Real-time safe.
  std::uint64_t saturationCount() const noexcept override { return saturation_count_; }
  /// Real-time safe.
  SimulatedHand& hand() noexcept override { return hand_; }
  /// Real-time safe.
  void injectFault(DeviceFault fault) noexcept override;
  /// Real-time safe.
  void setUserSwitch(int index, bool pressed) noexcept override;
  /// Puts the end-effector at rest at `position_m`, forgets the velocity history and the end-stop
  /// flag. Throws autograv::Error for a non-finite or unreachable position. Not real-time safe.
  void resetState(const Eigen::Vector3d& position_m) override;
  /// Real-time safe.
  bool endStopHit() const noexcept override { return end_stop_hit_; }
  /// Real-time safe.
  void clearEndStopHit() noexcept override { end_stop_hit_ = false; }
  /// Real-time safe. Unit: [s]
  double internalStep_s() const noexcept override { return step_s_; }
  /// Not real-time safe.
  void setCalibrated(bool calibrated) noexcept override { calibrated_ = calibrated; }
  /// Real-time safe.
  bool isCalibrated() const noexcept override { return calibrated_; }
  /// Real-time safe.
  DeviceFault fault() const noexcept { return fault_; }
  /// Not real-time safe. Unit: [kg]
  void setPayload_kg(double payload_kg) override;
  /// Not real-time safe. Unit: [rad]
  void setTilt_rad(double tilt_rad) override;

  /// User switches (stylus buttons) the driver reports.
  static constexpr int kSwitchCount = 4;

 protected:
  /// Throws autograv::Error when the specifications or parameters are not usable.
  SimulatedDriver(DeviceSpecifications specifications, const DriverParameters& parameters,
                  std::uint64_t seed);

  /// One fixed integration step of the mechanism under the motor commands `motor_command` (held
  /// over the step, actuator units) and the Cartesian force `external_force_n` (the hand). Sets
  /// end_stop_hit_ when the end stops act. Real-time safe. Units: [N], [s]
  virtual void integrateStep(const Eigen::Vector3d& motor_command,
                             const Eigen::Vector3d& external_force_n, double dt_s) noexcept = 0;
  /// Motor commands that produce the Cartesian force `force_n` at the current pose (J^T F for an
  /// arm). Real-time safe.
  virtual Eigen::Vector3d cartesianToMotor(const Eigen::Vector3d& force_n) const noexcept = 0;
  /// Cartesian force that motor commands produce at the current pose. Real-time safe. Unit: [N]
  virtual Eigen::Vector3d motorToCartesian(const Eigen::Vector3d& command) const noexcept = 0;
  /// Quantized end-effector position from the encoders, each encoder reading perturbed by
  /// `noise_counts` (encoder counts) before quantization. Real-time safe. Unit: [m]
  virtual Eigen::Vector3d readEncoders(const Eigen::Vector3d& noise_counts) const noexcept = 0;
  /// Puts the mechanism at rest at `position_m`; throws autograv::Error if it cannot.
  virtual void resetMechanism(const Eigen::Vector3d& position_m) = 0;
  /// The mechanism's own apparent gravity at its current state (payload included, tilt not).
  /// Real-time safe. Unit: [N]
  virtual Eigen::Vector3d mechanismGravity_n() const noexcept = 0;
  /// Adds a point mass of `payload_kg` at the end-effector to the mechanism's dynamics (replacing
  /// any earlier one); already validated by setPayload_kg. Not real-time safe. Unit: [kg]
  virtual void applyPayload_kg(double payload_kg) = 0;

  /// `mechanism_gravity_n` turned by the tilt: the physical force the motors must deliver to hold
  /// the end-effector still. Real-time safe. Unit: [N]
  Eigen::Vector3d loadedGravity_n(const Eigen::Vector3d& mechanism_gravity_n) const noexcept;
  /// The force command under which the motors deliver `delivered_n` (what trueGravity reports):
  /// the driver turns a command F into motor commands C F with the nominal C = d(motor)/d(force)
  /// at the pose (J^T for an arm, `motor_per_force`), and motor j delivers gain_j times its
  /// command, so the command is C^-1 K^-1 C delivered_n. Where the gains differ, that is no
  /// longer the gradient of a potential on a mechanism whose joints share one. Real-time safe.
  /// Unit: [N]
  Eigen::Vector3d commandDelivering_n(const Eigen::Matrix3d& motor_per_force,
                                      const Eigen::Vector3d& delivered_n) const noexcept;

  /// Set when the end-effector touched an end stop (endStopHit()).
  bool end_stop_hit_ = false;

 private:
  void sampleEncoders() noexcept;
  /// Force that turns the mechanism's gravity G into the tilted R G for one internal step.
  /// Real-time safe. Unit: [N]
  Eigen::Vector3d tiltForce_n() const noexcept;
  /// Stops the actuators now and forgets the commands in flight.
  void zeroActuators() noexcept;

  /// A motor command on its way to the device, and the internal step at which it takes effect.
  struct PendingCommand {
    std::uint64_t step = 0;
    Eigen::Vector3d motor = Eigen::Vector3d::Zero();
  };
  static constexpr int kPendingCapacity = 16;

  DeviceSpecifications specifications_;
  double step_s_;
  std::uint64_t steps_ = 0;
  double pending_s_ = 0.0;
  Random random_;
  double noise_sigma_counts_;
  double noise_correlation_time_s_;
  Eigen::Vector3d noise_counts_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d uncalibrated_offset_m_;
  VelocityEstimator velocity_;
  SimulatedHand hand_;
  Eigen::Vector3d motor_limit_;
  Eigen::Vector3d dac_step_;  // one DAC count per motor; 0: ideal
  std::uint64_t delay_steps_ = 0;
  std::array<PendingCommand, kPendingCapacity> pending_{};
  int pending_first_ = 0;
  int pending_count_ = 0;
  Eigen::Vector3d active_motor_command_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d actuator_gain_ = Eigen::Vector3d::Ones();
  bool thermal_enabled_ = false;
  MotorThermalModel thermal_;
  Eigen::Vector3d homing_offset_counts_ = Eigen::Vector3d::Zero();
  bool homing_offset_ = false;
  std::uint64_t saturation_count_ = 0;
  std::uint64_t last_sample_step_ = 0;
  bool has_sample_ = false;
  Eigen::Vector3d measured_position_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d frozen_position_m_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d frozen_velocity_m_per_s_ = Eigen::Vector3d::Zero();
  DeviceFault fault_ = DeviceFault::kNone;
  std::array<bool, kSwitchCount> switches_{};
  bool open_ = false;
  bool calibrated_ = true;
  // Tilt of the base (setTilt_rad); none by default, and then no extra work per step.
  Eigen::Matrix3d tilt_ = Eigen::Matrix3d::Identity();
  bool tilted_ = false;
};

}  // namespace autograv::sim
