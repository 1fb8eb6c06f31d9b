#include "estimation_options.h"

#include "autograv/estimation/pd_design.h"
#include "autograv/map/map_io.h"

namespace autograv::cli {

void addEstimationOptions(CLI::App& command, EstimationParameters& p,
                          EstimationMethod default_method) {
  p = default_method == EstimationMethod::kDither ? EstimationParameters::frictionRobust()
                                                  : EstimationParameters{};
  command
      .add_option_function<std::string>(
          "--method", [&p](const std::string& name) { p.method = parseEstimationMethod(name); },
          std::string("Estimation method: 'dither' converges through dry friction, 'paper' is "
                      "eqs. 7-13 as published (default ") +
              toString(default_method) + ")")
      ->check(CLI::IsMember({"paper", "dither"}));
  command
      .add_option_function<double>(
          "--dither-mn", [&p](double millinewtons) { p.dither_amplitude_n = millinewtons * 1e-3; },
          "Dither amplitude per axis for --method dither [mN] (default: 6 % of the device's max "
          "force)")
      ->check(CLI::NonNegativeNumber);
  command.add_option("--alpha", p.alpha_per_s, "PD damping alpha, K_D = alpha M [1/s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command.add_option("--beta", p.beta_per_s2, "PD stiffness beta, K_P = beta M [1/s^2]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command
      .add_option_function<double>(
          "--k0", [&p](double n_per_mm) { p.k0_n_per_m = n_per_mm * 1e3; },
          "Initialization field stiffness [N/mm] (default 0.5, at most a tenth of the device's "
          "max stiffness)")
      ->check(CLI::PositiveNumber);
  command.add_option("--n-s", p.n_s, "Slow samples that make a steady state")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  command
      .add_option_function<double>(
          "--eps-s", [&p](double mm_per_s) { p.eps_s_m_per_s = mm_per_s * 1e-3; },
          "Steady-state speed threshold [mm/s] (default 0.1)")
      ->check(CLI::PositiveNumber);
  command.add_option("--n-g", p.n_g, "Small updates that end a vertex")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  command
      .add_option_function<double>(
          "--eps-g", [&p](double grams) { p.eps_g_n = grams * 1e-3 * kStandardGravity; },
          "Estimate-change threshold [g-force] (default 0.5)")
      ->check(CLI::PositiveNumber);
  command.add_option("--max-iterations", p.max_iterations, "Iteration cap per vertex")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
}

void addGridOptions(CLI::App& command, int& grid, double& side_mm) {
  command.add_option("--grid", grid, "Vertices per axis (default 5)")->check(CLI::Range(2, 16));
  command
      .add_option("--side-mm", side_mm,
                  "Grid edge [mm] (default: 80 % of the cube inscribed in the workspace)")
      ->check(CLI::PositiveNumber);
}

void applyDeviceDefaults(const CLI::App& command, EstimationParameters& parameters,
                         const DeviceSpecifications& specifications) {
  if (command.count("--k0") == 0) {
    parameters.k0_n_per_m = defaultInitializationStiffness(specifications);
  }
  if (command.count("--n-g") == 0) {
    parameters.n_g = parameters.method == EstimationMethod::kDither
                         ? EstimationParameters::frictionRobust().n_g
                         : EstimationParameters{}.n_g;
  }
}

nlohmann::json parametersJson(const EstimationParameters& p) {
  return nlohmann::json::parse(parametersToJson(p));  // the map file's own encoding
}

}  // namespace autograv::cli
