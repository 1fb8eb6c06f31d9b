#include "calibration_report.h"

#include <cstdio>

#include "autograv/map/map_summary.h"
#include "autograv/map/value_kind.h"
#include "cli_support.h"
#include "estimation_options.h"
#include "servo_timing_option.h"

namespace autograv::cli {

void printCalibrationOutcome(const CalibrationOutcome& outcome,
                             const sim::CalibrationRunResult& result, const GravityMap& map) {
  const DeviceSpecifications& specs = outcome.specs;
  const WorkspaceGrid& grid = result.grid;
  const MapSummary summary = summarizeVertices(map.vertices());
  const sim::AccuracyReport& accuracy = outcome.accuracy;
  const double device_seconds = result.simulated_seconds;
  std::printf("\n%-34s %s\n", "map", outcome.map_path.c_str());
  std::printf("%-34s %d / %d\n", "vertices converged", map.convergedCount(), grid.vertexCount());
  std::printf("%-34s %d %s, %d %s, %d %s\n", "values", summary.at_vertex,
              toString(ValueKind::kAtVertex), summary.off_vertex, toString(ValueKind::kOffVertex),
              summary.solved, toString(ValueKind::kSolved));
  std::printf("%-34s %.1f %%\n", "reachable workspace inside the grid",
              100.0 * outcome.workspace_coverage);
  std::printf("%-34s %.1f / %d (paper: 14 at one vertex)\n", "iterations per vertex (median/max)",
              summary.iterations.median, summary.iterations.max);
  std::printf("%-34s %.1f s (%.2f s per vertex), wall %.1f s\n", "simulated time",
              result.simulated_seconds, summary.secondsPerVertex(), outcome.wall_s);
  std::printf("%-34s %.2f %% (vertex %d), worst |G_hat - G| %.1f mN\n", "worst measured point",
              100.0 * accuracy.max_error_rel, accuracy.worst_vertex, accuracy.max_error_n * 1e3);
  printFieldError(outcome.field);
  std::printf("%-34s %d at the vertex, %d just inside the stops, %d beyond reach\n",
              "measurement points", result.plan.at_vertex, result.plan.off_vertex,
              result.plan.skipped);
  std::printf("%-34s %.1f s, %d directions, stops recognised within %.0f ms\n",
              "workspace exploration", result.exploration_seconds,
              static_cast<int>(result.workspace.directions().size()),
              result.longest_stop_recognition_s * 1e3);
  std::printf("%-34s %.1f s above %.2f N (%.1f %% of %.0f s), %llu ticks at the force limit\n",
              "force on the device", result.seconds_above_continuous_force,
              continuousForceRating_n(specs),
              100.0 * result.seconds_above_continuous_force / device_seconds, device_seconds,
              static_cast<unsigned long long>(result.force_limit_ticks));
  std::printf("%-34s %s: breakaway %.1f mN, sliding %.1f mN\n", "device friction",
              sim::toString(outcome.friction), outcome.device_friction.breakaway_force_n * 1e3,
              outcome.device_friction.coulomb_force_n * 1e3);
  std::printf("%-34s unit %d, %s: each motor delivers %.3f / %.3f / %.3f of its command\n",
              "device actuators", outcome.unit.number, sim::toString(outcome.unit.actuators),
              outcome.actuator_gains.x(), outcome.actuator_gains.y(), outcome.actuator_gains.z());
  if (outcome.motors_at_end) {
    const Eigen::Vector3d& motors = *outcome.motors_at_end;
    std::printf(
        "%-34s room %.1f C; at the end: hottest winding %.1f C, housing %.1f C, lowest "
        "gain factor %.4f\n",
        "motor temperatures (thermal on)", outcome.unit.thermal.ambient_c, motors.x(), motors.y(),
        motors.z());
  }
  printAgreement("leave-one-out (no ground truth)", describeAgreement(map, outcome.agreement));
  std::printf("%-34s %.2f %% of mean |G| = %.3f N\n", "RMS residual at 1000 points",
              100.0 * accuracy.rms_residual_rel, accuracy.mean_true_norm_n);
  std::printf("%-34s %.1f N/m (beta |G| / (2 g) = %.1f N/m)\n", "Lipschitz constant c (measured)",
              result.lipschitz_n_per_m,
              outcome.parameters.beta_per_s2 * result.initialization.gravity_n.norm() /
                  (2.0 * kStandardGravity));
  std::printf("%-34s %.2f N of %.2f N, %llu clamps\n", "peak force", result.peak_force_n,
              specs.max_linear_force_n, static_cast<unsigned long long>(result.saturation_count));
  printServoLoop(outcome.servo_timing, result.servo_loop);
  if (result.redo_passes > 0) {
    std::printf("%-34s %d pass(es), %d vertex visit(s)\n", "failed vertices visited again",
                result.redo_passes, result.redone_vertices);
  }
  for (int index : summary.to_visit_again) {
    const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(index)];
    std::printf("  vertex %d: %s after %d iterations\n", index, toString(v.outcome), v.iterations);
  }
  const std::vector<ReviewedMeasurement>& reviewed = map.metadata().reviewed_measurements;
  std::printf("%-34s %zu measured again, %d left out of the fit\n",
              "measurements the others contradict", reviewed.size(), summary.left_out);
  for (const std::string& line : describeReviewedMeasurements(reviewed)) {
    std::printf("  %s\n", line.c_str());
  }
  std::printf("%-34s %s\n", "motors warming (thermal drift)",
              describeThermalDrift(map.metadata().thermal_drift).c_str());
}

