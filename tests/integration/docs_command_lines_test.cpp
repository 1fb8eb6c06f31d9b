// Docs that cannot drift. Every `autograv ...` command line written in README.md, CONTRIBUTING.md
// and docs/ (in code blocks and in inline code) is parsed by the program's own command line
// (makeApp: every registered command and option) and stopped once parsed, before any command
// starts: a command or flag that no longer exists, a value the parser refuses, a research option
// given to a command that does not take it, or an old spelling of a renamed flag fails the test,
// naming the file and line. The version the docs name is CMake's.
//
// Placeholders: `sim:D` is sim:omni; `<map.json>` is map.json (a file name in angle brackets is
// that file); an all-capital word (S, N, DIR) or a word in angle brackets (<device>) takes an
// example value for the flag before it (kExampleValues; "1" otherwise, map.json for a
// positional); `<command>` in the command's place stands for every command. In synopses, `[`
// and `]` around arguments are dropped, `a|b` is its first choice and `...` is skipped. A
// required argument the text leaves out (prose such as "`autograv verify` measures...") is filled
// in with an example value, so that the flags the text does write are still checked.
// AUTOGRAV_DOCS_TEST_LIST=1 in the environment lists every line it checks.
#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#if AUTOGRAV_DOCS_TEST_HAS_CLI
#include <CLI/CLI.hpp>

#include "advanced_options.h"
#include "autograv/error.h"
#include "commands.h"
#endif

