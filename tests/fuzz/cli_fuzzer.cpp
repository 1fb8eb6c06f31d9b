// The command line of every `autograv` subcommand: the input is an argv, one argument per line,
// parsed by the program's own CLI11 set-up (makeApp, every registered command). Parsing must end
// in success, a CLI11 parse error (whose message and help text are rendered, as main() does) or
// autograv::Error, never another exception. Commands that would start long work (calibration,
// simulation, verification, rendering, benchmarks) are stopped once parsed, before their
// callbacks, so only their parsing and validators run; `inspect`, which finishes at once, runs.
//
// Paths: '/' in an argument becomes '_', so a command can only name files in the fuzzer's scratch
// folder (its working directory), which holds a valid map "map.json" and a truncated "cut.json".
// Standard output (what inspect prints) goes to /dev/null; findings are reported on stderr.
//
// Build with -DAUTOGRAV_FUZZ=ON (clang); run: build/fuzz/tests/fuzz/cli_fuzzer
// -dict=tests/fuzz/cli.dict <scratch corpus> tests/fuzz/corpus/cli
#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "autograv/error.h"
#include "commands.h"

namespace {

namespace fs = std::filesystem;

/// The only command whose callback runs: it loads a map and prints a summary, nothing longer.
constexpr const char* kInstantCommand = "inspect";
/// Arguments beyond these are ignored: no subcommand takes more.
constexpr std::size_t kMaxArguments = 32;

/// Thrown to stop a parsed command before it starts its work.
struct ParsedOnly {};

[[noreturn]] void fail(const char* what) {
  std::fprintf(stderr, "cli_fuzzer: %s\n", what);
  std::abort();
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) fail("cannot read a seed map");
  return text.str();
}

void writeFile(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// Splits the input into arguments at newlines; argv[0] is the program's name.
std::vector<std::string> argumentsOf(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> arguments{"autograv"};
  std::string current;
  for (std::size_t i = 0; i < size && arguments.size() <= kMaxArguments; ++i) {
    const char c = static_cast<char>(data[i]);
    if (c == '\n') {
      arguments.push_back(current);
      current.clear();
    } else {
      current += c == '/' ? '_' : c;
    }
  }
  if (!current.empty() && arguments.size() <= kMaxArguments) arguments.push_back(current);
  return arguments;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  const std::string map =
      readFile(fs::path(AUTOGRAV_SOURCE_DIR) / "tests/fuzz/corpus/map/omega_grid2.json");
  const fs::path folder =
      fs::temp_directory_path() / ("autograv-cli-fuzzer-" + std::to_string(::getpid()));
  fs::create_directories(folder);
  writeFile(folder / "map.json", map);
  writeFile(folder / "cut.json", map.substr(0, map.size() / 2));
  fs::current_path(folder);
  if (std::freopen("/dev/null", "w", stdout) == nullptr) fail("cannot silence stdout");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::string> arguments = argumentsOf(data, size);
  std::vector<const char*> argv;
  argv.reserve(arguments.size());
  for (const std::string& argument : arguments) argv.push_back(argument.c_str());

  const std::unique_ptr<CLI::App> app = autograv::cli::makeApp();
  // Runs once parsing and validation are done, before the chosen subcommand's callback: stops
  // there unless that subcommand is the instant one. (Replacing the callbacks instead would free
  // the option values they own while CLI11 still writes to them.)
  app->parse_complete_callback([&app] {
    for (const CLI::App* command : app->get_subcommands()) {
      if (command->get_name() != kInstantCommand) throw ParsedOnly{};
    }
  });
  try {
    app->parse(static_cast<int>(argv.size()), argv.data());
  } catch (const ParsedOnly&) {
    // parsed; the command's work is not started
  } catch (const CLI::ParseError& error) {
    std::ostringstream out;
    std::ostringstream err;
    app->exit(error, out, err);  // the message or help text main() would print
  } catch (const autograv::Error&) {
    // A bad value or file, reported to the user as "autograv: error: ..."
  }
  // Any other exception escapes: main() would print "unexpected error" for it.
  return 0;
}
