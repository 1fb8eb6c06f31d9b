#include "autograv/device/device_specifications.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <string>

#include "autograv/error.h"

namespace autograv {

namespace {
// Datasheet continuous ratings by a word of the model name (lower case). SensAble Technologies,
// "PHANTOM Omni haptic device" datasheet: 3.3 N maximum, 0.88 N continuous (24 h); the Touch
// (formerly Omni) lists the same figures.
struct KnownRating {
  const char* name_word;
  double continuous_n;
};
constexpr KnownRating kKnownRatings[] = {{"omni", 0.88}, {"touch", 0.88}};

std::string lowerCase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}
}  // namespace

double continuousForceRating_n(const DeviceSpecifications& specifications) {
  const double peak_n = specifications.max_linear_force_n;
  if (specifications.max_continuous_force_n > 0.0) {
    return std::min(specifications.max_continuous_force_n, peak_n);
  }
  const std::string model = lowerCase(specifications.model_name);
  for (const KnownRating& known : kKnownRatings) {
    if (model.find(known.name_word) != std::string::npos)
      return std::min(known.continuous_n, peak_n);
  }
  return kDefaultContinuousForceFraction * peak_n;
}

void validateSpecifications(const DeviceSpecifications& specifications) {
  const struct {
    const char* field;
    double value;
    const char* unit;
  } checks[] = {
      {"max_linear_force_n", specifications.max_linear_force_n, "N"},
      {"max_linear_stiffness_n_per_m", specifications.max_linear_stiffness_n_per_m, "N/m"},
      {"max_linear_damping_n_s_per_m", specifications.max_linear_damping_n_s_per_m, "N s/m"},
      {"workspace_radius_m", specifications.workspace_radius_m, "m"},
  };
  if (specifications.model_name.empty()) {
    throw Error("device specifications: model_name is empty; the driver must name its model");
  }
  for (const auto& check : checks) {
    if (!(std::isfinite(check.value) && check.value > 0.0)) {
      std::ostringstream message;
      message << "device specifications of '" << specifications.model_name << "': " << check.field
              << " must be a positive number in " << check.unit << ", got " << check.value;
      throw Error(message.str());
    }
  }
  const double continuous_n = specifications.max_continuous_force_n;
  if (!(std::isfinite(continuous_n) && continuous_n >= 0.0 &&
        continuous_n <= specifications.max_linear_force_n)) {
    std::ostringstream message;
    message << "device specifications of '" << specifications.model_name
            << "': max_continuous_force_n must be 0 (unknown) or a force in N up to "
               "max_linear_force_n ("
            << specifications.max_linear_force_n << " N), got " << continuous_n;
    throw Error(message.str());
  }
}

}  // namespace autograv
