// autograv verify: how much force does a map miss, measured as a device could, and does it hold
// a released end-effector still? The device carries itself to each point with no hand on it, so
// this runs on hardware as on a simulation; on a simulation, also the ground-truth error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "autograv/compensation/gravity_compensated_device.h"
#include "autograv/device/device_specifications.h"
#include "autograv/device/servo_clock.h"
#include "autograv/device/wall_clock_tick_source.h"
#include "autograv/error.h"
#include "autograv/maintenance/map_verification.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/verification.h"
#include "cli_support.h"
#include "commands.h"
#include "servo_timing_option.h"

namespace autograv::cli {

namespace {

// Why these limits (README, "verify"). The residual is judged against |G_hat| at each point and
// against the friction the probe saw there:
// - median 2 %, 90th percentile 3 %: the field error a good map leaves (at most 1.5 % at the 90th
//   percentile over the workspace) plus what the probe itself reads at a point on a perfect map
//   (up to 3 mN: encoder counts and cogging), a few tenths of a percent of an Omni's |G|;
// - maximum 6 % of |G|, and at most the friction the probe saw (its median over the points): a
//   residual below the friction that holds a released stylus cannot move it, and 6 % is the
//   field's 5 % ceiling with the probe's own reading error on top.
constexpr double kDefaultMedianRatio = 0.02;
constexpr double kDefaultP90Ratio = 0.03;
constexpr double kDefaultMaxRatio = 0.06;
constexpr double kDefaultMaxFrictionRatio = 1.0;
// Calibration may spend 5 % of its time above the continuous rating; verify is held to the same.
constexpr double kMaxFractionAboveContinuous = 0.05;
// A probe friction held still measured nothing, which is no fault of the map: the others
// decide, as long as most points were measured.
constexpr double kMinProbedFraction = 0.9;
// A map without an explored workspace samples its grid's box, which pokes out of what the device
// reaches: the points it cannot reach are skipped, as long as half of them can be reached.
constexpr double kMinReachedFractionOfBox = 0.5;
// Where a drifting release is caught. Unit: [m]
constexpr double kCatchDrift_m = 0.003;

struct VerifyOptions {
  std::string map_path;
  std::string device;
  // The simulated device's and loop's (--seed, --friction, --unit, --actuators, --servo-timing),
  // once parsed; --seed also draws the points.
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  sim::SimulatedUnit unit;
  int points = 100;
  double duration_s = 1.0;
  double max_drift_ratio = 0.1;
  double max_residual_ratio = kDefaultMedianRatio;
  double max_residual_p90_ratio = kDefaultP90Ratio;
  double max_residual_max_ratio = kDefaultMaxRatio;
  double max_residual_friction_ratio = kDefaultMaxFrictionRatio;
  double stuck_threshold_mm = 0.15;
  bool compare_uncompensated = true;
  std::string report_path;
  bool allow_model_mismatch = false;
  sim::ServoTiming servo_timing = sim::ServoTiming::kExact;
};

// <prefix>_median<suffix>, _p90 and _max of `values`, each times `scale`.
void addPercentilesJson(nlohmann::json& json, const std::string& prefix, const Percentiles& values,
                        const std::string& suffix, double scale = 1.0) {
  json[prefix + "_median" + suffix] = values.median * scale;
  json[prefix + "_p90" + suffix] = values.p90 * scale;
  json[prefix + "_max" + suffix] = values.max * scale;
}

void runVerifyCommand(VerifyOptions options, const SimulationKnobs& simulated) {
  options.seed = simulated.seed;
  options.friction = simulated.friction;
  options.unit = simulated.unit;
  options.servo_timing = simulated.servo_timing;
  const DeviceHandle handle =
      openDevice(options.device, options.seed, options.friction, options.unit);
  const std::shared_ptr<sim::SimulatedDevice>& simulation = handle.simulation;
  const DeviceSpecifications& specs = handle.device->specifications();
  MapLoadOptions load;
  load.expected_device_model = specs.model_name;
  load.allow_model_mismatch = options.allow_model_mismatch;
  auto map = std::make_shared<const GravityMap>(loadMap(options.map_path, load));
  const double period_s = map->metadata().parameters.servo_period_s;

  VerificationOptions verification;
  verification.points = options.points;
  verification.seed = options.seed;
  verification.release.duration_s = options.duration_s;
  verification.release.stuck_threshold_m = options.stuck_threshold_mm * 1e-3;
  verification.release.catch_drift_m = kCatchDrift_m;
  verification.compare_uncompensated = options.compare_uncompensated;

  // A simulation's physics advances with its ticks, and the decorator reads that loop's clock;
  // hardware runs on the wall clock.
  std::unique_ptr<sim::SimulatedTickSource> simulated_ticks;
  std::unique_ptr<TickSource> wall_ticks;
  if (simulation) {
    simulated_ticks = std::make_unique<sim::SimulatedTickSource>(
        *simulation, period_s, sim::SimulatedTickSource::Mode::kAsFastAsPossible,
        options.servo_timing, options.seed);
    if (options.servo_timing == sim::ServoTiming::kExact) {
      verification.compensation.clock = std::make_shared<FixedPeriodServoClock>(period_s);
    } else {
      verification.compensation.clock =
          std::make_shared<sim::ServoTimingClock>(simulated_ticks->timingModel());
    }
  } else {
    wall_ticks = std::make_unique<WallClockTickSource>(period_s);
  }
  // Hardware: this thread runs the servo loop, at real-time priority where the system permits.
  const std::optional<RealTimePriority> servo_priority = enterServoPriority(handle);
  TickSource& ticks = simulated_ticks ? static_cast<TickSource&>(*simulated_ticks) : *wall_ticks;

  const bool from_workspace = !map->metadata().workspace.empty();
  const ResidualProbeOptions& probe = verification.probe;
  std::printf("verify %s on %s (%s): %d points drawn from %s, seed %llu\n",
              options.map_path.c_str(), specs.model_name.c_str(),
              simulation
                  ? (std::string("simulated, friction ") + sim::toString(options.friction)).c_str()
                  : "hardware",
              options.points,
              from_workspace ? "the map's explored workspace" : "the map's grid box (no workspace)",
              static_cast<unsigned long long>(options.seed));
  // What is judged is the map as it reads the field: its own model between the measurements.
  std::printf("field model: %s\n", describeFieldModel(*map).c_str());
  std::printf(
      "each point: the device carries itself there (no hand) and holds it until compensation is\n"
      "fully in; residual force probed by a %.0f N/m hold approached %d times from each side\n"
      "along each axis (friction cancels in the mean); then released for %.2f s (caught beyond\n"
      "%.0f mm)%s\n",
      probe.stiffness_n_per_m, probe.approaches_per_side, options.duration_s, kCatchDrift_m * 1e3,
      options.compare_uncompensated ? ", and again with compensation off" : "");
  std::fflush(stdout);

  ProgressBar progress("verify");
  verification.on_progress = [&](int done, int total) { progress.update(done, total, "points"); };
  sim::VerificationTruth truth;
  if (simulation) truth = sim::truthOf(*simulation);
  const VerificationReport report =
      verifyMap(handle.device, ticks, map, verification, options.allow_model_mismatch,
                simulation ? &truth : nullptr);
  progress.finish();

  const Percentiles& residual = report.residual_force_n;
  const Percentiles& residual_rel = report.residual_force_rel;
  const Percentiles& on = report.drift_m;
  const Percentiles& off = report.drift_uncompensated_m;
  const double friction_n = report.holding_friction_n.median;
  const double ratio = !options.compare_uncompensated ? 0.0
                       : off.median > 0.0             ? on.median / off.median
                                                      : INFINITY;
  const int needed_ready =
      from_workspace ? options.points
                     : static_cast<int>(std::ceil(kMinReachedFractionOfBox * options.points));
  const bool ready_ok = report.ready_points >= needed_ready;
  const bool all_probed = report.valid_residuals == report.ready_points;
  const bool most_probed = report.valid_residuals >= kMinProbedFraction * report.ready_points;
  const bool median_ok = residual_rel.median <= options.max_residual_ratio;
  const bool p90_ok = residual_rel.p90 <= options.max_residual_p90_ratio;
  const bool max_ok = residual_rel.max <= options.max_residual_max_ratio;
  const bool friction_ok = residual.max <= options.max_residual_friction_ratio * friction_n;
  const bool residual_ok =
      most_probed && report.valid_residuals > 0 && median_ok && p90_ok && max_ok && friction_ok;
  const bool force_ok =
      report.force_limit_ticks == 0 && report.max_force_sent_n < specs.max_linear_force_n &&
      report.clamp_count == 0 &&
      report.seconds_above_continuous_force <= kMaxFractionAboveContinuous * report.seconds;
  const bool drift_ok = ratio <= options.max_drift_ratio && report.caught_releases == 0;
  const bool pass = ready_ok && force_ok && drift_ok && residual_ok;

  std::printf("\n%-34s %10s %10s %10s\n", "", "median", "90th pct", "max");
  std::printf("%-34s %10.2f %10.2f %10.2f\n", "residual force [mN]", residual.median * 1e3,
              residual.p90 * 1e3, residual.max * 1e3);
  std::printf("%-34s %10.2f %10.2f %10.2f\n", "residual force [% of |G_hat|]",
              residual_rel.median * 100.0, residual_rel.p90 * 100.0, residual_rel.max * 100.0);
  std::printf("%-34s %10.2f %10.2f %10.2f\n", "friction the probe saw [mN]", friction_n * 1e3,
              report.holding_friction_n.p90 * 1e3, report.holding_friction_n.max * 1e3);
  std::printf("%-34s %10.3f %10.3f %10.3f\n", "drift, compensation on [mm]", on.median * 1e3,
              on.p90 * 1e3, on.max * 1e3);
  if (options.compare_uncompensated) {
    std::printf("%-34s %10.3f %10.3f %10.3f   (caught at %.0f mm)\n",
                "drift, compensation off [mm]", off.median * 1e3, off.p90 * 1e3, off.max * 1e3,
                kCatchDrift_m * 1e3);
  }
  std::printf("%-34s %10.2f   (no motion beyond %.2f mm after release)\n", "stuck fraction",
              report.stuck_fraction, options.stuck_threshold_mm);
  if (report.has_truth) {
    std::printf("\nSimulation only (ground truth, which no real device can measure):\n");
    std::printf("%-34s %10.2f %10.2f %10.2f\n", "|G_hat - G| [mN]",
                report.truth_error_n.median * 1e3, report.truth_error_n.p90 * 1e3,
                report.truth_error_n.max * 1e3);
    std::printf("%-34s %10.2f %10.2f %10.2f\n", "|G_hat - G| [% of |G|]",
                report.truth_error_rel.median * 100.0, report.truth_error_rel.p90 * 100.0,
                report.truth_error_rel.max * 100.0);
    std::printf("%-34s %d of %d\n", "points the simulator cannot reach", report.unreachable_points,
                options.points);
  }

  std::printf("\n%-34s %d of %d reached, %d held at full compensation%s\n", "points",
              report.reached_points, options.points, report.ready_points,
              ready_ok ? "" : "  TOO FEW");
  std::printf("%-34s %d of %d%s\n", "residual probes that slid", report.valid_residuals,
              report.ready_points,
              all_probed    ? ""
              : most_probed ? "  (friction held the rest; not counted)"
                            : "  FRICTION HELD TOO MANY");
  std::printf("%-34s median %.2f %% (limit %.3g), p90 %.2f %% (%.3g), max %.2f %% (%.3g)  %s\n",
              "residual / |G_hat|", residual_rel.median * 100.0, options.max_residual_ratio * 100.0,
              residual_rel.p90 * 100.0, options.max_residual_p90_ratio * 100.0,
              residual_rel.max * 100.0, options.max_residual_max_ratio * 100.0,
              median_ok && p90_ok && max_ok ? "ok" : "TOO HIGH");
  std::printf("%-34s max %.2f mN, friction %.2f mN (limit %.3g of it)  %s\n", "residual / friction",
              residual.max * 1e3, friction_n * 1e3, options.max_residual_friction_ratio,
              friction_ok ? "ok" : "TOO HIGH");
  std::printf(
      "%-34s max sent %.3f N of %.2f N (continuous %.2f N), %.2f s above continuous "
      "(longest %.2f s), %llu ticks at the limit  %s\n",
      "device force", report.max_force_sent_n, specs.max_linear_force_n,
      report.continuous_force_rating_n, report.seconds_above_continuous_force,
      report.longest_above_continuous_force_s,
      static_cast<unsigned long long>(report.force_limit_ticks), force_ok ? "ok" : "TOO HIGH");
  std::printf("%-34s %.4f (limit %.3g), %d compensated releases caught  %s\n",
              "drift median on / off", ratio, options.max_drift_ratio, report.caught_releases,
              drift_ok ? "ok" : "TOO HIGH");
  if (simulated_ticks) printServoLoop(options.servo_timing, simulated_ticks->loopSummary());
  if (servo_priority) std::printf("%-34s %s\n", "servo thread", describe(*servo_priority).c_str());
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
  std::printf("%-34s %.0f s\n", simulation ? "device time (simulated)" : "device time",
              report.seconds);

  nlohmann::json point_list = nlohmann::json::array();
  for (const PointVerification& point : report.points) {
    nlohmann::json entry = {{"point_m", vectorJson(point.point_m)},
                            {"reached", point.reached},
                            {"ready", point.ready},
                            {"residual_valid", point.residual.valid},
                            {"residual_force_n", vectorJson(point.residual.residual_force_n)},
                            {"residual_force_norm_n", point.residual.residual_force_n.norm()},
                            {"holding_friction_n", point.residual.holding_friction_n},
                            {"probe_stiffness_n_per_m", point.residual.stiffness_n_per_m},
                            {"drift_mm", point.release.drift_m * 1e3},
                            {"stuck", point.release.stuck},
                            {"caught", point.release.caught},
                            {"drift_off_mm", point.release_uncompensated.drift_m * 1e3},
                            {"map_gravity_n", vectorJson(point.map_gravity_n)}};
    if (report.has_truth) {
      entry["simulation_only_reachable"] = point.truly_reachable;
      entry["simulation_only_true_gravity_n"] = vectorJson(point.true_gravity_n);
      entry["simulation_only_truth_error_n"] = point.truth_error_n;
    }
    point_list.push_back(entry);
  }
  nlohmann::json json = {
      {"map", options.map_path},
      {"field_model", toString(map->fieldModel())},
      {"device", specs.model_name},
      {"device_name", options.device},
      {"simulated", simulation != nullptr},
      {"map_device", map->metadata().device_model},
      {"seed", options.seed},
      {"points", options.points},
      {"points_from_workspace", from_workspace},
      {"reached_points", report.reached_points},
      {"ready_points", report.ready_points},
      {"duration_s", options.duration_s},
      {"servo_period_s", report.servo_period_s},
      {"ramp_duration_s", verification.compensation.ramp_duration_s},
      {"probe_stiffness_n_per_m", probe.stiffness_n_per_m},
      {"probe_approach_distance_m", probe.approach_distance_m},
      {"probe_approaches_per_side", probe.approaches_per_side},
      {"residual_probes_valid", report.valid_residuals},
      {"max_residual_ratio", options.max_residual_ratio},
      {"max_residual_p90_ratio", options.max_residual_p90_ratio},
      {"max_residual_max_ratio", options.max_residual_max_ratio},
      {"max_residual_friction_ratio", options.max_residual_friction_ratio},
      {"holding_friction_median_n", friction_n},
      {"stuck_fraction", report.stuck_fraction},
      {"stuck_threshold_mm", options.stuck_threshold_mm},
      {"caught_releases", report.caught_releases},
      {"catch_drift_mm", kCatchDrift_m * 1e3},
      {"drift_ratio", ratio},
      {"max_drift_ratio", options.max_drift_ratio},
      {"max_force_sent_n", report.max_force_sent_n},
      {"max_linear_force_n", specs.max_linear_force_n},
      {"continuous_force_rating_n", report.continuous_force_rating_n},
      {"seconds_above_continuous_force", report.seconds_above_continuous_force},
      {"longest_above_continuous_force_s", report.longest_above_continuous_force_s},
      {"force_limit_ticks", report.force_limit_ticks},
      {"clamp_count", report.clamp_count},
      {"fault_count", faults},
      {"faults", fault_counts},
      {"device_seconds", report.seconds},
      {"force_ok", force_ok},
      {"drift_ok", drift_ok},
      {"residual_ok", residual_ok},
      {"pass", pass},
      {"releases", point_list}};
  addPercentilesJson(json, "residual_force", residual, "_n");
  addPercentilesJson(json, "residual_force", residual_rel, "_rel");
  addPercentilesJson(json, "drift", on, "_mm", 1e3);
  addPercentilesJson(json, "drift_off", off, "_mm", 1e3);
  addServoPriorityJson(json, servo_priority);
  if (simulation) {
    json["friction"] = sim::toString(options.friction);
    json["truth_is_simulation_only"] = true;
    addPercentilesJson(json, "truth_error", report.truth_error_n, "_n");
    addPercentilesJson(json, "truth_error", report.truth_error_rel, "_rel");
    json["unreachable_points"] = report.unreachable_points;
    json["servo_timing"] = sim::toString(options.servo_timing);
    json["servo_loop"] = servoLoopJson(options.servo_timing, simulated_ticks->loopSummary());
  }
  writeJsonReport(options.report_path, json);
  if (!pass) {
    std::printf("\nFAIL\n");
    throw CLI::RuntimeError(1);
  }
  std::printf("\nPASS\n");
}

void addVerifyCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<VerifyOptions>();
  CLI::App* command = app.add_subcommand(
      "verify",
      "Measure the force a map misses at seeded points of its workspace (the device carries "
      "itself there; a PD hold approached from both sides), then release the end-effector with "
      "compensation on and off and report the drift; exit 0 on PASS, 1 on FAIL");
  command->add_option("map", options->map_path, "Map file (JSON)")->required();
  addDeviceOption(*command, options->device);
  command->add_option("--points", options->points, "Test points")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command->add_option("--duration-s", options->duration_s, "Time after each release [s]")
      ->check(CLI::Range(0.001, 60.0))
      ->capture_default_str();
  command->add_flag("!--no-uncompensated", options->compare_uncompensated,
                    "Skip the releases with compensation off (the end-effector falls, caught "
                    "after a few millimetres)");
  addReportOption(*command, options->report_path);
  command->add_flag("--allow-model-mismatch", options->allow_model_mismatch,
                    "Use a map made for another device model");
  // What PASS requires, apart: each a positive number, its default shown.
  const auto add_limit = [command](const char* flag, double& limit, const char* description) {
    command->add_option(flag, limit, description)
        ->check(CLI::PositiveNumber)
        ->capture_default_str()
        ->group("Pass limits");
  };
  add_limit("--max-drift-ratio", options->max_drift_ratio,
            "Fail when drift median on / off exceeds this");
  add_limit("--max-residual-ratio", options->max_residual_ratio,
            "Fail when the median residual force exceeds this fraction of |G_hat|");
  add_limit("--max-residual-p90-ratio", options->max_residual_p90_ratio,
            "Fail when the 90th percentile of the residual exceeds this fraction of |G_hat|");
  add_limit("--max-residual-max-ratio", options->max_residual_max_ratio,
            "Fail when the largest residual exceeds this fraction of |G_hat|");
  add_limit("--max-residual-friction-ratio", options->max_residual_friction_ratio,
            "Fail when the largest residual exceeds this multiple of the friction the "
            "probe saw (median): above it a released stylus slides");
  add_limit("--stuck-threshold-mm", options->stuck_threshold_mm,
            "A release that moved less than this counts as stuck (a few encoder counts)");
  advanced->accept(*command, {knob::kSimulatedDevice, knob::kServoTiming});
  command->callback([options, advanced] { runVerifyCommand(*options, advanced->simulation()); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(50, addVerifyCommand);

}  // namespace autograv::cli
