// autograv verify: how much force does a map miss, measured as a device could, and does it hold
// a released end-effector still? On a simulated device, also the ground-truth error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "autograv/device/gravity_compensated_device.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/verification.h"
#include "cli_support.h"
#include "commands.h"
#include "friction_option.h"
#include "servo_timing_option.h"

namespace autograv::cli {

namespace {

struct VerifyOptions {
  std::string map_path;
  std::string device = "sim:omni";
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  int points = 100;
  double duration_s = 1.0;
  double max_drift_ratio = 0.1;
  double max_residual_ratio = 0.05;
  double stuck_threshold_mm = 0.15;
  std::string report_path;
  bool allow_model_mismatch = false;
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;
};

nlohmann::json vectorJson(const Eigen::Vector3d& value) {
  return {value.x(), value.y(), value.z()};
}

void runVerifyCommand(const VerifyOptions& options) {
  const DeviceHandle handle = openDevice(options.device, options.seed, options.friction);
  if (!handle.simulation) {
    throw Error(
        "verify places the end-effector at its test points by simulation, so it needs a "
        "simulated device; on " +
        options.device + " run `autograv check`, which measures the map against the device itself");
  }
  const std::shared_ptr<sim::SimulatedDevice>& simulated = handle.simulation;
  const DeviceSpecifications& specs = simulated->specifications();
  MapLoadOptions load;
  load.expected_device_model = specs.model_name;
  load.allow_model_mismatch = options.allow_model_mismatch;
  auto map = std::make_shared<const GravityMap>(loadMap(options.map_path, load));

  sim::VerificationOptions verification;
  verification.points = options.points;
  verification.seed = options.seed;
  verification.release_s = options.duration_s;
  verification.stuck_threshold_m = options.stuck_threshold_mm * 1e-3;
  verification.servo_timing = options.servo_timing;
  verification.servo_timing_seed = options.seed;
  const sim::ResidualProbeOptions& probe = verification.probe;
  std::printf("verify %s on %s (friction %s): %d points inside the grid, seed %llu\n",
              options.map_path.c_str(), specs.model_name.c_str(), sim::toString(options.friction),
              options.points, static_cast<unsigned long long>(options.seed));
  std::printf(
      "each point: carried there by hand and held until compensation is fully in; residual force\n"
      "probed by a %.0f N/m hold approached %d times from each side along each axis (friction\n"
      "cancels in the mean); then released for %.2f s, and again with compensation off\n",
      probe.stiffness_n_per_m, probe.approaches_per_side, options.duration_s);
  std::fflush(stdout);

  ProgressBar progress("verify");
  verification.on_progress = [&](int done, int total, bool compensated) {
    progress.update(done, total, compensated ? "compensation on" : "compensation off");
  };
  const sim::VerificationReport report =
      sim::verifyMapOnSimulatedDevice(simulated, map, verification, options.allow_model_mismatch);
  progress.finish();

  constexpr double kMinProbedFraction = 0.9;
  const sim::Percentiles& residual = report.residual_force_n;
  const sim::Percentiles& on = report.drift_m;
  const sim::Percentiles& off = report.drift_uncompensated_m;
  const double ratio = off.median > 0.0 ? on.median / off.median : INFINITY;
  const double residual_ratio =
      report.median_gravity_n > 0.0 ? residual.median / report.median_gravity_n : INFINITY;
  const bool all_ready = report.ready_points == options.points;
  const bool all_probed = report.valid_residuals == report.ready_points;
  // A probe friction held still measured nothing, which is no fault of the map: the median of the
  // others decides, as long as most points were measured.
  const bool most_probed = report.valid_residuals >= kMinProbedFraction * report.ready_points;
  const bool force_ok = report.max_force_sent_n <= specs.max_linear_force_n * (1.0 + 1e-12);
  const bool drift_ok = ratio <= options.max_drift_ratio;
  const bool residual_ok = most_probed && residual_ratio <= options.max_residual_ratio;
  const bool pass = all_ready && force_ok && drift_ok && residual_ok;

  std::printf("\n%-34s %10s %10s %10s\n", "", "median", "90th pct", "max");
  std::printf("%-34s %10.2f %10.2f %10.2f\n", "residual force [mN]", residual.median * 1e3,
              residual.p90 * 1e3, residual.max * 1e3);
  std::printf("%-34s %10.3f %10.3f %10.3f\n", "drift, compensation on [mm]", on.median * 1e3,
              on.p90 * 1e3, on.max * 1e3);
  std::printf("%-34s %10.3f %10.3f %10.3f\n", "drift, compensation off [mm]", off.median * 1e3,
              off.p90 * 1e3, off.max * 1e3);
  std::vector<double> friction_n;
  for (const auto& point : report.points) {
    if (point.residual.valid) friction_n.push_back(point.residual.holding_friction_n);
  }
  std::printf("%-34s %10.2f\n", "friction the probe saw [mN]",
              sim::percentiles(friction_n).median * 1e3);
  std::printf("%-34s %10.2f   (no motion beyond %.2f mm after release)\n", "stuck fraction",
              report.stuck_fraction, options.stuck_threshold_mm);
  std::printf("\nSimulation only (ground truth, which no real device can measure):\n");
  std::printf("%-34s %10.2f %10.2f %10.2f\n", "|G_hat - G| [mN]", report.truth_error_n.median * 1e3,
              report.truth_error_n.p90 * 1e3, report.truth_error_n.max * 1e3);
  std::printf("%-34s %10.2f %10.2f %10.2f\n", "|G_hat - G| [% of |G|]",
              report.truth_error_rel.median * 100.0, report.truth_error_rel.p90 * 100.0,
              report.truth_error_rel.max * 100.0);

  std::printf("\n%-34s %d of %d%s\n", "points held at full compensation", report.ready_points,
              options.points, all_ready ? "" : "  SOME NEVER READY");
  std::printf("%-34s %d of %d%s\n", "residual probes that slid", report.valid_residuals,
              report.ready_points,
              all_probed    ? ""
              : most_probed ? "  (friction held the rest; not counted)"
                            : "  FRICTION HELD TOO MANY");
  std::printf("%-34s %.4f of median |G_hat| %.3f N (limit %.3g)  %s\n", "residual median",
              residual_ratio, report.median_gravity_n, options.max_residual_ratio,
              residual_ok ? "ok" : "TOO HIGH");
  std::printf("%-34s %.2f N, max sent %.3f N  %s\n", "device force limit", specs.max_linear_force_n,
              report.max_force_sent_n, force_ok ? "ok, never exceeded" : "EXCEEDED");
  std::printf("%-34s %.4f (limit %.3g)  %s\n", "drift median on / off", ratio,
              options.max_drift_ratio, drift_ok ? "ok" : "TOO HIGH");
  printServoLoop(options.servo_timing, report.servo_loop);
  std::string fault_kinds;
  std::uint64_t faults = 0;
  nlohmann::json fault_counts = nlohmann::json::object();
  for (int kind = 1; kind < kServoFaultKinds; ++kind) {
    const auto fault = static_cast<ServoFault>(kind);
    const std::uint64_t count = report.fault_counts[static_cast<std::size_t>(kind)];
    fault_counts[toString(fault)] = count;
    faults += count;
    if (count == 0) continue;
    fault_kinds += std::string(fault_kinds.empty() ? " (" : ", ") + toString(fault) + " " +
                   std::to_string(count);
  }
  if (!fault_kinds.empty()) fault_kinds += ")";
  std::printf("%-34s %llu fault ticks%s, %llu clamps\n", "decorator",
              static_cast<unsigned long long>(faults), fault_kinds.c_str(),
              static_cast<unsigned long long>(report.clamp_count));
  std::printf("%-34s %.0f s\n", "simulated time", report.simulated_seconds);

  nlohmann::json point_list = nlohmann::json::array();
  for (const sim::PointVerification& point : report.points) {
    point_list.push_back({{"start_m", vectorJson(point.point_m)},
                          {"ready", point.ready},
                          {"residual_valid", point.residual.valid},
                          {"residual_force_n", vectorJson(point.residual.residual_force_n)},
                          {"residual_force_norm_n", point.residual.residual_force_n.norm()},
                          {"holding_friction_n", point.residual.holding_friction_n},
                          {"probe_stiffness_n_per_m", point.residual.stiffness_n_per_m},
                          {"drift_mm", point.release.drift_m * 1e3},
                          {"stuck", point.release.stuck},
                          {"drift_off_mm", point.release_uncompensated.drift_m * 1e3},
                          {"map_gravity_n", vectorJson(point.map_gravity_n)},
                          {"simulation_only_true_gravity_n", vectorJson(point.true_gravity_n)},
                          {"simulation_only_truth_error_n", point.truth_error_n}});
  }
  const nlohmann::json json = {{"map", options.map_path},
                               {"device", specs.model_name},
                               {"map_device", map->metadata().device_model},
                               {"seed", options.seed},
                               {"friction", sim::toString(options.friction)},
                               {"points", options.points},
                               {"ready_points", report.ready_points},
                               {"duration_s", options.duration_s},
                               {"servo_period_s", report.servo_period_s},
                               {"ramp_duration_s", verification.compensation.ramp_duration_s},
                               {"probe_stiffness_n_per_m", probe.stiffness_n_per_m},
                               {"probe_approach_distance_m", probe.approach_distance_m},
                               {"probe_approaches_per_side", probe.approaches_per_side},
                               {"residual_force_median_n", residual.median},
                               {"residual_force_p90_n", residual.p90},
                               {"residual_force_max_n", residual.max},
                               {"residual_probes_valid", report.valid_residuals},
                               {"residual_ratio", residual_ratio},
                               {"max_residual_ratio", options.max_residual_ratio},
                               {"holding_friction_median_n", sim::percentiles(friction_n).median},
                               {"stuck_fraction", report.stuck_fraction},
                               {"stuck_threshold_mm", options.stuck_threshold_mm},
                               {"drift_median_mm", on.median * 1e3},
                               {"drift_p90_mm", on.p90 * 1e3},
                               {"drift_max_mm", on.max * 1e3},
                               {"drift_off_median_mm", off.median * 1e3},
                               {"drift_off_p90_mm", off.p90 * 1e3},
                               {"drift_off_max_mm", off.max * 1e3},
                               {"drift_ratio", ratio},
                               {"max_drift_ratio", options.max_drift_ratio},
                               {"truth_error_median_n", report.truth_error_n.median},
                               {"truth_error_max_n", report.truth_error_n.max},
                               {"truth_error_median_rel", report.truth_error_rel.median},
                               {"truth_error_max_rel", report.truth_error_rel.max},
                               {"truth_is_simulation_only", true},
                               {"max_force_sent_n", report.max_force_sent_n},
                               {"max_linear_force_n", specs.max_linear_force_n},
                               {"clamp_count", report.clamp_count},
                               {"fault_count", faults},
                               {"faults", fault_counts},
                               {"simulated_seconds", report.simulated_seconds},
                               {"force_within_limit", force_ok},
                               {"drift_ratio_ok", drift_ok},
                               {"residual_ok", residual_ok},
                               {"pass", pass},
                               {"releases", point_list}};
  nlohmann::json full_report = json;
  full_report["servo_timing"] = sim::toString(options.servo_timing);
  full_report["servo_loop"] = servoLoopJson(options.servo_timing, report.servo_loop);
  writeJsonReport(options.report_path, full_report);
  if (!pass) {
    std::printf("\nFAIL\n");
    throw CLI::RuntimeError(1);
  }
  std::printf("\nPASS\n");
}

void addVerifyCommand(CLI::App& app) {
  auto options = std::make_shared<VerifyOptions>();
  CLI::App* command = app.add_subcommand(
      "verify",
      "Measure the force a map misses at seeded points (a PD hold approached from both sides), "
      "then release the end-effector with compensation on and off and report the drift");
  command->add_option("map", options->map_path, "Map file (JSON)")->required();
  addDeviceOption(*command, options->device);
  command->add_option("--seed", options->seed, "Seed of the points and the device noise")
      ->capture_default_str();
  addFrictionOption(*command, options->friction);
  addServoTimingOption(*command, options->servo_timing);
  command->add_option("--points", options->points, "Release points")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command->add_option("--duration-s", options->duration_s, "Time after each release [s]")
      ->check(CLI::Range(0.001, 60.0))
      ->capture_default_str();
  command
      ->add_option("--max-drift-ratio", options->max_drift_ratio,
                   "Fail when drift median on / off exceeds this")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--max-residual-ratio", options->max_residual_ratio,
                   "Fail when the median residual force exceeds this fraction of median |G_hat|")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      ->add_option("--stuck-threshold-mm", options->stuck_threshold_mm,
                   "A release that moved less than this counts as stuck (a few encoder counts)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--report", options->report_path, "Write a JSON report here");
  command->add_flag("--allow-model-mismatch", options->allow_model_mismatch,
                    "Use a map made for another device model");
  command->callback([options] { runVerifyCommand(*options); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(50, addVerifyCommand);

}  // namespace autograv::cli
