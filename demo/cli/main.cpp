// autograv: calibrate, inspect, verify, render and benchmark gravity maps from the command line.
#include <cstdio>
#include <exception>

#include <CLI/CLI.hpp>

#include "autograv/error.h"
#include "commands.h"
#include "error_translation.h"

int main(int argc, char** argv) {
  const auto app = autograv::cli::makeApp();
  try {
    app->parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app->exit(error);
  } catch (const autograv::Error& error) {
    // The library names its C++ parameters; the user typed flags.
    std::fprintf(stderr, "autograv: error: %s\n",
                 autograv::cli::inCommandLineTerms(error.what()).c_str());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "autograv: unexpected error: %s\n", error.what());
    return 3;
  }
  return 0;
}
