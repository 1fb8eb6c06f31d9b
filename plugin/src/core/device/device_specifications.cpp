#include "autograv/device/device_specifications.h"

#include <cmath>
#include <sstream>

#include "autograv/error.h"

namespace autograv {

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
}

}  // namespace autograv
