#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/device/haptic_device.h"
#include "autograv/device/servo_loop_stats.h"
#include "autograv/device/tick_source.h"
#include "autograv/sim/actuators.h"
#include "autograv/sim/friction.h"
#include "autograv/sim/motor_thermal.h"
#include "autograv/sim/servo_timing_model.h"
#include "autograv/sim/simulated_hand.h"

namespace autograv::sim {

/// Faults a simulated driver can be told to show, for error-path tests.
enum class DeviceFault : std::uint8_t {
  kNone,
  kStopsAnswering,  ///< Every getter and setForce returns false.
  kNanPosition,     ///< getPosition returns true with NaN components.
  kFrozenPosition,  ///< getPosition keeps returning the last sample (a stale driver).
};

/// A simulated 3-DoF device with a known ground-truth apparent gravity field. The HapticDevice
/// side behaves like a real driver (quantized encoders, noise, estimated velocity, saturation);
/// the true*() side is for tests and reports only and must never feed an estimator.
class SimulatedDevice : public HapticDevice {
 public:
  /// Integrates the dynamics over `dt_s` with the internal fixed step, holding the last commanded
  /// force (zero-order hold) and the hand's force. Real-time safe. Unit: [s]
  virtual void advance(double dt_s) noexcept = 0;
  /// Simulated time since construction. Unit: [s]
  virtual double time_s() const noexcept = 0;

  /// Ground-truth apparent gravity G(X) at an end-effector position, with the paper's sign
  /// (eq. 1, M Xdd + G = F): the force command (setForce) that holds the end-effector still, so
  /// it points mostly up (+z); the weight a user feels is about -G. The command includes what
  /// the unit's actuators make of it (DriverParameters::actuator_gain): a motor that delivers 5 %
  /// less needs 5 % more command. Unit: [N]
  virtual Eigen::Vector3d trueGravity(const Eigen::Vector3d& position_m) const = 0;
  /// Ground-truth apparent (Cartesian) mass at a position. Unit: [kg]
  virtual Eigen::Matrix3d trueApparentMass(const Eigen::Vector3d& position_m) const = 0;
  /// True, unquantized end-effector position and velocity. Unit: [m], [m/s]
  virtual Eigen::Vector3d truePosition_m() const noexcept = 0;
  /// See truePosition_m(). Unit: [m/s]
  virtual Eigen::Vector3d trueVelocity_m_per_s() const noexcept = 0;
  /// Puts the end-effector at rest at `position_m` (tests and scripted demos). The actuators keep
  /// their command: a force sent now reaches them one transport delay later, so send the force
  /// that should hold it there and advance one servo period before the reset. Unit: [m]
  virtual void resetState(const Eigen::Vector3d& position_m) = 0;

  /// Force the actuators produce now: the command of one transport delay ago, after saturation
  /// and the force DAC's quantization. Unit: [N]
  virtual Eigen::Vector3d appliedForce_n() const noexcept = 0;
  /// Number of setForce calls whose force was clamped by actuator saturation.
  virtual std::uint64_t saturationCount() const noexcept = 0;

  /// The simulated user's hand acting on this device.
  virtual SimulatedHand& hand() noexcept = 0;
  /// Makes the driver misbehave from now on (kNone heals it).
  virtual void injectFault(DeviceFault fault) noexcept = 0;
  /// Presses or releases simulated user switch `index`.
  virtual void setUserSwitch(int index, bool pressed) noexcept = 0;

  /// True when the end-effector has pressed against the mechanical end stops (a stiff spring
  /// beyond the workspace radius) since construction or the last resetState.
  virtual bool endStopHit() const noexcept = 0;
  /// Forgets that the end stops were hit, so that a procedure can tell whether they are hit from
  /// now on. Real-time safe.
  virtual void clearEndStopHit() noexcept = 0;
  /// Centre of the workspace sphere of radius specifications().workspace_radius_m. Unit: [m]
  virtual Eigen::Vector3d workspaceCenter_m() const noexcept = 0;
  /// Ground truth: whether the mechanism can hold the end-effector at `position_m` without
  /// touching an end stop or a joint limit. By default: inside the workspace sphere. For fitting
  /// grids and judging maps, never for an estimator. Real-time safe. Unit: [m]
  virtual bool isReachable(const Eigen::Vector3d& position_m) const noexcept {
    return (position_m - workspaceCenter_m()).norm() <= specifications().workspace_radius_m;
  }
  /// Step of the fixed-step integration inside advance(). Unit: [s]
  virtual double internalStep_s() const noexcept = 0;
  /// setCalibrated(false) makes the device behave as one fresh from power-up that was never
  /// homed: calibrate() returns false and positions carry an offset until calibrate(true).
  virtual void setCalibrated(bool calibrated) noexcept = 0;
  /// False until calibrate() homed a device made uncalibrated by setCalibrated(false).
  virtual bool isCalibrated() const noexcept = 0;

