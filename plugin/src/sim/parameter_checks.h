#pragma once

#include <string>
#include <utility>

#include <Eigen/Core>

#include "autograv/sim/friction.h"

namespace autograv::sim {

/// The checks a simulated device runs on its parameters at construction. Every failure throws
/// autograv::Error naming the device and the parameter, e.g. "sim delta device: grip_mass_kg must
/// be finite and > 0". Not real-time safe.
class ParameterChecks {
 public:
  /// `device` starts every message, e.g. "sim delta device".
  explicit ParameterChecks(std::string device) : device_(std::move(device)) {}

  /// Finite and > 0; a vector on every component.
  void positive(double value, const char* name) const;
  void positive(const Eigen::Vector3d& values, const char* name) const;
  /// Finite and >= 0; a vector on every component.
  void nonNegative(double value, const char* name) const;
  void nonNegative(const Eigen::Vector3d& values, const char* name) const;
  /// Every component finite.
  void finite(double value, const char* name) const;
  void finite(const Eigen::Vector3d& values, const char* name) const;
  void finite(const Eigen::Matrix3d& values, const char* name) const;
  /// LuGre friction of the joints or axes (LuGreParameters::validate under the device's name).
  void friction(const LuGreParameters& friction) const;
  /// Cogging of the three motors: amplitudes finite and >= 0, phases finite.
  void cogging(const Eigen::Vector3d& amplitude, const char* amplitude_name,
               const Eigen::Vector3d& phase_rad) const;
  /// The upper arms, forearms, motors, encoders and joint friction of a mechanism driven in joint
  /// space: SerialArmParameters and DeltaParameters name and mean them alike.
  template <class ArmParameters>
  void armsAndMotors(const ArmParameters& p) const {
    positive(p.upper_arm_length_m, "upper_arm_length_m");
    positive(p.forearm_length_m, "forearm_length_m");
    nonNegative(p.upper_arm_mass_kg, "upper_arm_mass_kg");
    finite(p.upper_arm_com_m, "upper_arm_com_m");
    nonNegative(p.upper_arm_inertia_kg_m2, "upper_arm_inertia_kg_m2");
    nonNegative(p.forearm_mass_kg, "forearm_mass_kg");
    nonNegative(p.rotor_inertia_kg_m2, "rotor_inertia_kg_m2");
    positive(p.joint_counts_per_rev, "joint_counts_per_rev");
    friction(p.friction);
  }
  /// Throws autograv::Error "<device>: <what>", for the checks particular to one device.
  [[noreturn]] void fail(const std::string& what) const;

 private:
  std::string device_;
};

}  // namespace autograv::sim
