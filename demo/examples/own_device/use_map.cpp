// Using the map own_device saved, as an application does: load it, wrap the driver in
// GravityCompensatedDevice, and send forces as before; the map's G_hat(X) is added to each. The
// program then says how well the map cancels the point mass's own (known) gravity.
//   use_map [MAP_PATH]
#include <algorithm>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <autograv/compensation/gravity_compensated_device.h>
#include <autograv/device/servo_clock.h>
#include <autograv/error.h>
#include <autograv/map/map_io.h>

#include "point_mass_device.h"

namespace {

constexpr double kServoPeriod_s = 1e-3;

/// Residual of the map against the device's gravity on a 9 x 9 x 9 lattice over the cube of
/// +-40 mm about the centre, well inside the 80 mm workspace: sorted. Unit: [N]
std::vector<double> residuals_n(const autograv::GravityMap& map) {
  std::vector<double> residuals;
  constexpr int n = 9;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      for (int k = 0; k < n; ++k) {
        const Eigen::Vector3d p =
            0.04 * (Eigen::Vector3d(i, j, k) * 2.0 / (n - 1) - Eigen::Vector3d::Ones());
        residuals.push_back(
            (map.gravityAt(p) + example::PointMassDevice::gravityForce_n(p)).norm());
      }
    }
  }
  std::sort(residuals.begin(), residuals.end());
  return residuals;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string map_path = argc > 1 ? argv[1] : "own_device_map.json";
  const auto device = std::make_shared<example::PointMassDevice>(kServoPeriod_s);
  try {
    // A map is tied to its device's model: loadMap refuses another's.
    autograv::MapLoadOptions load;
    load.expected_device_model = device->specifications().model_name;
    const auto map =
        std::make_shared<const autograv::GravityMap>(autograv::loadMap(map_path, load));

    // This loop runs in simulated time (each setForce advances the point mass by 1 ms, much
    // faster than the wall clock): it gives the decorator a clock that says so. A real-time loop
    // keeps the default.
    autograv::CompensationOptions compensation;
    compensation.clock = std::make_shared<autograv::FixedPeriodServoClock>(kServoPeriod_s);
    autograv::GravityCompensatedDevice compensated(device, compensation);
    if (!compensated.open()) return 1;
    compensated.publishMap(map);

    // Release tests: the hand lets go at a point; the application sends no force of its own.
    const std::vector<Eigen::Vector3d> points = {
        {0.0, 0.0, 0.0}, {0.015, -0.01, 0.01}, {-0.015, 0.015, -0.015}, {0.01, 0.015, 0.015}};
    std::printf("release tests (0.5 s, application force zero):\n");
    double worst_drift_m = 0.0;
    for (const Eigen::Vector3d& point : points) {
      double drift_m[2] = {0.0, 0.0};
      for (const bool enabled : {true, false}) {
        compensated.setCompensationEnabled(enabled);
        for (int t = 0; t < 600; ++t) {  // held there while the compensation fades in (or out)
          device->placeAt(point);
          compensated.setForce(Eigen::Vector3d::Zero());
        }
        for (int t = 0; t < 500; ++t) compensated.setForce(Eigen::Vector3d::Zero());
        Eigen::Vector3d end_m;
        compensated.getPosition(end_m);
        drift_m[enabled ? 0 : 1] = (end_m - point).norm();
      }
      worst_drift_m = std::max(worst_drift_m, drift_m[0]);
      std::printf(
          "  at (%+5.1f, %+5.1f, %+5.1f) mm: drift %5.2f mm compensated, %5.1f mm without\n",
          point.x() * 1e3, point.y() * 1e3, point.z() * 1e3, drift_m[0] * 1e3, drift_m[1] * 1e3);
    }
    compensated.close();

    const std::vector<double> residuals = residuals_n(*map);
    const double median_n = residuals[residuals.size() / 2], max_n = residuals.back();
    std::printf(
        "residual of the map against the device's gravity (|G| about %.2f N) at %zu points of "
        "the workspace: median %.1f mN, max %.1f mN\n",
        example::PointMassDevice::gravityForce_n(Eigen::Vector3d::Zero()).norm(), residuals.size(),
        median_n * 1e3, max_n * 1e3);
    std::printf("worst drift compensated: %.2f mm; faults %llu; fade stalled: %s\n",
                worst_drift_m * 1e3, static_cast<unsigned long long>(compensated.faultCount()),
                compensated.fadeStalled() ? "yes" : "no");
    // What a user would feel: far below the 30 mN of friction, the end-effector stays put.
    return max_n < 0.03 && worst_drift_m < 1e-3 && !compensated.fadeStalled() ? 0 : 1;
  } catch (const autograv::Error& error) {
    std::fprintf(stderr, "use_map: %s\n", error.what());
    return 1;
  }
}
