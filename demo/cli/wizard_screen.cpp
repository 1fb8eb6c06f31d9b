#include "wizard_screen.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "cli_support.h"

namespace autograv::cli {

namespace {

std::string fixed(double value, int decimals) {
  char text[48];
  std::snprintf(text, sizeof text, "%.*f", decimals, value);
  return text;
}

std::string stepHeading(const WizardStatus& status) {
  if (status.step_number == 0) return status.title;
  return "Step " + std::to_string(status.step_number) + " of " +
         std::to_string(WizardStatus::kStepCount) + ": " + status.title;
}

/// The step's live numbers on one line (a gauge where there is progress to show).
std::string gaugeLine(const WizardStatus& status, int columns) {
  const int bar_width = std::clamp(columns / 3, 8, 32);
  const bool bar = columns >= 44;
  std::ostringstream line;
  switch (status.step) {
    case WizardStep::kCentre: {
      if (!status.position_valid) return "";
      // Full when within the tolerance; empty 50 mm farther out.
      const double fraction =
          std::clamp(1.0 - (status.centre_distance_m - status.centre_tolerance_m) / 0.05, 0.0, 1.0);
      line << "distance " << fixed(status.centre_distance_m * 1e3, 1) << " mm";
      if (bar) line << "  " << progressBar(fraction, bar_width);
      line << (status.within_tolerance
                   ? "  OK"
                   : "  (need <= " + fixed(status.centre_tolerance_m * 1e3, 0) + " mm)");
      break;
    }
    case WizardStep::kRelease:
      line << "sag " << fixed(status.sag_m * 1e3, 2) << " mm, speed "
           << fixed(status.speed_m_per_s * 1e3, 2) << " mm/s, "
           << fixed(status.release_elapsed_s, 1) << " s";
      break;
    case WizardStep::kExplore: {
      // The explored volume growing: directions done, and the box of what was reached.
      const int total = std::max(status.direction_count, 1);
      if (bar) {
        line << progressBar(static_cast<double>(status.directions_probed) / total, bar_width)
             << ' ';
      }
      line << status.directions_probed << '/' << status.direction_count << " directions";
      if (status.directions_probed > 0) {
        const Eigen::Vector3d extent_m = status.explored_high_m - status.explored_low_m;
        line << ", box " << fixed(extent_m.x() * 1e3, 0) << "x" << fixed(extent_m.y() * 1e3, 0)
             << "x" << fixed(extent_m.z() * 1e3, 0) << " mm";
      }
      break;
    }
    case WizardStep::kAutoCalibration: {
      const int total = std::max(status.vertices_to_visit, 1);
      const int done = std::clamp(status.vertex_ordinal - 1, 0, total);
      if (bar) line << progressBar(static_cast<double>(done) / total, bar_width) << ' ';
      line << done << '/' << status.vertices_to_visit << " vertices";
      line << "  ETA " << (std::isfinite(status.eta_s) ? formatDuration(status.eta_s) : "?");
      if (status.paused) line << "  PAUSED";
      break;
    }
    case WizardStep::kVerify: {
      const int total = std::max(static_cast<int>(status.verify.size()), 1);
      int done = 0;
      for (const auto& result : status.verify) done += result.finished ? 1 : 0;
      if (bar) line << progressBar(static_cast<double>(done) / total, bar_width) << ' ';
      line << done << '/' << status.verify.size() << " release tests";
      break;
    }
    default:
      return "";
  }
  return line.str();
}

std::string keyHelp(const WizardStatus& status, const ScreenContext& context, bool compact) {
  std::vector<std::string> keys;
  switch (status.step) {
    case WizardStep::kCheck:
      if (status.waiting_for_user) keys.push_back("Enter retry");
      break;
    case WizardStep::kCentre:
      keys.push_back("Enter confirm");
      break;
    case WizardStep::kAutoCalibration:
      keys.push_back(status.paused ? "p resume" : "p pause");
      break;
    case WizardStep::kReview:
      keys.push_back("Enter save");
      if (offersRedo(status.review)) {
        keys.push_back("r redo");
      }
      break;
    case WizardStep::kSave:
      if (status.waiting_for_user) keys.push_back("Enter retry");
      break;
    default:
      break;
  }
  keys.push_back("q quit");
  if (context.simulated_hand && !context.auto_hand) {
    if (compact) {
      keys.push_back("g grab");
      keys.push_back("arrows/PgUp/PgDn move");
    } else {
      keys.push_back("g grab/let go");
      keys.push_back("arrows move");
      keys.push_back("PgUp/PgDn up/down");
    }
  }
  std::string text = "Keys:";
  for (std::size_t i = 0; i < keys.size(); ++i) text += (i == 0 ? " " : " | ") + keys[i];
  return text;
}

std::string handLine(const ScreenContext& context) {
  if (!context.simulated_hand) return "";
  std::string text = context.auto_hand ? "Simulated hand (automatic): " : "Simulated hand: ";
  if (!context.hand_holding) return text + "not holding";
  const Eigen::Vector3d& t = context.hand_target_m;
  return text + "holding, target (" + fixed(t.x() * 1e3, 0) + ", " + fixed(t.y() * 1e3, 0) + ", " +
         fixed(t.z() * 1e3, 0) + ") mm";
}

void addWrapped(std::vector<std::string>& lines, const std::string& text, int columns,
                const std::string& first_prefix = "", const std::string& indent = "  ") {
  if (text.empty()) return;
  std::vector<std::string> wrapped =
      wrapText(text, columns - static_cast<int>(first_prefix.size()), indent);
  for (std::size_t i = 0; i < wrapped.size(); ++i) {
    lines.push_back((i == 0 ? first_prefix : std::string(first_prefix.size(), ' ')) + wrapped[i]);
  }
}

}  // namespace

std::vector<std::string> wrapText(const std::string& text, int columns, const std::string& indent) {
  const std::size_t width = static_cast<std::size_t>(std::max(columns, 8));
  std::vector<std::string> lines;
  std::istringstream paragraphs(text);
  std::string paragraph;
  while (std::getline(paragraphs, paragraph)) {
    // Keep a paragraph's own leading spaces (the message's indented sub-lines).
    const std::size_t lead = paragraph.find_first_not_of(' ');
    const std::string own_indent = paragraph.substr(0, lead == std::string::npos ? 0 : lead);
    std::istringstream words(paragraph);
    std::string word;
    std::string line = own_indent;
    bool empty = true;
    while (words >> word) {
      const std::string prefix = empty ? "" : " ";
      if (!empty && line.size() + prefix.size() + word.size() > width) {
        lines.push_back(line);
        line = own_indent + indent;
        empty = true;
      }
      while (line.size() + word.size() > width) {  // a word longer than the line
        const std::size_t room = width > line.size() ? width - line.size() : 1;
        lines.push_back(line + word.substr(0, room));
        word.erase(0, room);
        line = own_indent + indent;
      }
      line += (empty ? "" : " ") + word;
      empty = false;
    }
    lines.push_back(line);
  }
  return lines;
}

std::string progressBar(double fraction, int width) {
  const int inner = std::max(width - 2, 1);
  const int filled = static_cast<int>(std::clamp(fraction, 0.0, 1.0) * inner + 0.5);
  return "[" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(inner - filled), '.') + "]";
}