namespace autograv {
namespace {

namespace fs = std::filesystem;

/// One command line found in a document.
struct DocumentedCommand {
  std::string file;                    ///< Relative to the source tree.
  int line = 0;                        ///< 1-based.
  std::string text;                    ///< As written, from `autograv` on.
  std::vector<std::string> arguments;  ///< After `autograv`, placeholders not yet resolved.
};

/// The documents whose command lines are checked: the README, CONTRIBUTING.md and every page
/// under docs/. CHANGELOG.md is left out: it quotes the flags of earlier versions on purpose.
std::vector<fs::path> documents() {
  const fs::path root = AUTOGRAV_SOURCE_DIR;
  std::vector<fs::path> files = {root / "README.md", root / "CONTRIBUTING.md"};
  for (const auto& entry : fs::recursive_directory_iterator(root / "docs")) {
    if (entry.is_regular_file() && entry.path().extension() == ".md") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> readLines(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

#if AUTOGRAV_DOCS_TEST_HAS_CLI

std::string trimmed(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

/// Splits a shell line into words: blanks separate them, quotes group them (and go).
std::vector<std::string> shellWords(const std::string& text) {
  std::vector<std::string> words;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (const char c : text) {
    if (quote != 0) {
      if (c == quote) {
        quote = 0;
      } else {
        word += c;
      }
    } else if (c == '\'' || c == '"') {
      quote = c;
      in_word = true;
    } else if (c == ' ' || c == '\t') {
      if (in_word) words.push_back(word);
      word.clear();
      in_word = false;
    } else {
      word += c;
      in_word = true;
    }
  }
  if (in_word) words.push_back(word);
  return words;
}

/// A word that ends the command: a shell operator or a redirection.
bool endsCommand(const std::string& word) {
  static const std::vector<std::string> operators = {"&&", "||", ";", "|", "&", ")", "<"};
  if (std::find(operators.begin(), operators.end(), word) != operators.end()) return true;
  return word.rfind(">", 0) == 0 || word.rfind("2>", 0) == 0 || word.rfind("1>", 0) == 0;
}

/// `autograv`, or a path to it (build/release/demo/autograv).
bool isProgram(const std::string& word) {
  return word == "autograv" ||
         (word.size() > 9 && word.compare(word.size() - 9, 9, "/autograv") == 0);
}

/// The first argument of a command line: a command, an option or a placeholder for a command.
/// `find_package(autograv 0.2)`, `autograv COMPONENTS`, `autograv 0.2.0` (printed) are not.
bool startsCommandLine(const std::string& word) {
  if (word.empty()) return false;
  if (word[0] == '-') return true;
  if (word[0] == '<') return true;
  return std::all_of(word.begin(), word.end(), [](char c) {
    return std::islower(static_cast<unsigned char>(c)) || c == '-';
  });
}

/// Every command line in one snippet of shell: a logical line of a code block, where the program
/// may come after others (`xvfb-run -a autograv render ...`), or inline code, which is a command
/// line only when it starts with the program (not a message that quotes one).
void findCommands(const std::string& snippet, const std::string& file, int line,
                  std::vector<DocumentedCommand>& found, bool anywhere) {
  std::vector<std::string> words = shellWords(snippet);
  if (!words.empty() && words.front() == "$") words.erase(words.begin());
  for (std::size_t i = 0; i < words.size() && (anywhere || i == 0); ++i) {
    if (!isProgram(words[i])) continue;
    DocumentedCommand command{file, line, "autograv", {}};
    for (std::size_t j = i + 1; j < words.size() && !endsCommand(words[j]); ++j) {
      std::string word = words[j];
      const bool last = !word.empty() && word.back() == ';';
      if (last) word.pop_back();
      command.arguments.push_back(word);
      command.text += " " + word;
      if (last) break;
    }
    if (!command.arguments.empty() && startsCommandLine(command.arguments.front())) {
      found.push_back(command);
    }
  }
}

/// A snippet without its shell comment (a '#' that starts a word).
std::string withoutComment(const std::string& text) {
  char quote = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quote != 0) {
      if (c == quote) quote = 0;
    } else if (c == '\'' || c == '"') {
      quote = c;
    } else if (c == '#' && (i == 0 || text[i - 1] == ' ' || text[i - 1] == '\t')) {
      return text.substr(0, i);
    }
  }
  return text;
}

/// The command lines of one document (Markdown): code blocks line by line, with `\`
/// continuations joined and comments dropped; inline code in the text, whose spans may be broken
/// across lines of a paragraph (or escape a table's `|` as `\|`).
std::vector<DocumentedCommand> commandsIn(const std::vector<std::string>& lines,
                                          const std::string& file) {
  std::vector<DocumentedCommand> found;
  bool in_code = false;
  std::string paragraph;             // The text since the last blank line or code fence.
  std::vector<std::size_t> offsets;  // Where each of its lines starts,
  int paragraph_line = 0;            // and the first one's number.
  const auto flushParagraph = [&] {
    static const std::regex span("`([^`]+)`");
    for (auto match = std::sregex_iterator(paragraph.begin(), paragraph.end(), span);
         match != std::sregex_iterator(); ++match) {
      const auto at = static_cast<std::size_t>(match->position(0));
      const auto line_index = static_cast<int>(
          std::upper_bound(offsets.begin(), offsets.end(), at) - offsets.begin() - 1);
      std::string code = std::regex_replace(match->str(1), std::regex(R"(\\\|)"), "|");
      findCommands(code, file, paragraph_line + line_index, found, false);
    }
    paragraph.clear();
    offsets.clear();
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string line = trimmed(lines[i]);
    const int number = static_cast<int>(i) + 1;
    if (line.rfind("```", 0) == 0) {
      flushParagraph();
      in_code = !in_code;
      continue;
    }
    if (in_code) {
      std::string logical = lines[i];
      while (!logical.empty() && logical.back() == '\\' && i + 1 < lines.size()) {
        logical.pop_back();
        logical += " " + lines[++i];
      }
      findCommands(withoutComment(logical), file, number, found, true);
      continue;
    }
    if (line.empty()) {
      flushParagraph();
      continue;
    }
    if (paragraph.empty()) paragraph_line = number;
    offsets.push_back(paragraph.size());
    paragraph += line + " ";
  }
  flushParagraph();
  return found;
}

std::vector<DocumentedCommand> documentedCommands() {
  std::vector<DocumentedCommand> all;
  for (const fs::path& path : documents()) {
    if (!fs::exists(path)) continue;
    const std::string name = fs::relative(path, AUTOGRAV_SOURCE_DIR).string();
    const std::vector<DocumentedCommand> found = commandsIn(readLines(path), name);
    all.insert(all.end(), found.begin(), found.end());
  }
  return all;
}

// ---------------------------------------------------------------------------------------------
// Placeholders

/// The example value of a placeholder given to each flag; other flags take "1".
const std::map<std::string, std::string> kExampleValues = {
    {"--device", "sim:omni"},
    {"--truth", "sim:omni"},
    {"--friction", "typical"},
    {"--actuators", "typical"},
    {"--servo-timing", "exact"},
    {"--method", "dither"},
    {"--field-model", "choose"},
    {"--view", "iso"},
    {"--background", "white"},
    {"--color-map", "viridis"},
    {"--grid", "5"},
    {"--box-mm", "160x120x70"},
    {"--size-px", "1280x960"},
    {"--dither-hz", "20"},
    {"--out", "out.json"},
    {"-o", "out.png"},
    {"--report", "report.json"},
    {"--map", "map.json"},
    {"--maps", "maps"},
    {"--compare", "other.json"},
    {"--diff", "difference.png"},
    {"--plot", "plot.png"},
    {"--title", "title"},
    {"--position-mm", "0,0,0"},
};

std::string exampleValue(const std::string& flag) {
  if (flag.empty()) return "map.json";  // a positional: most are map files
  const auto found = kExampleValues.find(flag);
  return found != kExampleValues.end() ? found->second : "1";
}

bool isWordPlaceholder(const std::string& word) {
  if (word.empty()) return false;
  return std::all_of(word.begin(), word.end(),
                     [](char c) {
                       return std::isupper(static_cast<unsigned char>(c)) ||
                              std::isdigit(static_cast<unsigned char>(c)) || c == '_';
                     }) &&
         std::isupper(static_cast<unsigned char>(word[0]));
}

/// The argument lists a documented command line stands for: one, or one per command for
/// `autograv <command> ...`. `commands` names every command of the program.
std::vector<std::vector<std::string>> resolvePlaceholders(
    const std::vector<std::string>& written, const std::vector<std::string>& commands) {
  std::vector<std::string> arguments;
  bool every_command = false;
  std::string flag;  // The flag before the current word, if any.
  for (std::string word : written) {
    // Synopsis marks: [--report r.json], --view iso|front|top, ...
    while (!word.empty() && word.front() == '[') word.erase(word.begin());
    while (!word.empty() && word.back() == ']') word.pop_back();
    if (word.empty() || word == "..." || word == "\u2026") continue;
    if (word.find('|') != std::string::npos && word.front() != '<')
      word = word.substr(0, word.find('|'));
    if (arguments.empty() && !every_command && word == "<command>") {
      every_command = true;
      continue;
    }
    if (word.size() > 2 && word.front() == '<' && word.back() == '>') {
      const std::string inner = word.substr(1, word.size() - 2);
      word = inner.find_first_of("./") != std::string::npos ? inner : exampleValue(flag);
    } else if (isWordPlaceholder(word)) {
      word = exampleValue(flag);
    } else if (word.size() > 2 && word.compare(word.size() - 2, 2, ":D") == 0) {
      word = "sim:omni";
    }
    flag = word.rfind("-", 0) == 0 && word.find('=') == std::string::npos ? word : std::string();
    arguments.push_back(word);
  }
  if (!every_command) return {arguments};
  std::vector<std::vector<std::string>> lines;
  for (const std::string& command : commands) {
    std::vector<std::string> line = {command};
    line.insert(line.end(), arguments.begin(), arguments.end());
    lines.push_back(line);
  }
  return lines;
}

// ---------------------------------------------------------------------------------------------
// Parsing

/// Thrown to stop a parsed command line before its command starts.
struct ParsedOnly {};

/// Every command of the program.
std::vector<std::string> programCommands() {
  const std::unique_ptr<CLI::App> app = cli::makeApp();
  std::vector<std::string> names;
  for (const CLI::App* command : app->get_subcommands([](CLI::App*) { return true; })) {
    names.push_back(command->get_name());
  }
  return names;
}

/// Why `arguments` does not parse, or empty when it does. Runs nothing: the program's parse
/// callback, which CLI11 calls once every option is parsed and validated and before any command's
/// callback, stops it. Required arguments the text left out are filled in (a few rounds).
std::string whyItDoesNotParse(std::vector<std::string> arguments) {
  for (int round = 0; round < 4; ++round) {
    const std::unique_ptr<CLI::App> app = cli::makeApp();
    app->parse_complete_callback([] { throw ParsedOnly{}; });
    std::vector<std::string> argv_storage = {"autograv"};
    argv_storage.insert(argv_storage.end(), arguments.begin(), arguments.end());
    std::vector<const char*> argv;
    for (const std::string& argument : argv_storage) argv.push_back(argument.c_str());

    std::ostringstream printed;  // --help-advanced prints itself before it exits
    std::streambuf* const saved = std::cout.rdbuf(printed.rdbuf());
    std::string problem;
    bool retry = false;
    try {
      app->parse(static_cast<int>(argv.size()), argv.data());
      problem = "the command would have run: nothing stopped it once parsed";
    } catch (const ParsedOnly&) {
      std::vector<const CLI::App*> apps = {app.get()};
      for (const CLI::App* command : app->get_subcommands()) apps.push_back(command);
      for (const CLI::App* owner : apps) {
        for (const CLI::Option* option : owner->get_options([](const CLI::Option* o) {
               return o->get_group() == cli::kOldSpellingsGroup && o->count() > 0;
             })) {
          problem = "old spelling " + option->get_name() + " (" + option->get_description() + ")";
        }
      }
    } catch (const CLI::RequiredError& error) {
      // Fill in what the text left out, then parse again: the flags it wrote are what counts.
      for (const CLI::App* command : app->get_subcommands()) {
        for (const CLI::Option* option : command->get_options(
                 [](const CLI::Option* o) { return o->get_required() && o->count() == 0; })) {
          if (option->get_positional() && !option->nonpositional()) {
            arguments.push_back(exampleValue(""));
          } else {
            arguments.push_back(option->get_name());
            arguments.push_back(exampleValue(option->get_name()));
          }
          retry = true;
        }
      }
      if (!retry) problem = error.what();
    } catch (const CLI::ParseError& error) {
      if (error.get_exit_code() != 0) problem = error.what();  // 0: --help, --version
    } catch (const autograv::Error& error) {
      problem = error.what();
    }
    std::cout.rdbuf(saved);
    if (!retry) return problem;
  }
  return "required arguments still missing after filling them in";
}

TEST(DocsCommandLinesTest, EveryCommandLineInTheDocsParses) {
  const std::vector<std::string> commands = programCommands();
  const std::vector<DocumentedCommand> documented = documentedCommands();
  std::size_t checked = 0;
  std::map<std::string, int> per_file;
  // AUTOGRAV_DOCS_TEST_LIST=1 lists every line as found and as parsed.
  const bool list = std::getenv("AUTOGRAV_DOCS_TEST_LIST") != nullptr;
  for (const DocumentedCommand& command : documented) {
    for (const std::vector<std::string>& arguments :
         resolvePlaceholders(command.arguments, commands)) {
      ++checked;
      if (list) {
        std::cout << command.file << ":" << command.line << ": " << command.text << "\n   ->";
        for (const std::string& argument : arguments) std::cout << " " << argument;
        std::cout << "\n";
      }
      const std::string problem = whyItDoesNotParse(arguments);
      EXPECT_TRUE(problem.empty())
          << command.file << ":" << command.line << ": `" << command.text << "`: " << problem;
    }
    ++per_file[command.file];
  }
  std::cout << documented.size() << " command lines in the docs (" << checked
            << " parsed with placeholders expanded):";
  for (const auto& [file, count] : per_file) std::cout << " " << file << " " << count << ";";
  std::cout << "\n";
  // The README and the command guide alone write dozens; an extractor that finds few is broken.
  EXPECT_GE(documented.size(), 60u);
  EXPECT_GT(per_file["README.md"], 0);
}

/// The checker itself: what it must find in a document, and what it must refuse.
TEST(DocsCommandLinesTest, TheCheckerFindsAndRefusesWhatItShould) {
  const std::vector<std::string> page = {
      "Run `autograv calibrate --device sim:D --seed S --out <map.json>` first; the",
      "`autograv verify` command measures. `find_package(autograv 0.2)` is no command, nor",
      "`error: no map (run autograv calibrate --out <path> to make one)`.",
      "```sh",
      "autograv render m.json -o scene.png \\",
      "  --view top   # a comment --not-a-flag",
      "pkg-config --modversion autograv",
      "```",
      "",
      "| `autograv inspect m.json --list` | `--method dither\\|paper` |",
  };
  const std::vector<DocumentedCommand> found = commandsIn(page, "page.md");
  ASSERT_EQ(found.size(), 4u);
  EXPECT_EQ(found[0].line, 1);
  EXPECT_EQ(found[1].line, 2);
  EXPECT_EQ(found[2].line, 5);
  EXPECT_EQ(found[2].text, "autograv render m.json -o scene.png --view top");
  EXPECT_EQ(found[3].text, "autograv inspect m.json --list");

  const std::vector<std::string> commands = programCommands();
  for (const DocumentedCommand& command : found) {
    for (const auto& arguments : resolvePlaceholders(command.arguments, commands)) {
      EXPECT_EQ(whyItDoesNotParse(arguments), "") << command.text;
    }
  }
  EXPECT_EQ(resolvePlaceholders({"<command>", "--help"}, commands).size(), commands.size());

  // A flag or command that does not exist, a bad value, a research option the command does not
  // take, an old spelling: each is refused.
  for (const std::vector<std::string>& wrong : std::vector<std::vector<std::string>>{
           {"calibrate", "--out", "m.json", "--no-such-flag"},
           {"calibrat", "--out", "m.json"},
           {"calibrate", "--out", "m.json", "--friction", "sticky"},
           {"inspect", "m.json", "--friction", "high"},
           {"calibrate", "--out", "m.json", "--eps-g", "0.3"},
           {"verify", "--no-such-flag"},
       }) {
    std::string joined;
    for (const std::string& word : wrong) joined += " " + word;
    EXPECT_NE(whyItDoesNotParse(wrong), "") << "autograv" << joined;
  }
}

#else

TEST(DocsCommandLinesTest, EveryCommandLineInTheDocsParses) {
  GTEST_SKIP() << "the command line is not built (AUTOGRAV_BUILD_DEMO=OFF)";
}

#endif

// ---------------------------------------------------------------------------------------------
// The version

/// The version the docs write where they name one (`find_package(autograv 0.2)`, the package
/// `autograv_0.2.0_amd64.deb`, `autograv 0.2.0` as --version prints it, pkg-config's
/// --modversion) is the one of `project(autograv VERSION ...)`.
TEST(DocsVersionTest, EveryVersionTheDocsNameIsCMakes) {
  const std::string version = AUTOGRAV_CMAKE_PROJECT_VERSION;
  const std::string major_minor = version.substr(0, version.rfind('.'));
  struct Pattern {
    std::regex regex;
    bool major_minor_only;
  };
  const std::vector<Pattern> patterns = {
      {std::regex(R"(find_package\(autograv (\d+\.\d+(\.\d+)?))"), true},
      {std::regex(R"(autograv_(\d+\.\d+\.\d+)_)"), false},
      {std::regex(R"(\bautograv (\d+\.\d+\.\d+))"), false},
      {std::regex(R"(--modversion autograv\s*#\s*(\d+\.\d+\.\d+))"), false},
  };
  int found = 0;
  for (const fs::path& path : documents()) {
    if (!fs::exists(path)) continue;
    const std::vector<std::string> lines = readLines(path);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      for (const Pattern& pattern : patterns) {
        for (auto match = std::sregex_iterator(lines[i].begin(), lines[i].end(), pattern.regex);
             match != std::sregex_iterator(); ++match) {
          ++found;
          const std::string written = (*match)[1].str();
          const std::string expected =
              pattern.major_minor_only
                  ? (written.size() > major_minor.size() ? version : major_minor)
                  : version;
          EXPECT_EQ(written, expected)
              << fs::relative(path, AUTOGRAV_SOURCE_DIR).string() << ":" << i + 1 << ": "
              << lines[i] << "\n(CMakeLists.txt says " << version << ")";
        }
      }
    }
  }
  EXPECT_GT(found, 0) << "no version found in the docs: has the pattern changed?";
}

}  // namespace
}  // namespace autograv
