// autograv sim: release the end-effector with zero force and report where it goes - the
// uncompensated drift a user feels today - and measure the device's friction.
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/error.h"
#include "autograv/estimation/estimation_parameters.h"
#include "autograv/sim/friction_measurement.h"
#include "cli_support.h"
#include "commands.h"

namespace autograv::cli {

namespace {

struct SimOptions {
  std::string device;
  double seconds = 1.0;
  std::string report_path;
  // The simulated device's (--seed, --friction, --unit, --actuators), once parsed.
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  sim::SimulatedUnit unit;
};

void runSimCommand(SimOptions options, const SimulationKnobs& simulation) {
  options.seed = simulation.seed;
  options.friction = simulation.friction;
  options.unit = simulation.unit;
  if (!(std::isfinite(options.seconds) && options.seconds > 0.0 && options.seconds <= 3600.0)) {
    throw Error("--seconds must be in (0, 3600]");
  }
  auto device = openSimulatedDevice(options.device, options.seed, options.friction, options.unit);
  const Eigen::Vector3d start = device->workspaceCenter_m();
  device->resetState(start);
  const double radius_m = device->specifications().workspace_radius_m;
  const Eigen::Vector3d gravity_start = device->trueGravity(start);

  // A 1 kHz servo loop that reads the device as an application would and commands nothing.
  constexpr double kServo_s = 0.001;
  const auto ticks = static_cast<long long>(std::llround(options.seconds / kServo_s));
  double time_to_1mm_s = -1.0, time_to_end_stop_s = -1.0, max_drift_m = 0.0;
  Eigen::Vector3d measured = start, velocity = Eigen::Vector3d::Zero();
  for (long long tick = 0; tick < ticks; ++tick) {
    if (!device->getPosition(measured) || !device->getLinearVelocity(velocity) ||
        !device->setForce(Eigen::Vector3d::Zero())) {
      throw Error(options.device + ": the device stopped answering");
    }
    device->advance(kServo_s);
    const double drift_m = (device->truePosition_m() - start).norm();
    max_drift_m = std::max(max_drift_m, drift_m);
    if (time_to_1mm_s < 0.0 && drift_m >= 0.001) time_to_1mm_s = device->time_s();
    if (time_to_end_stop_s < 0.0 && device->endStopHit()) time_to_end_stop_s = device->time_s();
  }
  device->getPosition(measured);
  device->getLinearVelocity(velocity);
  const Eigen::Vector3d final_true = device->truePosition_m();
  const double drift_mm = (final_true - start).norm() * 1e3;
  const Eigen::Vector3d gravity_final = device->trueGravity(final_true);

  std::printf(
      "%s (seed %llu, friction %s): released at rest at the workspace centre "
      "[%.1f, %.1f, %.1f] mm with zero force for %.3g s\n",
      options.device.c_str(), static_cast<unsigned long long>(options.seed),
      sim::toString(options.friction), start.x() * 1e3, start.y() * 1e3, start.z() * 1e3,
      options.seconds);
  std::printf("  true |G| at the start   %.3f N (apparent mass %.1f g)\n", gravity_start.norm(),
              gravity_start.norm() / kStandardGravity * 1e3);
  std::printf("  final position (true)   [%.2f, %.2f, %.2f] mm\n", final_true.x() * 1e3,
              final_true.y() * 1e3, final_true.z() * 1e3);
  std::printf("  final position (driver) [%.2f, %.2f, %.2f] mm, speed %.1f mm/s\n",
              measured.x() * 1e3, measured.y() * 1e3, measured.z() * 1e3, velocity.norm() * 1e3);
  std::printf("  drift                   %.2f mm (max %.2f mm; workspace radius %.0f mm)\n",
              drift_mm, max_drift_m * 1e3, radius_m * 1e3);
  if (time_to_1mm_s >= 0.0) {
    std::printf("  drifted 1 mm after      %.1f ms\n", time_to_1mm_s * 1e3);
  }
  if (time_to_end_stop_s >= 0.0) {
    std::printf("  hit the end stop after  %.0f ms\n", time_to_end_stop_s * 1e3);
  } else {
    std::printf("  did not reach the end stop\n");
  }
  std::printf("  true |G| at the end     %.3f N\n", gravity_final.norm());

  // On a fresh device of the same seed, so that the drift run above is not disturbed.
  auto bench = openSimulatedDevice(options.device, options.seed, options.friction, options.unit);
  const sim::FrictionMeasurement friction = sim::measureFriction(*bench);
  std::printf(
      "  friction (%s): breakaway %.1f mN (largest over %zu directions, smallest %.1f mN), "
      "sliding %.1f mN\n",
      sim::toString(options.friction), friction.breakaway_force_n * 1e3, friction.directions.size(),
      friction.min_breakaway_force_n * 1e3, friction.coulomb_force_n * 1e3);
  nlohmann::json breakaway_by_direction = nlohmann::json::array();
  for (std::size_t i = 0; i < friction.directions.size(); ++i) {
    breakaway_by_direction.push_back(
        {{"direction", vectorJson(friction.directions[i])}, {"force_n", friction.breakaway_n[i]}});
  }

  const nlohmann::json report = {
      {"device", options.device},
      {"seed", options.seed},
      {"friction", sim::toString(options.friction)},
      {"breakaway_force_n", friction.breakaway_force_n},
      {"min_breakaway_force_n", friction.min_breakaway_force_n},
      {"coulomb_force_n", friction.coulomb_force_n},
      {"breakaway_by_direction", breakaway_by_direction},
      {"seconds", options.seconds},
      {"start_m", vectorJson(start)},
      {"final_position_m", vectorJson(final_true)},
      {"final_measured_position_m", vectorJson(measured)},
      {"final_speed_mm_per_s", velocity.norm() * 1e3},
      {"drift_mm", drift_mm},
      {"max_drift_mm", max_drift_m * 1e3},
      {"time_to_1mm_s", time_to_1mm_s >= 0.0 ? nlohmann::json(time_to_1mm_s) : nlohmann::json()},
      {"hit_end_stop", device->endStopHit()},
      {"time_to_end_stop_s",
       time_to_end_stop_s >= 0.0 ? nlohmann::json(time_to_end_stop_s) : nlohmann::json()},
      {"workspace_radius_mm", radius_m * 1e3},
      {"gravity_at_start_n", vectorJson(gravity_start)},
      {"gravity_norm_at_start_n", gravity_start.norm()},
      {"apparent_mass_at_start_g", gravity_start.norm() / kStandardGravity * 1e3},
      {"gravity_norm_at_final_n", gravity_final.norm()}};
  writeJsonReport(options.report_path, report);
}

void addSimCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<SimOptions>();
  CLI::App* command = app.add_subcommand(
      "sim",
      "Release a simulated end-effector at rest at the workspace centre with zero force and "
      "report where it drifts (what a user feels without gravity compensation)");
  command->group(kResearchCommands);
  addSimulatedDeviceOption(*command, options->device);
  command->add_option("--seconds", options->seconds, "Simulated time to run [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  addReportOption(*command, options->report_path);
  advanced->accept(*command, {knob::kSimulatedDevice});
  command->callback([options, advanced] { runSimCommand(*options, advanced->simulation()); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(80, addSimCommand);

}  // namespace autograv::cli
