// Motors that warm as they hold forces, and sessions that home the encoders elsewhere: the
// thermal model's steady state and time constants, what it does to a device's field, and that
// with both off a device is what it was.
#include "autograv/sim/motor_thermal.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/sim/simulated_driver.h"

namespace autograv::sim {
namespace {

constexpr double kStep_s = 0.01;

/// Runs `model` at a constant command for `seconds` and returns it.
MotorThermalModel heldFor(MotorThermalModel model, const Eigen::Vector3d& command, double seconds) {
  for (double t = 0.0; t < seconds; t += kStep_s) model.step(kStep_s, command);
  return model;
}

TEST(MotorThermalTest, TheRatedCommandReachesTheRatedRiseInSteadyState) {
  for (const std::string& name : simulatedDeviceNames()) {
    const MotorThermalParameters motor = motorThermalParameters(name);
    const Eigen::Vector3d rated(0.1, 0.2, 0.3);
    ThermalConditions room;
    room.enabled = true;
    const MotorThermalModel warm =
        heldFor(MotorThermalModel(motor, rated, room), rated, 12.0 * motor.housing_time_constant_s);
    for (int m = 0; m < 3; ++m) {
      EXPECT_NEAR(warm.winding_c()[m] - room.ambient_c, motor.rated_winding_rise_k,
                  0.01 * motor.rated_winding_rise_k)
          << name << " motor " << m;
    }
  }
}

TEST(MotorThermalTest, HeatGoesWithTheSquareOfTheCommandTimesTheResistanceItWarmsTo) {
  // Half the rated command: a quarter of the heat at the same resistance; the resistance then
  // follows the winding's temperature (a current drive's I^2 R grows with it, a voltage drive's
  // V^2 / R falls), so the rise solves rise = rated / 4 * g(rise) / g(rated) (fixed point).
  for (const std::string& name : simulatedDeviceNames()) {
    const MotorThermalParameters motor = motorThermalParameters(name);
    const auto g = [&motor](double rise_k) {
      const double ratio = 1.0 + motor.resistance_coefficient_per_k * rise_k;
      return motor.drive == MotorDrive::kCurrent ? ratio : 1.0 / ratio;
    };
    const double rated_k = motor.rated_winding_rise_k;
    double expected_k = 0.25 * rated_k;
    for (int i = 0; i < 50; ++i) expected_k = 0.25 * rated_k * g(expected_k) / g(rated_k);
    const Eigen::Vector3d rated = Eigen::Vector3d::Constant(1.0);
    ThermalConditions room;
    room.enabled = true;
    const MotorThermalModel half = heldFor(MotorThermalModel(motor, rated, room), 0.5 * rated,
                                           12.0 * motor.housing_time_constant_s);
    EXPECT_NEAR(half.winding_c()[0] - room.ambient_c, expected_k, 0.01 * expected_k) << name;
    // Not a quarter: 12-20 % less on a current drive, about 20 % more on a voltage drive.
    EXPECT_GT(std::abs(expected_k / (0.25 * rated_k) - 1.0), 0.1) << name;
  }
}

TEST(MotorThermalTest, TheWindingLeadsAndTheHousingFollowsOverItsOwnTimeConstant) {
  const MotorThermalParameters motor = motorThermalParameters("sim:omni");
  ThermalConditions room;
  room.enabled = true;
  const Eigen::Vector3d rated = Eigen::Vector3d::Ones();
  const MotorThermalModel minute = heldFor(MotorThermalModel(motor, rated, room), rated, 60.0);
  // After five winding time constants the winding stands its heat times R_wh above the housing
  // (within 15 %: its resistance has risen with it), while the housing has barely moved.
  const double rise_k = motor.rated_winding_rise_k;
  const double heat_w =
      rise_k / ((motor.winding_to_housing_k_per_w + motor.housing_to_ambient_k_per_w) *
                (1.0 + motor.resistance_coefficient_per_k * rise_k));
  const double expected_k = heat_w * motor.winding_to_housing_k_per_w;
  EXPECT_NEAR(minute.winding_c()[0] - minute.housing_c()[0], expected_k, 0.15 * expected_k);
  EXPECT_LT(minute.housing_c()[0] - room.ambient_c, 0.15 * motor.rated_winding_rise_k);
}

TEST(MotorThermalTest, ACurrentDriveLosesTheMagnetsShareAndAVoltageDriveTheResistancesToo) {
  ThermalConditions room;
  room.enabled = true;
  room.start_c = room.reference_c + 30.0;  // a motor 30 K warmer than the factory's
  const Eigen::Vector3d rated = Eigen::Vector3d::Ones();
  const MotorThermalParameters current = motorThermalParameters("sim:omni");
  const MotorThermalParameters voltage = motorThermalParameters("sim:falcon");
  ASSERT_EQ(current.drive, MotorDrive::kCurrent);
  ASSERT_EQ(voltage.drive, MotorDrive::kVoltage);
  EXPECT_NEAR(MotorThermalModel(current, rated, room).gainFactor()[0],
              1.0 + 30.0 * current.magnet_coefficient_per_k, 1e-12);
  EXPECT_NEAR(MotorThermalModel(voltage, rated, room).gainFactor()[0],
              (1.0 + 30.0 * voltage.magnet_coefficient_per_k) /
                  (1.0 + 30.0 * voltage.resistance_coefficient_per_k),
              1e-12);
  // At the reference temperature every motor delivers its unit's gain.
  room.start_c = room.reference_c;
  EXPECT_EQ(MotorThermalModel(voltage, rated, room).gainFactor(), Eigen::Vector3d::Ones());
}

TEST(MotorThermalTest, RefusesFiguresThatCannotBeAMotor) {
  ThermalConditions room;
  MotorThermalParameters motor;
  motor.winding_time_constant_s = 0.0;
  EXPECT_THROW(MotorThermalModel(motor, Eigen::Vector3d::Ones(), room), Error);
  EXPECT_THROW(MotorThermalModel({}, Eigen::Vector3d(1.0, 0.0, 1.0), room), Error);
  room.ambient_c = std::nan("");
  EXPECT_THROW(MotorThermalModel({}, Eigen::Vector3d::Ones(), room), Error);
  EXPECT_THROW(motorThermalParameters("sim:phantom"), Error);
}

TEST(MotorThermalTest, AWarmDeviceNeedsAnotherCommandToHoldTheSameWeight) {
  SimulatedUnit unit;
  unit.thermal.enabled = true;
  for (const std::string& name : simulatedDeviceNames()) {
    const auto cold = makeSimulatedDevice(name, 1, FrictionLevel::kTypical, unit);
    const auto warm = makeSimulatedDevice(name, 1, FrictionLevel::kTypical, unit);
    ASSERT_NE(warm->motorThermal(), nullptr);
    warm->motorThermal()->setTemperature_c(unit.thermal.reference_c + 30.0);
    const Eigen::Vector3d at_m = cold->workspaceCenter_m();
    const double ratio = warm->trueGravity(at_m).norm() / cold->trueGravity(at_m).norm();
    // 30 K: 3.7 % more command for NdFeB magnets on a current drive, 20 % for ferrite on a
    // voltage drive.
    const MotorThermalParameters motor = motorThermalParameters(name);
    const double expected = motor.drive == MotorDrive::kCurrent ? 0.036 : 0.18;
    EXPECT_NEAR(ratio - 1.0, expected, 0.4 * expected) << name;
  }
}

TEST(MotorThermalTest, OffItChangesNothingAndOnInARoomAtTheReferenceItWaitsForCurrent) {
  // With no force sent the motors carry no current: the device with warming motors moves exactly
  // as the one without, step for step.
  SimulatedUnit warming;
  warming.thermal.enabled = true;
  for (const std::string& name : simulatedDeviceNames()) {
    const auto plain = makeSimulatedDevice(name, 7);
    const auto thermal = makeSimulatedDevice(name, 7, FrictionLevel::kTypical, warming);
    EXPECT_EQ(plain->motorThermal(), nullptr);
    plain->open();
    thermal->open();
    for (int tick = 0; tick < 300; ++tick) {
      plain->advance(0.001);
      thermal->advance(0.001);
    }
    EXPECT_EQ(plain->truePosition_m(), thermal->truePosition_m()) << name;
    EXPECT_EQ(plain->trueGravity(plain->workspaceCenter_m()),
              thermal->trueGravity(thermal->workspaceCenter_m()))
        << name;
  }
}

TEST(MotorThermalTest, ASessionHomesWithinTheRepeatabilityAndTheFirstIsTheMapsOwn) {
  for (const std::string& name : simulatedDeviceNames()) {
    const double bound = homingRepeatabilityCounts(name);
    EXPECT_EQ(homingOffsetCounts(name, 1, 1), Eigen::Vector3d::Zero());
    const Eigen::Vector3d second = homingOffsetCounts(name, 1, 2);
    EXPECT_EQ(second, homingOffsetCounts(name, 1, 2)) << "the same session homes the same";
    EXPECT_NE(second, homingOffsetCounts(name, 1, 3));
    EXPECT_NE(second, homingOffsetCounts(name, 2, 2));
    EXPECT_LE(second.cwiseAbs().maxCoeff(), bound) << name;
    EXPECT_GT(second.cwiseAbs().maxCoeff(), 0.0) << name;
  }
  EXPECT_THROW(homingOffsetCounts("sim:omni", 1, 0), Error);
}

TEST(MotorThermalTest, AnotherSessionReadsTheSamePlaceElsewhereByUnderAMillimetre) {
  for (const std::string& name : simulatedDeviceNames()) {
    SimulatedUnit later;
    later.session = 4;
    const auto first = makeSimulatedDevice(name, 3);
    const auto again = makeSimulatedDevice(name, 3, FrictionLevel::kTypical, later);
    first->open();
    again->open();
    const Eigen::Vector3d at_m = first->workspaceCenter_m();
    first->resetState(at_m);
    again->resetState(at_m);
    Eigen::Vector3d read_first, read_again;
    ASSERT_TRUE(first->getPosition(read_first));
    ASSERT_TRUE(again->getPosition(read_again));
    const double shift_m = (read_again - read_first).norm();
    EXPECT_GT(shift_m, 0.02e-3) << name;
    EXPECT_LT(shift_m, 1.0e-3) << name;
  }
}

}  // namespace
}  // namespace autograv::sim
