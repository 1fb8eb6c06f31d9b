// autograv: calibrate, inspect, verify, render and benchmark gravity maps from the command line.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>

#include "autograv/error.h"
#include "commands.h"

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

}  // namespace autograv::cli

int main(int argc, char** argv) {
  CLI::App app{"autograv - autocalibrated gravity compensation for 3-DoF impedance haptic devices"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "autograv 0.1.0");
  autograv::cli::addRegisteredCommands(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  } catch (const autograv::Error& error) {
    std::fprintf(stderr, "autograv: error: %s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "autograv: unexpected error: %s\n", error.what());
    return 3;
  }
  return 0;
}
