#pragma once

// What `autograv wizard` prints: a full screen redrawn in place on a terminal, or plain lines
// (one per change) when standard output is a file or a pipe.

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "autograv/wizard/calibration_wizard.h"
#include "cli_support.h"

namespace autograv::cli {

/// What the front end adds to the wizard's status on screen.
struct ScreenContext {
  std::string device_name;
  /// The user's hand is simulated (a sim: device).
  bool simulated_hand = true;
  /// The simulated hand acts by itself (--auto-hand).
  bool auto_hand = false;
  bool hand_holding = false;
  Eigen::Vector3d hand_target_m = Eigen::Vector3d::Zero();  ///< Unit: [m]
  /// A line for the front end's own news (e.g. "Stopping: writing the checkpoint...").
  std::string notice;
};

/// Splits `text` at its newlines and wraps each line at word boundaries to `columns`;
/// continuation lines start with `indent`. Words longer than a line are cut.
std::vector<std::string> wrapText(const std::string& text, int columns,
                                  const std::string& indent = "  ");

/// "[#####.....]" of `width` characters in all (brackets included), `fraction` in [0, 1].
std::string progressBar(double fraction, int width);

/// The whole screen, at most `rows` lines of fewer than `columns` characters: when the terminal
/// is small, blank lines, the summary and then the end of the message give way first, so the
/// step, its live numbers and the prompt stay visible.
std::vector<std::string> renderScreen(const WizardStatus& status, const ScreenContext& context,
                                      int columns, int rows);

/// Draws screens on a terminal: cursor home, each line cleared to its end, the rest erased.
/// Redraws only when the text changed.
class TerminalScreen {
 public:
  void draw(const std::vector<std::string>& lines);

 private:
  std::vector<std::string> last_;
};

/// Plain-line output for a log or a pipe: a line when the step, the prompt or a result changes,
/// never the same text twice; the calibration's progress goes to the ProgressBar (stderr).
class PlainLog {
 public:
  explicit PlainLog(std::FILE* out) : out_(out) {}
  void update(const WizardStatus& status);

 private:
  void print(const std::string& text, const std::string& indent);

  std::FILE* out_;
  bool started_ = false;
  WizardStep step_ = WizardStep::kCheck;
  std::string prompt_;
  std::string message_;
  std::unique_ptr<ProgressBar> progress_;
  std::unique_ptr<ProgressBar> explore_progress_;
  int progress_total_ = 0;
  int verify_reported_ = 0;
  bool review_reported_ = false;
};

}  // namespace autograv::cli
