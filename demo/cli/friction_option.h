#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "autograv/sim/friction.h"
#include "choice_option.h"

namespace autograv::cli {

/// Adds --friction none|low|typical|high to `command`: the friction of the simulated device the
/// command runs on, written into `level` (which keeps its value, typical by default, when the
/// option is not given). The one definition shared by the program's research and simulation
/// options (AdvancedOptions) and by autograv-demo.
inline CLI::Option* addFrictionOption(CLI::App& command, sim::FrictionLevel& level) {
  return addChoiceOption(
      command, "--friction", level, sim::parseFrictionLevel, sim::frictionLevelNames(),
      "Friction of the simulated device: none, low, typical (published figures) or high");
}

}  // namespace autograv::cli
