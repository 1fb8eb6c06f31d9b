#include "cli_support.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "autograv/error.h"
#include "autograv/map/map_io.h"

namespace autograv::cli {

std::unique_ptr<sim::SimulatedDevice> openSimulatedDevice(const std::string& name,
                                                          std::uint64_t seed,
                                                          sim::FrictionLevel friction) {
  auto device = sim::makeSimulatedDevice(name, seed, friction);
  if (!device->open()) throw Error("device " + name + ": open() failed");
  if (!device->calibrate()) throw Error("device " + name + ": calibrate() failed");
  return device;
}

void writeJsonReport(const std::string& path, const nlohmann::json& report) {
  if (path.empty()) return;
  writeFileAtomically(path, report.dump(2) + "\n", "report");
}

bool stderrIsTerminal() { return ::isatty(STDERR_FILENO) == 1; }

int terminalColumns() {
  winsize size{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
  return 80;
}

std::string formatDuration(double seconds) {
  char text[32];
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  if (seconds < 10.0) {
    std::snprintf(text, sizeof text, "%.1fs", seconds);
  } else if (seconds < 60.0) {
    std::snprintf(text, sizeof text, "%.0fs", seconds);
  } else {
    const int whole = static_cast<int>(seconds);
    std::snprintf(text, sizeof text, "%dm %02ds", whole / 60, whole % 60);
  }
  return text;
}

ProgressBar::ProgressBar(std::string label)
    : label_(std::move(label)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_),
      terminal_(stderrIsTerminal()) {}

void ProgressBar::update(int done, int total, const std::string& detail) {
  const auto now = std::chrono::steady_clock::now();
  const double since_draw = std::chrono::duration<double>(now - last_draw_).count();
  const bool last = done >= total;
  if (drawn_ && !last && since_draw < (terminal_ ? 0.1 : 5.0)) return;
  last_draw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double fraction = total > 0 ? static_cast<double>(done) / total : 1.0;
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : NAN;
  std::ostringstream line;
  line << label_ << ' ' << done << '/' << total;
  const int columns = terminal_ ? terminalColumns() : 80;
  const int bar_width = columns >= 100 ? 30 : (columns >= 70 ? 16 : 0);
  if (bar_width > 0) {
    const int filled = static_cast<int>(fraction * bar_width + 0.5);
    line << " [" << std::string(static_cast<std::size_t>(filled), '#')
         << std::string(static_cast<std::size_t>(bar_width - filled), '.') << ']';
  }
  line << ' ' << static_cast<int>(fraction * 100.0 + 0.5) << "%  " << detail;
  line << "  ETA " << (last ? "0s" : formatDuration(eta));
  std::string text = line.str();
  if (terminal_) {
    if (static_cast<int>(text.size()) > columns - 1)
      text.resize(static_cast<std::size_t>(columns - 1));
    std::fprintf(stderr, "\r\033[K%s", text.c_str());
  } else {
    std::fprintf(stderr, "%s\n", text.c_str());
  }
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (terminal_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace autograv::cli
