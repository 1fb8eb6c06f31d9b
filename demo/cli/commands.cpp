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

void addRegisteredCommands(CLI::App& app) {
  auto commands = registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& command : commands) command.second(app);
}

std::unique_ptr<CLI::App> makeApp() {
  auto app = std::make_unique<CLI::App>(
      "autograv - autocalibrated gravity compensation for 3-DoF impedance haptic devices");
  app->require_subcommand(1);
  app->set_version_flag("--version", "autograv " AUTOGRAV_VERSION_STRING);
  addRegisteredCommands(*app);
  return app;
}

}  // namespace autograv::cli
