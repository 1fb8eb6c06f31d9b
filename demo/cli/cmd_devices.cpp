// autograv devices: every device this build can open, by the name the other commands take.
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/devices/device_registry.h"
#include "cli_support.h"
#include "commands.h"

namespace autograv::cli {

namespace {

void runDevicesCommand(const std::string& report_path) {
  const std::vector<DeviceListing> devices = listDevices();
  std::printf("%-10s %-16s %-16s %8s %10s %10s %10s  %s\n", "name", "model", "serial", "force N",
              "stiff N/m", "damp Ns/m", "radius mm", "manufacturer");
  nlohmann::json report = nlohmann::json::array();
  for (const DeviceListing& device : devices) {
    const DeviceSpecifications& s = device.specifications;
    std::printf("%-10s %-16s %-16s %8.2f %10.0f %10.1f %10.1f  %s\n", device.name.c_str(),
                s.model_name.c_str(), s.serial_number.empty() ? "-" : s.serial_number.c_str(),
                s.max_linear_force_n, s.max_linear_stiffness_n_per_m,
                s.max_linear_damping_n_s_per_m, s.workspace_radius_m * 1e3, s.manufacturer.c_str());
    report.push_back({{"name", device.name},
                      {"model", s.model_name},
                      {"manufacturer", s.manufacturer},
                      {"serial", s.serial_number},
                      {"max_linear_force_n", s.max_linear_force_n},
                      {"max_linear_stiffness_n_per_m", s.max_linear_stiffness_n_per_m},
                      {"max_linear_damping_n_s_per_m", s.max_linear_damping_n_s_per_m},
                      {"workspace_radius_m", s.workspace_radius_m}});
  }
  if (!chai3dDevicesAvailable()) {
    std::printf("(built without CHAI3D: chai3d:N devices need -DAUTOGRAV_CHAI3D_DIR)\n");
  }
  writeJsonReport(report_path, {{"devices", report}, {"chai3d", chai3dDevicesAvailable()}});
}

void addDevicesCommand(CLI::App& app, const Advanced& /*advanced*/) {
  auto report_path = std::make_shared<std::string>();
  CLI::App* command = app.add_subcommand(
      "devices", "List the devices this build can open (simulated, and CHAI3D's connected ones)");
  command->add_option("--report", *report_path, "Write the list as JSON here");
  command->callback([report_path] { runDevicesCommand(*report_path); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(15, addDevicesCommand);

}  // namespace autograv::cli