  /// Puts a point load of `payload_kg` on the end-effector (a heavier handle, a tool): a point
  /// mass in the mechanism's dynamics, so trueGravity() gains payload_kg * g along the up
  /// direction and trueApparentMass() gains payload_kg. 0 removes it. Throws autograv::Error for a
  /// negative, non-finite or too heavy load. Not real-time safe. Unit: [kg]
  virtual void setPayload_kg(double payload_kg) = 0;
  /// Tilts the device's base by `tilt_rad` about its y axis (gravity no longer along -z in the
  /// device's frame): trueGravity() is the untilted field rotated by that angle. 0 levels it.
  /// Throws autograv::Error for a non-finite angle. Not real-time safe. Unit: [rad]
  virtual void setTilt_rad(double tilt_rad) = 0;
  /// The motors' temperatures and what they make of each motor's gain, when they warm
  /// (SimulatedUnit::thermal); null when they do not. Ground truth: for reports and studies,
  /// never for an estimator. Real-time safe.
  virtual const MotorThermalModel* motorThermal() const noexcept { return nullptr; }
  /// The same, to set the motors' or the room's temperature (a study of a warm device).
  virtual MotorThermalModel* motorThermal() noexcept { return nullptr; }
};

/// The simulated models of real devices makeSimulatedDevice builds: {"sim:omega", "sim:omni",
/// "sim:falcon"}.
std::vector<std::string> simulatedDeviceNames();
/// The test devices makeSimulatedDevice builds too, made to break what the models above satisfy
/// by construction (a conservative field, a round workspace, rounded stops): {"sim:swirl-cube",
/// "sim:swirl-ellipsoid", "sim:falcon-can"} (swirlCubeParameters, swirlEllipsoidParameters,
/// falconCanParameters: sim:falcon's delta between a flat floor and ceiling). Not models of real
/// devices.
std::vector<std::string> testDeviceNames();

/// Builds a preset simulated device: unit `unit` of the model `name` (its actuators' gains, the
/// same whatever the seed: actuatorGains) with the given friction level; the same seed gives the
/// same run, bit for bit. Throws autograv::Error listing the valid names for an unknown one.
/// Not real-time safe.
std::unique_ptr<SimulatedDevice> makeSimulatedDevice(
    const std::string& name, std::uint64_t seed = 1,
    FrictionLevel friction = FrictionLevel::kTypical, const SimulatedUnit& unit = {});

/// Paces a servo loop on a simulated device: each tick advances the physics by the interval the
/// ServoTimingModel draws (exactly one period with ServoTiming::kExact), either as fast as the CPU
/// allows (tests) or locked to the wall clock (demos). Records what the loop did.
class SimulatedTickSource final : public TickSource {
 public:
  /// How the ticks are paced: as fast as the CPU allows, or locked to the wall clock.
  enum class Mode { kAsFastAsPossible, kRealTime };
  /// Ticks `device` at intervals drawn by the timing model (`period_s` nominal, unit: [s]),
  /// paced by `mode`. Throws autograv::Error for a period outside (0, 0.1] s.
  /// Not real-time safe.
  SimulatedTickSource(SimulatedDevice& device, double period_s, Mode mode,
                      ServoTiming timing = ServoTiming::kExact, std::uint64_t timing_seed = 1);
  /// Real-time safe (kAsFastAsPossible).
  bool waitForNextTick() override;
  double period_s() const override { return period_s_; }
  /// Simulated time since construction (the device's own clock, which the ticks advance).
  /// Unit: [s]
  double now_s() const override;
  double lastInterval_s() const override { return model_.lastInterval_s(); }
  /// The loop's clock, to share with a GravityCompensatedDevice driven by this loop.
  const ServoTimingModel& timingModel() const noexcept { return model_; }
  /// Rate, lateness and gaps of the ticks so far. Not real-time safe.
  ServoLoopStats::Summary loopSummary() const noexcept { return stats_.summary(); }

 private:
  SimulatedDevice& device_;
  double period_s_;
  Mode mode_;
  ServoTimingModel model_;
  ServoLoopStats stats_;
  double start_time_s_;
  long long wall_start_ns_ = 0;
};

}  // namespace autograv::sim
