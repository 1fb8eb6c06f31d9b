// autograv inspect: a human summary of a gravity map file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "autograv/map/map_io.h"
#include "autograv/map/map_summary.h"
#include "autograv/map/value_kind.h"
#include "cli_support.h"
#include "commands.h"

namespace autograv::cli {

namespace {

struct InspectOptions {
  std::string map_path;
  bool list_vertices = false;
};

void printRow(const char* label, const std::string& value) {
  std::printf("%-22s %s\n", label, value.c_str());
}

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, a, b, c, d);
  return text;
}

// Volume of the explored workspace's boundary model: the integral of r(u)^3 / 3 over the sphere
// of directions, on a Fibonacci lattice of directions (equal areas). Unit: [m^3]
double workspaceVolume_m3(const ExploredWorkspace& workspace) {
  constexpr int kDirections = 4000;
  constexpr double kPi = 3.14159265358979323846;
  const double golden_angle = kPi * (3.0 - std::sqrt(5.0));
  double sum = 0.0;
  for (int i = 0; i < kDirections; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / kDirections;
    const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d u(ring * std::cos(golden_angle * i), ring * std::sin(golden_angle * i),
                            z);
    sum += std::pow(workspace.boundaryDistance_m(u), 3) / 3.0;
  }
  return sum * 4.0 * kPi / kDirections;
}

void printWorkspace(const ExploredWorkspace& workspace) {
  if (workspace.empty()) {
    printRow("workspace", "not explored (a map made before the exploration, or without it)");
    return;
  }
  std::vector<double> reach_mm;
  for (double r : workspace.radii_m()) reach_mm.push_back(r * 1e3);
  const Eigen::Vector3d c = workspace.center_m() * 1e3;
  printRow("workspace",
           "explored along " + std::to_string(workspace.directions().size()) +
               format(" probe directions from [%.1f, %.1f, %.1f] mm", c.x(), c.y(), c.z()));
  printRow("", format("reach %.1f min, %.1f median, %.1f max mm", workspace.minRadius_m() * 1e3,
                      median(reach_mm), workspace.maxRadius_m() * 1e3));
  const double volume_m3 = workspaceVolume_m3(workspace);
  printRow("", format("volume about %.0f cm^3 (%.2f L) inside the probes' stops", volume_m3 * 1e6,
                      volume_m3 * 1e3));
}

void printLookup(const GravityMap& map) {
  const int k = map.lookupRefinement();
  const FieldModel model = map.fieldModel();
  printRow("field model", describeFieldModel(map));
  for (const std::string& line : describeFieldModelScores(map.metadata().field_model_scores)) {
    printRow("", line);
  }
  if (k <= 1 && model == FieldModel::kThinPlate) {
    printRow("lookup", "trilinear over the vertex values (refinement 1)");
    return;
  }
  const Eigen::Vector3i n = lookupResolution(map.grid(), k, model);
  const std::string lookup_grid =
      std::to_string(n.x()) + "x" + std::to_string(n.y()) + "x" + std::to_string(n.z());
  if (model != FieldModel::kThinPlate) {
    printRow("lookup", "refinement " + std::to_string(k) + ": trilinear on a " + lookup_grid +
                           " grid, one cell beyond the box, of the fit to every measurement");
  } else {
    printRow("lookup", "refinement " + std::to_string(k) + ": trilinear on a " + lookup_grid +
                           " grid of the thin-plate interpolant of every measurement");
  }
  if (map.metadata().field_model != model) {
    printRow("", std::string("(the file asks for the ") + toString(map.metadata().field_model) +
                     " model at refinement " + std::to_string(map.metadata().lookup_refinement) +
                     "; its measurements cannot determine it)");
  }
}

