#pragma once

#include <memory>

#include <CLI/CLI.hpp>

#include "advanced_options.h"

namespace autograv::cli {

/// The research and simulation options, declared once on the program: a command says which it
/// takes (AdvancedOptions::accept) and reads their values in its callback.
using Advanced = std::shared_ptr<AdvancedOptions>;

/// The headings of `autograv --help`: what a user runs, and the research and simulation commands.
inline constexpr const char* kUserCommands = "Commands";
inline constexpr const char* kResearchCommands = "Research and simulation commands";

/// Adds one subcommand (options and callback) to the `autograv` program.
using AddCommandFunction = void (*)(CLI::App& app, const Advanced& advanced);

/// Records a subcommand; main() adds them all sorted by `order` (the order of --help).
/// Returns true so that it can initialise a static. Not real-time safe.
bool registerCommand(int order, AddCommandFunction add);

/// Adds every registered subcommand to `app`, sorted by order.
void addRegisteredCommands(CLI::App& app, const Advanced& advanced);

/// The whole `autograv` command line: one required subcommand of those registered, --version,
/// --help and --help-advanced, and the research and simulation options, which every command
/// accepts after its own (CLI11's fallthrough) and refuses when it does not take them. main()
/// parses argv with it; the command-line fuzzer parses made-up ones. Not real-time safe.
std::unique_ptr<CLI::App> makeApp();

}  // namespace autograv::cli

/// Use once at namespace scope in each cmd_<name>.cpp, e.g.
///   AUTOGRAV_REGISTER_COMMAND(30, addCalibrateCommand);
/// Orders: devices 15, calibrate 30, inspect 40, verify 50, retare 55, check 56, wizard 60,
/// render/plot/export/compare 70; the research commands (listed apart by --help): sim 80,
/// paper-experiment 85, bench 90.
#define AUTOGRAV_REGISTER_COMMAND(order, function)   \
  static const bool autograv_registered_##function = \
      ::autograv::cli::registerCommand(order, function)
