#include "sim/parameter_checks.h"

#include <cmath>
#include <string>

#include "autograv/error.h"

namespace autograv::sim {

void ParameterChecks::positive(double value, const char* name) const {
  if (!std::isfinite(value) || value <= 0.0) fail(std::string(name) + " must be finite and > 0");
}

void ParameterChecks::positive(const Eigen::Vector3d& values, const char* name) const {
  for (int i = 0; i < 3; ++i) positive(values[i], name);
}

void ParameterChecks::nonNegative(double value, const char* name) const {
  if (!std::isfinite(value) || value < 0.0) fail(std::string(name) + " must be finite and >= 0");
}

void ParameterChecks::nonNegative(const Eigen::Vector3d& values, const char* name) const {
  for (int i = 0; i < 3; ++i) nonNegative(values[i], name);
}

void ParameterChecks::finite(double value, const char* name) const {
  if (!std::isfinite(value)) fail(std::string(name) + " must be finite");
}

void ParameterChecks::finite(const Eigen::Vector3d& values, const char* name) const {
  if (!values.allFinite()) fail(std::string(name) + " must be finite");
}

void ParameterChecks::finite(const Eigen::Matrix3d& values, const char* name) const {
  if (!values.allFinite()) fail(std::string(name) + " must be finite");
}

void ParameterChecks::friction(const LuGreParameters& friction) const {
  friction.validate(device_);
}

void ParameterChecks::cogging(const Eigen::Vector3d& amplitude, const char* amplitude_name,
                              const Eigen::Vector3d& phase_rad) const {
  nonNegative(amplitude, amplitude_name);
  finite(phase_rad, "cogging_phase_rad");
}

void ParameterChecks::fail(const std::string& what) const { throw Error(device_ + ": " + what); }

}  // namespace autograv::sim
