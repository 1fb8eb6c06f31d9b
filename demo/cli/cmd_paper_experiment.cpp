// autograv paper-experiment: the paper's Section V on the simulated Omega.
#include <cstdio>
#include <string>

#include <nlohmann/json.hpp>

#include "advanced_options.h"
#include "autograv/sim/paper_frame.h"
#include "autograv/sim/procedures.h"
#include "cli_support.h"
#include "commands.h"
#include "estimation_options.h"

namespace autograv::cli {

namespace {

struct PaperExperimentOptions {
  std::string device;
  std::string report_path;
  // The simulated device's (--seed, --friction, --unit, --actuators), once parsed.
  std::uint64_t seed = 1;
  sim::FrictionLevel friction = sim::FrictionLevel::kTypical;
  sim::SimulatedUnit unit;
};

void runPaperExperimentCommand(PaperExperimentOptions options, const AdvancedOptions& advanced) {
  options.seed = advanced.simulation().seed;
  options.friction = advanced.simulation().friction;
  options.unit = advanced.simulation().unit;
  auto device = openSimulatedDevice(options.device, options.seed, options.friction, options.unit);
  // The paper's values are the defaults.
  const EstimationParameters p = estimationParameters(
      advanced.estimation(), EstimationMethod::kPaper, device->specifications());
  std::printf(
      "Paper Sec. V on %s (seed %llu, friction %s): alpha = %g 1/s, beta = %g 1/s^2, "
      "k0 = %g N/mm,\nn_S = %d, eps_S = %g mm/s, n_G = %d, eps_G = %g g\n",
      options.device.c_str(), static_cast<unsigned long long>(options.seed),
      sim::toString(options.friction), p.alpha_per_s, p.beta_per_s2, p.k0_n_per_m * 1e-3, p.n_s,
      p.eps_s_m_per_s * 1e3, p.n_g, p.eps_g_n / kStandardGravity * 1e3);
  const Eigen::Vector3d target_mm = sim::chai3dToPaperFrame(sim::paperTargetPoint_m());
  const Eigen::Vector3d start_mm = sim::chai3dToPaperFrame(sim::paperStartPoint_m());
  std::printf("X_D = [%.1f, %.1f, %.1f] mm, start = [%.1f, %.1f, %.1f] mm (paper frame, y up)\n\n",
              target_mm.x(), target_mm.y(), target_mm.z(), start_mm.x(), start_mm.y(),
              start_mm.z());

  const sim::PaperExperimentResult result = sim::runPaperExperiment(*device, p);
  // Simulation only: the truth at X0 shows what eq. (7) got right; a sag onto the end stops
  // shows as a G_hat_0 far below it.
  const Eigen::Vector3d& initial_n = result.initialization.gravity_n;
  const Eigen::Vector3d initial_true_n = device->trueGravity(result.initialization.center_m);
  std::printf(
      "initialization (eq. 7) after %.2f s: G_hat_0 = [%.4f, %.4f, %.4f] N, |G_hat_0| = %.4f N\n"
      "  true G(X0)  = [%.4f, %.4f, %.4f] N, |G(X0)|   = %.4f N (simulation only), error "
      "%.2f %%\n\n",
      result.initialization.seconds, initial_n.x(), initial_n.y(), initial_n.z(), initial_n.norm(),
      initial_true_n.x(), initial_true_n.y(), initial_true_n.z(), initial_true_n.norm(),
      100.0 * (initial_n - initial_true_n).norm() / initial_true_n.norm());
  if (result.initialization.end_stop_hit) {
    std::printf(
        "WARNING: the end-effector pressed against the end stops during the initialization:\n"
        "G_hat_0 then holds the stop's force, not the gravity at X0.\n\n");
  }
  std::printf("%5s %12s %12s %10s\n", "j", "Delta_j[mm]", "M_hat_j[g]", "t_j[ms]");
  nlohmann::json history = nlohmann::json::array();
  int j = 1;
  for (const auto& record : result.estimate.history) {
    std::printf("%5d %12.4f %12.2f %10.0f\n", j++, record.position_error_m * 1e3,
                record.mass_estimate_kg * 1e3, record.duration_s * 1e3);
    history.push_back({{"delta_mm", record.position_error_m * 1e3},
                       {"mass_g", record.mass_estimate_kg * 1e3},
                       {"gravity_n", vectorJson(record.gravity_estimate_n)},
                       {"duration_s", record.duration_s}});
  }
  const double mass_estimate_g = result.estimate.gravity_n.norm() / kStandardGravity * 1e3;
  const double mass_true_g = result.mass_true_kg * 1e3;
  const double error_rel = std::abs(mass_estimate_g - mass_true_g) / mass_true_g;
  std::printf("\noutcome: %s after %d iterations (paper: 14)\n", toString(result.estimate.outcome),
              result.estimate.iterations);
  std::printf("M_hat(X_D) = %.1f g, true %.1f g, error %.2f %% (paper: 217 g vs 214 g, 1.4 %%)\n",
              mass_estimate_g, mass_true_g, 100.0 * error_rel);
  std::printf("|G_hat - G| = %.2f mN, simulated time %.1f s\n",
              (result.estimate.gravity_n - result.gravity_true_n).norm() * 1e3,
              result.simulated_seconds);

  nlohmann::json report = {{"device", options.device},
                           {"seed", options.seed},
                           {"friction", sim::toString(options.friction)},
                           {"outcome", toString(result.estimate.outcome)},
                           {"converged", result.estimate.outcome == VertexOutcome::kConverged},
                           {"iterations", result.estimate.iterations},
                           {"mass_estimate_g", mass_estimate_g},
                           {"mass_true_g", mass_true_g},
                           {"mass_error_rel", error_rel},
                           {"gravity_estimate_n", vectorJson(result.estimate.gravity_n)},
                           {"gravity_true_n", vectorJson(result.gravity_true_n)},
                           {"initial_gravity_n", vectorJson(initial_n)},
                           {"initial_gravity_true_n", vectorJson(initial_true_n)},
                           {"initial_center_m", vectorJson(result.initialization.center_m)},
                           {"initial_end_stop_hit", result.initialization.end_stop_hit},
                           {"target_m", vectorJson(result.target_m)},
                           {"simulated_seconds", result.simulated_seconds},
                           {"parameters", parametersJson(p)},
                           {"history", history}};
  writeJsonReport(options.report_path, report);
}

void addPaperExperimentCommand(CLI::App& app, const Advanced& advanced) {
  auto options = std::make_shared<PaperExperimentOptions>();
  CLI::App* command = app.add_subcommand(
      "paper-experiment",
      "Reproduce the paper's Section V: estimate the apparent gravity at X_D = [0,-30,0] mm on "
      "the simulated Omega with the paper's parameters");
  command->group(kResearchCommands);
  addSimulatedDeviceOption(*command, options->device);
  addReportOption(*command, options->report_path);
  advanced->accept(*command, {knob::kSimulatedDevice, knob::kEstimation});
  command->callback([options, advanced] { runPaperExperimentCommand(*options, *advanced); });
}

}  // namespace

AUTOGRAV_REGISTER_COMMAND(85, addPaperExperimentCommand);

}  // namespace autograv::cli
