#pragma once

#include <memory>

#include <CLI/CLI.hpp>

namespace autograv::cli {

/// Adds one subcommand (options and callback) to the `autograv` program.
using AddCommandFunction = void (*)(CLI::App& app);

/// Records a subcommand; main() adds them all sorted by `order` (the order of --help).
/// Returns true so that it can initialise a static. Not real-time safe.
bool registerCommand(int order, AddCommandFunction add);

/// Adds every registered subcommand to `app`, sorted by order.
void addRegisteredCommands(CLI::App& app);

/// The whole `autograv` command line: one required subcommand of those registered, --version and
/// --help. main() parses argv with it; the command-line fuzzer parses made-up ones. Not real-time
/// safe.
std::unique_ptr<CLI::App> makeApp();

}  // namespace autograv::cli

/// Use once at namespace scope in each cmd_<name>.cpp, e.g.
///   AUTOGRAV_REGISTER_COMMAND(30, addCalibrateCommand);
/// Orders: sim 10, devices 15, paper-experiment 20, calibrate 30, inspect 40, verify 50,
/// retare 55, check 56, wizard 60,
/// render/plot/export 70, bench 90.
#define AUTOGRAV_REGISTER_COMMAND(order, function)   \
  static const bool autograv_registered_##function = \
      ::autograv::cli::registerCommand(order, function)