std::vector<std::string> renderScreen(const WizardStatus& status, const ScreenContext& context,
                                      int columns, int rows) {
  columns = std::max(columns, 20);
  rows = std::max(rows, 6);
  const int width = columns - 1;  // never write the last column: no automatic wrap

  std::vector<std::string> head;
  std::string header = "autograv wizard - " + context.device_name;
  const std::string where = status.step_number > 0
                                ? "step " + std::to_string(status.step_number) + "/" +
                                      std::to_string(WizardStatus::kStepCount)
                                : toString(status.step);
  if (static_cast<int>(header.size() + where.size()) + 2 <= width) {
    header +=
        std::string(static_cast<std::size_t>(width) - header.size() - where.size(), ' ') + where;
  }
  head.push_back(header);
  std::vector<std::string> summary;
  addWrapped(summary, status.summary, width);
  head.push_back(std::string(static_cast<std::size_t>(std::min(width, 100)), '-'));
  addWrapped(head, stepHeading(status), width);
  const std::string gauge = gaugeLine(status, width);
  if (!gauge.empty()) addWrapped(head, gauge, width);

  std::vector<std::string> body;
  addWrapped(body, status.message, width);

  std::vector<std::string> tail;
  addWrapped(tail, status.prompt, width, "> ");
  addWrapped(tail, context.notice, width, "! ");
  addWrapped(tail, keyHelp(status, context, width < 60), width);
  addWrapped(tail, handLine(context), width);

  // Roomy layout first; on a short terminal drop the blank lines and the summary, then cut the
  // message from its end.
  std::vector<std::string> lines;
  const int roomy = static_cast<int>(head.size() + summary.size() + body.size() + tail.size()) + 3;
  if (roomy <= rows) {
    lines.push_back(head[0]);
    lines.insert(lines.end(), summary.begin(), summary.end());
    lines.insert(lines.end(), head.begin() + 1, head.end());
    lines.emplace_back();
    lines.insert(lines.end(), body.begin(), body.end());
    lines.emplace_back();
    lines.insert(lines.end(), tail.begin(), tail.end());
    return lines;
  }
  lines = head;
  const int room_for_body = rows - static_cast<int>(head.size() + tail.size());
  if (room_for_body >= static_cast<int>(body.size())) {
    lines.insert(lines.end(), body.begin(), body.end());
  } else if (room_for_body > 0) {
    lines.insert(lines.end(), body.begin(), body.begin() + (room_for_body - 1));
    lines.push_back("  ...");
  }
  lines.insert(lines.end(), tail.begin(), tail.end());
  if (static_cast<int>(lines.size()) > rows) {
    // A tiny terminal: keep the step heading and the prompt above everything else.
    std::vector<std::string> essential;
    addWrapped(essential, stepHeading(status), width);
    addWrapped(essential, status.prompt, width, "> ");
    if (!gauge.empty()) addWrapped(essential, gauge, width);
    addWrapped(essential, status.message, width);
    essential.resize(std::min(essential.size(), static_cast<std::size_t>(rows)));
    return essential;
  }
  return lines;
}

