#pragma once

// The library names what a caller can change by its C++ name (`WizardConfig::grid_resolution`,
// `EstimationParameters::beta_per_s2`); the command line says the same in its own flags
// (`--box-mm`, `--beta-per-s2`). This is the one table between the two, applied wherever the
// command line prints a message that came from the library.

#include <string>
#include <utility>
#include <vector>

#include "autograv/wizard/calibration_wizard.h"

namespace autograv::cli {

/// One row of the table: a phrase the library writes and what the command line says instead.
struct FlagTranslation {
  const char* library_phrase;
  const char* command_line_phrase;
};

/// Every row, longest library phrase first where one contains another.
const std::vector<FlagTranslation>& flagTranslations();

/// `message` with every library phrase of the table replaced by its command-line phrase.
std::string inCommandLineTerms(std::string message);

/// The status with its texts (message, prompt, summary, fault, save error) translated.
WizardStatus inCommandLineTerms(WizardStatus status);

}  // namespace autograv::cli
