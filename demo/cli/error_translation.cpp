#include "error_translation.h"

namespace autograv::cli {

const std::vector<FlagTranslation>& flagTranslations() {
  // A phrase comes before every shorter one it contains: the first match wins.
  static const std::vector<FlagTranslation> table = {
      {"a calibration with WizardConfig::map_path set to this path makes one",
       "`autograv calibrate --out` with this path makes one"},
      {"the WizardConfig::centre_m, WizardConfig::grid_resolution and "
       "WizardConfig::advanced.box_size_m of that run",
       "the same --grid and --box-mm (or --side-mm) as that run"},
      {"Fit the grid to the workspace instead (leave WizardConfig::advanced.box_size_m empty)",
       "Drop --box-mm and --side-mm: the grid is then fitted to the explored workspace"},
      {"WizardConfig::advanced.explorer and advanced.min_workspace_extent_m would be ignored. "
       "Leave them at their defaults to resume",
       "--boundary-probes would be ignored. Drop it to resume"},
      {"WizardConfig::resume = true", "--resume"},
      {"WizardConfig::resume = false", "no --resume"},
      {"WizardConfig::map_path", "--out"},
      {"WizardConfig::advanced.box_size_m", "--box-mm (or --side-mm)"},
      {"WizardConfig::grid_resolution", "--grid"},
      {"EstimationParameters::beta_per_s2", "--beta-per-s2"},
      {"EstimationParameters::alpha_per_s", "--alpha-per-s"},
      {"EstimationParameters::k0_n_per_m", "--k0-n-per-mm"},
      {"EstimationParameters::eps_s_m_per_s", "--eps-s-mm-per-s"},
      {"EstimationParameters::eps_g_n", "--eps-g-gf"},
      {"EstimationParameters::n_g", "--n-g"},
      {"EstimationParameters::n_s", "--n-s"},
      {"EstimationParameters::max_iterations", "--max-iterations"},
      {"MapLoadOptions::allow_model_mismatch = true", "--allow-model-mismatch"},
      {"MapLibrary(dir)", "--maps DIR"},
      {"CalibrationWizard, then MapLibrary::save", "autograv wizard --device ..."},
      {"re-tare it (retareMap)", "run autograv retare"},
      {"calibrate it again (CalibrationWizard)", "calibrate it again (autograv wizard)"},
  };
  return table;
}

std::string inCommandLineTerms(std::string message) {
  for (const FlagTranslation& row : flagTranslations()) {
    const std::string from = row.library_phrase;
    const std::string to = row.command_line_phrase;
    for (std::size_t at = message.find(from); at != std::string::npos;
         at = message.find(from, at + to.size())) {
      message.replace(at, from.size(), to);
    }
  }
  return message;
}

WizardStatus inCommandLineTerms(WizardStatus status) {
  status.message = inCommandLineTerms(std::move(status.message));
  status.prompt = inCommandLineTerms(std::move(status.prompt));
  status.summary = inCommandLineTerms(std::move(status.summary));
  status.fault = inCommandLineTerms(std::move(status.fault));
  status.save_error = inCommandLineTerms(std::move(status.save_error));
  return status;
}

}  // namespace autograv::cli
