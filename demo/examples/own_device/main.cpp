// Calibrating a haptic device of your own with autograv: the whole program. Your driver is any
// autograv::HapticDevice; here it is the example's simulated point mass (point_mass_device.h),
// and a simulated hand plays the user's part (simulated_user.h). Then run use_map.
//   own_device [MAP_PATH]
#include <cstdio>
#include <memory>

#include <autograv/error.h>
#include <autograv/wizard/calibrate.h>

#include "point_mass_device.h"
#include "simulated_user.h"

int main(int argc, char** argv) {
  auto device = std::make_shared<example::PointMassDevice>();  // your driver
  example::SimulatedUser user(*device);                        // your hand, on a real device

  autograv::WizardConfig config;  // the defaults: the grid is fitted to the explored workspace
  config.map_path = argc > 1 ? argv[1] : "own_device_map.json";
  config.grid_resolution = Eigen::Vector3i::Constant(4);  // 4 x 4 x 4 vertices: quick

  autograv::CalibrateOptions options;
  options.speed = 50.0;  // the point mass runs in simulated time: 50 times faster than real time
  options.on_progress = [](const autograv::WizardStatus& status) {
    std::printf("%s\n", autograv::progressLine(status).c_str());
  };
  options.on_status = [&](const autograv::WizardStatus& status, autograv::CalibrationWizard&) {
    user.act(status);  // a person's hand and stylus button, on a real device
  };
  try {
    const autograv::CalibrateResult result = autograv::calibrate(device, config, options);
    std::printf("%s %s: %d of %d vertices converged, largest force %.2f N\n",
                result.ok() ? "saved" : "did not save", config.map_path.c_str(),
                result.status.converged, result.status.vertex_count, result.status.force.peak_n);
    return result.ok() ? 0 : 1;             // if not, the last progress line said why
  } catch (const autograv::Error& error) {  // a setting it cannot use, before anything moves
    std::fprintf(stderr, "own_device: %s\n", error.what());
    return 1;
  }
}
