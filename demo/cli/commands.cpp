#include "commands.h"

#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "autograv/version.h"

namespace autograv::cli {

namespace {
std::vector<std::pair<int, AddCommandFunction>>& registry() {
  static std::vector<std::pair<int, AddCommandFunction>> commands;
  return commands;
}
}  // namespace

bool registerCommand(int order, AddCommandFunction add) {
  registry().emplace_back(order, add);
  return true;
}

void addRegisteredCommands(CLI::App& app, const Advanced& advanced) {
  auto commands = registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& command : commands) command.second(app, advanced);
}

std::unique_ptr<CLI::App> makeApp() {
  auto app = std::make_unique<CLI::App>(
      "autograv - autocalibrated gravity compensation for 3-DoF impedance haptic devices");
  app->require_subcommand(1);
  app->set_version_flag("--version", "autograv " AUTOGRAV_VERSION_STRING);
  // The program's own options (the research and simulation ones) may follow the command's.
  app->fallthrough();
  app->formatter(makeHelpFormatter());
  const Advanced advanced = AdvancedOptions::declare(*app);
  addRegisteredCommands(*app, advanced);
  for (CLI::App* command : app->get_subcommands([](CLI::App*) { return true; })) {
    if (command->get_group() != kResearchCommands) command->group(kUserCommands);
  }
  advanced->refuseOthers(*app);
  app->footer(
      "Each command's options: autograv <command> --help. Research and simulation options "
      "(friction, seeds, estimation parameters): autograv --help-advanced.");
  return app;
}

}  // namespace autograv::cli
