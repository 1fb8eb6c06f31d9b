#include "hand_script.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "autograv/error.h"

namespace autograv::demo {

namespace {

[[noreturn]] void fail(const std::string& source, int line, const std::string& what) {
  throw Error(source + ":" + std::to_string(line) + ": " + what);
}

double readNumber(std::istringstream& words, const std::string& source, int line,
                  const std::string& what) {
  std::string word;
  if (!(words >> word)) fail(source, line, "expected " + what);
  try {
    std::size_t used = 0;
    const double value = std::stod(word, &used);
    if (used != word.size() || !std::isfinite(value)) throw std::invalid_argument(word);
    return value;
  } catch (const std::exception&) {
    fail(source, line, "expected " + what + ", found '" + word + "'");
  }
}

}  // namespace

HandScript HandScript::parse(const std::string& text, const std::string& source) {
  HandScript script;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  const char* const usage =
      "expected 'at T grab', 'at T move X Y Z [SPEED]', 'at T release' or "
      "'at T compensation on|off'";
  while (std::getline(lines, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword)) continue;  // blank or comment
    if (keyword != "at") fail(source, number, usage);
    HandEvent event;
    event.line = number;
    event.time_s = readNumber(words, source, number, "a time in seconds after 'at'");
    if (event.time_s < 0.0) fail(source, number, "times must not be negative");
    std::string action;
    if (!(words >> action)) fail(source, number, usage);
    if (action == "grab") {
      event.kind = HandEvent::Kind::kGrab;
    } else if (action == "release") {
      event.kind = HandEvent::Kind::kRelease;
    } else if (action == "move") {
      event.kind = HandEvent::Kind::kMove;
      event.position_m.x() = readNumber(words, source, number, "x in metres");
      event.position_m.y() = readNumber(words, source, number, "y in metres");
      event.position_m.z() = readNumber(words, source, number, "z in metres");
      std::string speed;
      if (words >> speed) {
        std::istringstream again(speed);
        event.speed_m_per_s = readNumber(again, source, number, "a speed in m/s");
        if (!(event.speed_m_per_s > 0.0)) fail(source, number, "the speed must be positive");
      }
    } else if (action == "compensation") {
      std::string state;
      words >> state;
      if (state == "on") {
        event.kind = HandEvent::Kind::kCompensationOn;
      } else if (state == "off") {
        event.kind = HandEvent::Kind::kCompensationOff;
      } else {
        fail(source, number, "expected 'compensation on' or 'compensation off'");
      }
    } else {
      fail(source, number, usage);
    }
    std::string extra;
    if (words >> extra) fail(source, number, "unexpected '" + extra + "' at the end of the line");
    script.events_.push_back(event);
  }
  std::stable_sort(script.events_.begin(), script.events_.end(),
                   [](const HandEvent& a, const HandEvent& b) { return a.time_s < b.time_s; });
  return script;
}

HandScript HandScript::load(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw Error("cannot read the hand script " + path);
  std::ostringstream text;
  text << file.rdbuf();
  return parse(text.str(), path);
}

}  // namespace autograv::demo