void runInspectCommand(const InspectOptions& options) {
  // loadMap validates everything, the checksum included: what is printed is what a device would
  // use. No device model is expected here, so maps of every model can be inspected.
  const GravityMap map = loadMap(options.map_path);
  const WorkspaceGrid& grid = map.grid();
  const MapMetadata& metadata = map.metadata();
  const EstimationParameters& p = metadata.parameters;

  std::vector<double> norms_n;
  std::vector<double> iterations;
  std::vector<double> seconds;
  std::map<std::string, int> outcomes;
  const MapSummary summary = summarizeVertices(map.vertices());
  // Failed or never visited: the vertices a redo pass would visit again.
  const std::vector<int>& not_converged = summary.to_visit_again;
  for (int i = 0; i < grid.vertexCount(); ++i) {
    const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(i)];
    ++outcomes[toString(v.outcome)];
    if (v.outcome == VertexOutcome::kPending) continue;
    norms_n.push_back(v.gravity_n.norm());
    iterations.push_back(v.iterations);
    seconds.push_back(v.seconds);
  }

  printRow("map", options.map_path + " (schema " + std::to_string(kMapSchemaVersion) +
                      ", checksum fnv1a-64 ok)");
  printRow("device",
           metadata.device_model +
               (metadata.device_serial.empty() ? "" : ", serial " + metadata.device_serial));
  printRow("created", metadata.created_utc);
  if (metadata.prior) {
    // A map corrected from another unit's map: which one, and by how much.
    const PriorText prior = describePrior(*metadata.prior);
    printRow("made from", prior.made_from);
    printRow("correction", prior.correction);
  }
  const Eigen::Vector3d c = grid.center_m() * 1e3;
  printRow("grid", std::string(grid.isCube() ? "cube " : "box ") + grid.describe() +
                       format(", centre [%.1f, %.1f, %.1f] mm", c.x(), c.y(), c.z()));
  std::string outcome_text = std::to_string(map.convergedCount()) + " converged, " +
                             std::to_string(grid.vertexCount() - map.convergedCount()) + " not";
  std::string details;
  for (const auto& [name, count] : outcomes) {
    if (name == "converged") continue;
    // "unreachable": beyond the explored workspace (or held by a stop), so not measured.
    const std::string shown = name == "unreachable" ? "out of reach" : name;
    details += (details.empty() ? "" : ", ") + shown + " " + std::to_string(count);
  }
  if (!details.empty()) outcome_text += " (" + details + ")";
  printRow("vertices", outcome_text);
  printRow("values", std::to_string(summary.at_vertex) + " measured at the vertex, " +
                         std::to_string(summary.off_vertex) +
                         " measured inside the stops (off vertex), " +
                         std::to_string(summary.solved) + " solved from the measurements");
  printWorkspace(metadata.workspace);
  printLookup(map);
  const AgreementText agreement = describeAgreement(map, judgeAgreement(map));
  printRow("leave-one-out", "each measurement from the fit of the others: " + agreement.summary);
  if (!agreement.least_sure.empty()) printRow("", agreement.least_sure);
  // The calibration's own review: measurements the others contradicted, measured again.
  const std::vector<std::string> reviewed =
      describeReviewedMeasurements(metadata.reviewed_measurements);
  printRow("measured again",
           reviewed.empty() ? std::string("none: no measurement stood out from the others")
                            : std::to_string(reviewed.size()) + " that the others contradicted, " +
                                  std::to_string(summary.left_out) + " left out of the fit");
  for (const std::string& line : reviewed) printRow("", line);
  printRow("motors warming", describeThermalDrift(metadata.thermal_drift));
  if (!norms_n.empty()) {
    const auto [lowest, highest] = std::minmax_element(norms_n.begin(), norms_n.end());
    printRow("|G_hat|", format("%.4f .. %.4f N, median %.4f N (apparent mass %.1f", *lowest,
                               *highest, median(norms_n), *lowest / kStandardGravity * 1e3) +
                            format(" .. %.1f g)", *highest / kStandardGravity * 1e3));
    printRow("iterations", format("median %.1f, max %.0f", median(iterations),
                                  *std::max_element(iterations.begin(), iterations.end())));
    double total_s = 0.0;
    for (double s : seconds) total_s += s;
    printRow("time at vertices",
             format("%.1f s in all, median %.2f s per vertex", total_s, median(seconds)));
  } else {
    printRow("|G_hat|", "no vertex visited yet");
  }
  printRow("parameters", format("alpha %g 1/s, beta %g 1/s^2, k0 %g N/mm", p.alpha_per_s,
                                p.beta_per_s2, p.k0_n_per_m * 1e-3));
  printRow("", format("n_S %g, eps_S %g mm/s, n_G %g, eps_G %g mN", p.n_s, p.eps_s_m_per_s * 1e3,
                      p.n_g, p.eps_g_n * 1e3));
  printRow("", format("step %g..%g s, max %g iterations, servo period %g ms", p.min_step_duration_s,
                      p.max_step_duration_s, p.max_iterations, p.servo_period_s * 1e3));
  printRow("", format("Lipschitz prior %g N/m", p.lipschitz_prior_n_per_m));
  if (p.method == EstimationMethod::kDither) {
    const std::string amplitude = p.dither_amplitude_n > 0.0
                                      ? format("%g mN per axis", p.dither_amplitude_n * 1e3)
                                      : std::string(
                                            "picked at each point within the continuous "
                                            "rating");
    printRow("",
             format("method dither: %g Hz, amplitude ", p.dither_frequency_hz) + amplitude +
                 format(", %g and %g steady windows", p.steady_windows, p.final_steady_windows));
  } else {
    printRow("", "method paper (eqs. 7-13 as published, no dither)");
  }

  const std::size_t kMaxListed = 20;
  if (!options.list_vertices && !not_converged.empty()) {
    std::printf("\nnot converged:\n");
    for (std::size_t k = 0; k < not_converged.size() && k < kMaxListed; ++k) {
      const int i = not_converged[k];
      const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(i)];
      const Eigen::Vector3d x = grid.vertexPosition(i) * 1e3;
      std::printf("  vertex %4d at [%7.2f, %7.2f, %7.2f] mm: %s after %d iterations\n", i, x.x(),
                  x.y(), x.z(), toString(v.outcome), v.iterations);
    }
    if (not_converged.size() > kMaxListed) {
      std::printf("  ... and %zu more (--list shows every vertex)\n",
                  not_converged.size() - kMaxListed);
    }
  }
  if (options.list_vertices) {
    std::printf("\n%6s  %-26s  %-30s  %5s  %7s  %-15s  %-10s  %s\n", "vertex", "position [mm]",
                "G_hat [N]", "iter", "time[s]", "outcome", "value", "measured at [mm]");
    for (int i = 0; i < grid.vertexCount(); ++i) {
      const VertexEstimate& v = map.vertices()[static_cast<std::size_t>(i)];
      const Eigen::Vector3d x = grid.vertexPosition(i) * 1e3;
      std::string measured_at;
      if (v.measuredOffVertex()) {
        const Eigen::Vector3d at = v.measured_at_m * 1e3;
        measured_at = format("[%7.2f, %7.2f, %7.2f]", at.x(), at.y(), at.z());
      }
      std::printf(
          "%6d  [%7.2f, %7.2f, %7.2f]  [%8.4f, %8.4f, %8.4f]  %5d  %7.2f  %-15s  %-10s  %s\n", i,
          x.x(), x.y(), x.z(), v.gravity_n.x(), v.gravity_n.y(), v.gravity_n.z(), v.iterations,
          v.seconds, toString(v.outcome), toString(valueKind(v)), measured_at.c_str());
    }
  }
}

void addInspectCommand(CLI::App& app, const Advanced& /*advanced*/) {
  auto options = std::make_shared<InspectOptions>();
  CLI::App* command = app.add_subcommand(
      "inspect", "Validate a gravity map file and print a summary (grid, device, convergence)");
  command->add_option("map", options->map_path, "Map file (JSON)")->required();
  command->add_flag("--list", options->list_vertices, "Also print every vertex");
  command->callback([options] { runInspectCommand(*options); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(40, addInspectCommand);

}  // namespace autograv::cli