nlohmann::json calibrationReportJson(const CalibrationOutcome& outcome,
                                     const sim::CalibrationRunResult& result,
                                     const GravityMap& map) {
  const DeviceSpecifications& specs = outcome.specs;
  const WorkspaceGrid& grid = result.grid;
  const MapSummary summary = summarizeVertices(map.vertices());
  const sim::AccuracyReport& accuracy = outcome.accuracy;
  // The vertices a redo pass would visit again: failed, or never visited.
  nlohmann::json failed = nlohmann::json::array();
  for (int index : summary.to_visit_again) {
    failed.push_back(
        {{"vertex", index},
         {"outcome", toString(map.vertices()[static_cast<std::size_t>(index)].outcome)}});
  }
  nlohmann::json report = {
      {"device", specs.model_name},
      {"seed", outcome.seed},
      {"friction", sim::toString(outcome.friction)},
      {"unit", outcome.unit.number},
      {"actuators", sim::toString(outcome.unit.actuators)},
      {"actuator_gains", vectorJson(outcome.actuator_gains)},
      {"session", outcome.unit.session},
      {"thermal", outcome.unit.thermal.enabled},
      {"breakaway_force_n", outcome.device_friction.breakaway_force_n},
      {"coulomb_force_n", outcome.device_friction.coulomb_force_n},
      {"map", outcome.map_path},
      {"grid", gridJson(grid)},
      {"vertices", grid.vertexCount()},
      {"converged", map.convergedCount()},
      {"unreachable", map.unreachableCount()},
      {"filled", map.filledCount()},
      {"complete", map.isComplete()},
      {"workspace_coverage", outcome.workspace_coverage},
      {"failed", failed},
      {"iterations_median", summary.iterations.median},
      {"iterations_max", summary.iterations.max},
      {"simulated_seconds", result.simulated_seconds},
      {"seconds_per_vertex", summary.secondsPerVertex()},
      {"wall_seconds", outcome.wall_s},
      {"max_error_rel", accuracy.max_error_rel},
      {"worst_vertex", accuracy.worst_vertex},
      {"max_error_n", accuracy.max_error_n},
      {"rms_residual_rel", accuracy.rms_residual_rel},
      {"field_worst_point_m", vectorJson(outcome.field.worst_point_m)},
      {"measured_at_vertex", result.plan.at_vertex},
      {"measured_inside_stops", result.plan.off_vertex},
      {"beyond_reach", result.plan.skipped},
      {"exploration_seconds", result.exploration_seconds},
      {"exploration_directions", result.workspace.directions().size()},
      {"longest_stop_recognition_s", result.longest_stop_recognition_s},
      {"continuous_force_n", continuousForceRating_n(specs)},
      {"seconds_above_continuous_force", result.seconds_above_continuous_force},
      {"force_limit_ticks", result.force_limit_ticks},
      {"mean_true_gravity_n", accuracy.mean_true_norm_n},
      {"lipschitz_n_per_m", result.lipschitz_n_per_m},
      {"peak_force_n", result.peak_force_n},
      {"max_force_n", specs.max_linear_force_n},
      {"saturation_count", result.saturation_count},
      {"redo_passes", result.redo_passes},
      {"redone_vertices", result.redone_vertices},
      {"stop_retreats", result.stop_retreats},
      {"initial_gravity_n", vectorJson(result.initialization.gravity_n)},
      {"parameters", parametersJson(outcome.parameters)}};
  addFieldErrorJson(report, outcome.field);
  addAgreementJson(report, outcome.agreement);
  addFieldModelJson(report, map);
  addReviewedJson(report, map);
  report["servo_timing"] = sim::toString(outcome.servo_timing);
  report["servo_timing_seed"] = outcome.servo_timing_seed;
  report["servo_loop"] = servoLoopJson(outcome.servo_timing, result.servo_loop);
  if (outcome.motors_at_end) {
    report["ambient_c"] = outcome.unit.thermal.ambient_c;
    report["hottest_winding_c"] = outcome.motors_at_end->x();
    report["hottest_housing_c"] = outcome.motors_at_end->y();
    report["lowest_gain_factor"] = outcome.motors_at_end->z();
  }
  return report;
}

}  // namespace autograv::cli
