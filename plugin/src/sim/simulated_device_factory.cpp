#include <memory>
#include <string>
#include <vector>

#include "autograv/error.h"
#include "autograv/sim/delta_device.h"
#include "autograv/sim/point_mass_device.h"
#include "autograv/sim/serial_arm_device.h"
#include "autograv/sim/simulated_device.h"

namespace autograv::sim {

std::vector<std::string> simulatedDeviceNames() { return {"sim:omega", "sim:omni", "sim:falcon"}; }

std::unique_ptr<SimulatedDevice> makeSimulatedDevice(const std::string& name, std::uint64_t seed,
                                                     FrictionLevel friction) {
  if (name == "sim:omega")
    return std::make_unique<PointMassDevice>(omegaParameters(friction), seed);
  if (name == "sim:omni") return std::make_unique<SerialArmDevice>(omniParameters(friction), seed);
  if (name == "sim:falcon") return std::make_unique<DeltaDevice>(falconParameters(friction), seed);
  std::string valid;
  for (const auto& known : simulatedDeviceNames()) valid += (valid.empty() ? "" : ", ") + known;
  throw Error("unknown simulated device '" + name + "'; valid names: " + valid);
}

}  // namespace autograv::sim