void TerminalScreen::draw(const std::vector<std::string>& lines) {
  if (lines == last_) return;
  // No line feed after the last line: on a full screen it would scroll the first line away.
  std::string out = "\033[H";
  for (std::size_t i = 0; i < lines.size(); ++i) {
    out += lines[i] + "\033[K";
    if (i + 1 < lines.size()) out += "\r\n";
  }
  out += "\033[J";
  std::fwrite(out.data(), 1, out.size(), stdout);
  std::fflush(stdout);
  last_ = lines;
}

void PlainLog::print(const std::string& text, const std::string& indent) {
  for (const auto& line : wrapText(text, 1000, "")) {
    std::fprintf(out_, "%s%s\n", indent.c_str(), line.c_str());
  }
}

void PlainLog::update(const WizardStatus& status) {
  if (explore_progress_ && status.step != WizardStep::kExplore) {
    explore_progress_->update(status.direction_count, status.direction_count, "explored");
    explore_progress_->finish();
    explore_progress_.reset();
    if (!status.workspace.empty()) {
      std::fprintf(out_,
                   "      explored: reach %.1f to %.1f mm; %d vertices measured at the vertex, %d "
                   "just inside the stops, %d beyond reach\n",
                   status.workspace.minRadius_m() * 1e3, status.workspace.maxRadius_m() * 1e3,
                   status.measured_at_vertex, status.measured_off_vertex, status.beyond_reach);
    }
  }
  if (progress_ && status.step != WizardStep::kAutoCalibration) {
    if (status.step == WizardStep::kReview) {
      progress_->update(progress_total_, progress_total_, "finished");
    }
    progress_->finish();
    progress_.reset();
  }
  if (!started_ || status.step != step_) {
    started_ = true;
    step_ = status.step;
    prompt_.clear();
    message_.clear();
    const std::string number = status.step_number > 0 ? std::to_string(status.step_number) + "/" +
                                                            std::to_string(WizardStatus::kStepCount)
                                                      : std::string(toString(status.step));
    std::fprintf(out_, "[%s] %s\n", number.c_str(), status.title.c_str());
    if (status.step == WizardStep::kCentre && !status.summary.empty()) {
      print(status.summary, "      ");
    }
  }
  // The messages of these steps are results worth a line each; the others carry live numbers
  // that change every frame and are shown only when the prompt changes.
  const bool report_message =
      status.step == WizardStep::kCheck || status.step == WizardStep::kDone ||
      status.step == WizardStep::kAborted || status.step == WizardStep::kFault;
  if (report_message && status.message != message_) {
    message_ = status.message;
    print(status.message, "      ");
  }
  if (status.step == WizardStep::kReview && status.review_valid && !review_reported_) {
    review_reported_ = true;
    print(status.message, "      ");
  }
  if (status.step != WizardStep::kReview) review_reported_ = false;
  if (status.step == WizardStep::kRelease && status.initial_gravity_valid && message_.empty()) {
    message_ = status.message;
    print(status.message, "      ");
  }
  if (status.step == WizardStep::kExplore) {
    std::fflush(out_);  // the bar goes to stderr: keep the order of the lines
    if (!explore_progress_) explore_progress_ = std::make_unique<ProgressBar>("direction");
    char detail[128];
    const Eigen::Vector3d extent_m = status.explored_high_m - status.explored_low_m;
    std::snprintf(detail, sizeof detail, "%s, reach %.0f-%.0f mm, box %.0fx%.0fx%.0f mm",
                  toString(status.explorer_state), status.reach_min_m * 1e3,
                  status.reach_max_m * 1e3, extent_m.x() * 1e3, extent_m.y() * 1e3,
                  extent_m.z() * 1e3);
    explore_progress_->update(status.directions_probed, status.direction_count, detail);
  }
  if (status.step == WizardStep::kAutoCalibration) {
    std::fflush(out_);  // the bar goes to stderr: keep the order of the lines
    if (!progress_) progress_ = std::make_unique<ProgressBar>("vertex");
    char detail[96];
    if (status.calibrator_state == AutoCalibrator::Status::kEstimating &&
        std::isfinite(status.delta_m)) {
      std::snprintf(detail, sizeof detail, "#%d iter %d, delta %.3f mm", status.vertex,
                    status.iteration, status.delta_m * 1e3);
    } else {
      std::snprintf(detail, sizeof detail, "#%d %s", status.vertex,
                    toString(status.calibrator_state));
    }
    progress_total_ = status.vertices_to_visit;
    progress_->update(std::clamp(status.vertex_ordinal - 1, 0, status.vertices_to_visit),
                      status.vertices_to_visit, detail);
  }
  if (status.step == WizardStep::kVerify || status.step == WizardStep::kDone) {
    int finished = 0;
    for (const auto& result : status.verify) finished += result.finished ? 1 : 0;
    if (status.step == WizardStep::kVerify) {
      for (; verify_reported_ < finished; ++verify_reported_) {
        const VerifyResult& result = status.verify[static_cast<std::size_t>(verify_reported_)];
        std::fprintf(out_, "      release test at vertex #%d: drift %.2f mm in %.2f s\n",
                     result.vertex, result.drift_m * 1e3, result.duration_s);
      }
    }
  }
  if (!status.prompt.empty() && status.prompt != prompt_) {
    prompt_ = status.prompt;
    print(status.prompt, "    > ");
  }
  std::fflush(out_);
}

}  // namespace autograv::cli
