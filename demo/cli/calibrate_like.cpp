#include "calibrate_like.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "autograv/device/device_specifications.h"
#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "autograv/sim/friction_measurement.h"
#include "autograv/sim/procedures.h"
#include "cli_support.h"

namespace autograv::cli {

CLI::Option* addLikeOption(CLI::App& command, std::string& like) {
  return command
      .add_option("--like", like,
                  "Correct the map of another unit of this model (a path, or 'library' for the "
                  "map library's) with a few measurements, instead of a whole calibration")
      ->excludes("--resume")
      ->excludes("--grid")
      ->excludes("--box-mm")
      ->excludes("--side-mm");
}

nlohmann::json transferReportJson(const TransferResult& result) {
  nlohmann::json report;
  report["prior"] = result.prior.source;
  report["accepted"] = result.accepted;
  report["simulated_seconds"] = result.seconds;
  report["probe_seconds"] = result.probe_seconds;
  report["points_converged"] = result.converged_points;
  report["points_left_out"] = result.failed_points;
  report["workspace_difference_m"] = result.prior.workspace_difference_m;
  report["correction_model"] = result.prior.correction_model;
  nlohmann::json scores = nlohmann::json::object();
  for (const CorrectionScore& score : result.scores) {
    scores[toString(score.model)] = {{"mean_rel", score.mean_rel}, {"max_rel", score.max_rel}};
  }
  report["correction_scores"] = scores;
  report["check_points"] = result.prior.check_points;
  report["check_mean_rel"] = result.prior.check_mean_rel;
  report["check_max_rel"] = result.prior.check_max_rel;
  report["check_errors_rel"] = result.check_errors_rel;
  report["check_first_max_rel"] = result.first_check_max_rel;
  report["check_points_remeasured"] = result.remeasured_points;
  report["remeasure_seconds"] = result.remeasure_seconds;
  report["seconds_above_continuous_force"] = result.seconds_above_continuous_force;
  report["peak_force_n"] = result.peak_force_n;
  if (!result.accepted) report["refusal"] = result.refusal;
  return report;
}

GravityMap loadPrior(const std::string& like, const std::string& maps_dir, const std::string& model,
                     const std::string& serial, const TransferOptions& options,
                     std::string& source) {
  source = like;
  if (like == kLikeLibrary) {
    const MapLibrary library(maps_dir);
    source = library.findOtherUnit(model, serial);
    if (source.empty()) {
      throw Error("--like library: the map library '" + library.dir() +
                  "' holds no whole calibration of another " + model +
                  "; give a map's path to --like, or run a whole calibration");
    }
  } else if (!std::filesystem::exists(like)) {
    throw Error("--like: no map file '" + like + "' (a path, or '" + kLikeLibrary +
                "' for the map library's map of this model)");
  }
  GravityMap prior = loadMap(source);
  checkTransferPrior(prior, model, options);
  if (!serial.empty() && prior.metadata().device_serial == serial) {
    std::fprintf(stderr,
                 "note: the prior was made on this very unit (serial %s); the correction then "
                 "follows what changed since\n",
                 serial.c_str());
  }
  return prior;
}

void printTransfer(const TransferResult& result) {
  const MapPrior& prior = result.prior;
  std::printf("%-34s %s (unit %s, made %s)\n", "prior", prior.source.c_str(),
              prior.device_serial.empty() ? "with no serial" : prior.device_serial.c_str(),
              prior.created_utc.empty() ? "at an unknown time" : prior.created_utc.c_str());
  std::printf("%-34s within %.1f mm of the prior's stops (%.1f s)\n", "workspace check",
              prior.workspace_difference_m * 1e3, result.probe_seconds);
  double held_s = 0.0;
  int iterations = 0;
  for (const VertexEstimate& estimate : result.estimates) {
    held_s += estimate.seconds;
    iterations += estimate.iterations;
  }
  const double points = std::max<double>(1.0, static_cast<double>(result.estimates.size()));
  std::printf("%-34s %d converged, %d left out; %.1f iterations and %.2f s held per point\n",
              "points measured", result.converged_points, result.failed_points, iterations / points,
              held_s / points);
  if (!prior.correction_model.empty()) {
    std::printf("%-34s %s, chosen by leave-one-out over %zu points\n", "correction",
                prior.correction_model.c_str(), prior.points_m.size());
    for (const CorrectionScore& score : result.scores) {
      std::printf("%-34s %-13s leave-one-out mean %.2f %%, largest %.2f %%\n", "",
                  toString(score.model), 100.0 * score.mean_rel, 100.0 * score.max_rel);
    }
    std::printf("%-34s %d points: mean %.2f %%, largest %.2f %% of |G|\n",
                "check (points not fitted)", prior.check_points, 100.0 * prior.check_mean_rel,
                100.0 * prior.check_max_rel);
    if (result.remeasured_points > 0) {
      std::printf(
          "%-34s %d standing out past the line measured again (%.1f s): largest %.2f %% "
          "at first\n",
          "", result.remeasured_points, result.remeasure_seconds,
          100.0 * result.first_check_max_rel);
    }
  }
}

void runCalibrateLike(const std::string& device_name, const std::string& like,
                      const std::string& out_path, const std::string& report_path,
                      const AdvancedOptions& advanced) {
  const SimulationKnobs& simulation = advanced.simulation();
  auto device =
      openSimulatedDevice(device_name, simulation.seed, simulation.friction, simulation.unit);
  applySimulatedLoad(*device, simulation.load);
  const DeviceSpecifications& specs = device->specifications();
  TransferOptions options;
  options.parameters =
      estimationParameters(advanced.estimation(), EstimationMethod::kDither, specs);
  const GravityMap prior =
      loadPrior(like, {}, specs.model_name, specs.serial_number, options, options.prior_source);
  checkWritable(out_path, "map");
  if (!report_path.empty()) checkWritable(report_path, "report");

  std::printf("Correcting %s's map to %s: seed %llu, friction %s, unit %d with %s actuators\n",
              options.prior_source.c_str(), specs.model_name.c_str(),
              static_cast<unsigned long long>(simulation.seed), sim::toString(simulation.friction),
              simulation.unit.number, sim::toString(simulation.unit.actuators));
  std::fflush(stdout);
  // The user puts the stylus in the middle of the workspace and lets go; the prior's
  // compensation holds it there.
  const Eigen::Vector3d center_m = prior.metadata().workspace.center_m();
  device->setForce(prior.gravityAt(center_m));
  device->advance(options.parameters.servo_period_s);
  device->resetState(center_m);
  sim::SimulatedTickSource ticks(
      *device, options.parameters.servo_period_s, sim::SimulatedTickSource::Mode::kAsFastAsPossible,
      simulation.servo_timing, simulation.servo_timing_seed.value_or(simulation.seed));
  ProgressBar progress("point");
  options.on_progress = [&](const TransferProgress& now) {
    char detail[96];
    std::snprintf(
        detail, sizeof detail, "%s, sim %.0f s",
        now.phase == TransferProgress::Phase::kProbing ? "probing the stops" : "measuring",
        now.seconds);
    progress.update(now.done, now.total, detail);
  };
  const std::uint64_t saturations_before = device->saturationCount();
  const auto wall_start = std::chrono::steady_clock::now();
  const TransferResult result = transferMap(*device, ticks, prior, options);
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  progress.finish();
  const std::uint64_t limit_ticks = device->saturationCount() - saturations_before;

  std::printf("\n");
  printTransfer(result);
  nlohmann::json report = transferReportJson(result);
  report["wall_seconds"] = wall_s;
  report["force_limit_ticks"] = limit_ticks;
  report["device"] = device_name;
  report["seed"] = simulation.seed;
  report["unit"] = simulation.unit.number;
  if (!result.accepted) {
    writeJsonReport(report_path, report);
    throw Error("the correction was refused, and no map was saved: " + result.refusal +
                ": autograv calibrate --device " + device_name + " --out " + out_path);
  }
  const GravityMap& map = *result.map;
  saveMap(map, out_path);
  auto bench =
      openSimulatedDevice(device_name, simulation.seed, simulation.friction, simulation.unit);
  const sim::FrictionMeasurement friction = sim::measureFriction(*bench);
  const sim::FieldErrorReport field = sim::measureFieldError(
      map, *device, sim::kFieldErrorSamples, simulation.seed, 5e-3, friction.breakaway_force_n);
  const double continuous_n = continuousForceRating_n(specs);
  std::printf("%-34s %s (field model %s)\n", "map", out_path.c_str(), toString(map.fieldModel()));
  std::printf("%-34s %.1f s (%.1f s of it the workspace check), wall %.1f s\n", "simulated time",
              result.seconds, result.probe_seconds, wall_s);
  printFieldError(field);
  std::printf("%-34s %.1f s above %.2f N (%.1f %% of %.0f s), %llu ticks at the force limit\n",
              "force on the device", result.seconds_above_continuous_force, continuous_n,
              100.0 * result.seconds_above_continuous_force / std::max(result.seconds, 1e-9),
              result.seconds, static_cast<unsigned long long>(limit_ticks));
  report["map"] = out_path;
  report["field_model"] = toString(map.fieldModel());
  addFieldErrorJson(report, field);
  writeJsonReport(report_path, report);
}

}  // namespace autograv::cli
