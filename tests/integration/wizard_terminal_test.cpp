// End to end: the real `autograv wizard` binary in a pseudo-terminal (tmux), driven by keys,
// judged by its screen and by the map it saves; and the same binary without a terminal.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <list>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "autograv/map/map_io.h"
#include "run_command.h"
#include "scratch_folder.h"

namespace autograv {
namespace {

const std::string kBinary = AUTOGRAV_BINARY_DIR "/demo/autograv";
const std::string kPtyRunner = AUTOGRAV_SOURCE_DIR "/tests/integration/wizard_pty_run.sh";

// A small grid on the Omni-like arm, with the paper's thresholds and the device-aware k0.
// Low friction: these tests drive the terminal front end, not the estimator's accuracy through
// friction, and count on every vertex converging.
const std::string kRunOptions =
    " --device sim:omni --auto-hand --grid 2 --side-mm 40 --seed 3 --friction low";
// The same on the Omega-like point mass, for the run `autograv calibrate` resumes.
const std::string kOmegaOptions =
    " --device sim:omega --auto-hand --grid 2 --side-mm 40 --seed 3 --friction low";

std::string quoted(const std::string& text) { return "'" + text + "'"; }

using testing::CommandResult;
using testing::runCommand;

/// A detached tmux session on a private server, running one command (no quotes in it) in a pane
/// of the given size through wizard_pty_run.sh: the command's exit code is printed as
/// "WIZARD_EXIT=<code>", then "TTY_icanon" when raw mode was undone ("TTY_RAW" when not), and
/// the pane stays open.
class TmuxSession {
 public:
  TmuxSession(const std::string& command, int columns, int rows)
      : socket_("autograv_wizard_test_" + std::to_string(::getpid()) + "_" +
                std::to_string(counter_++)) {
    const std::string script = "sh " + kPtyRunner + " " + command;
    started_ =
        std::system(("tmux -L " + socket_ + " new-session -d -s wizard -x " +
                     std::to_string(columns) + " -y " + std::to_string(rows) + " " + quoted(script))
                        .c_str()) == 0;
  }
  ~TmuxSession() { std::system(("tmux -L " + socket_ + " kill-server 2>/dev/null").c_str()); }

  bool started() const { return started_; }

  std::string capture() const {
    return runCommand("tmux -L " + socket_ + " capture-pane -p -t wizard").output;
  }

  /// tmux key names ("Enter", "C-c", "q").
  void sendKeys(const std::string& keys) const {
    std::system(("tmux -L " + socket_ + " send-keys -t wizard " + keys).c_str());
  }

  /// Polls the screen until it contains `text`; returns the last screen seen. The wait is a
  /// safeguard against a hung binary, not a measurement.
  bool waitFor(const std::string& text, std::string& screen, double max_wait_s = 60.0) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(max_wait_s);
    while (std::chrono::steady_clock::now() < end) {
      screen = capture();
      if (screen.find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return false;
  }

 private:
  static inline int counter_ = 0;
  std::string socket_;
  bool started_ = false;
};

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> result;
  std::istringstream stream(text);
  std::string line;
  while (std::getline(stream, line)) result.push_back(line);
  return result;
}

class WizardTerminalTest : public ::testing::Test {
 protected:
  /// A folder for the test, autograv-wizard-<name>-XXXXXX, kept if the test fails.
  std::string folder(const std::string& name) {
    return folders_.emplace_back("wizard-" + name).path().string();
  }

  std::list<testing::ScratchFolder> folders_;  // a list: a ScratchFolder cannot move

  void SetUp() override {
    // A build without the demo (AUTOGRAV_BUILD_DEMO=OFF, as the sanitizer builds are) has no
    // binary to drive; in a build with it, the test depends on the autograv target.
    if (!std::filesystem::exists(kBinary)) {
      GTEST_SKIP() << kBinary << " is not built (AUTOGRAV_BUILD_DEMO=OFF?)";
    }
    ASSERT_EQ(runCommand("tmux -V").exit_code, 0) << "tmux is needed for the pseudo-terminal";
  }
};

TEST_F(WizardTerminalTest, AutoHandRunInATerminalWaitsForEnterAtReviewAndSavesTheMap) {
  const std::string folder = this->folder("full");
  const std::string map_path = folder + "/map.json";
  TmuxSession session(kBinary + " wizard" + kRunOptions + " --speed 0 --out " + map_path, 100, 30);
  ASSERT_TRUE(session.started());
  std::string screen;
  ASSERT_TRUE(session.waitFor("Press Enter to save the map", screen)) << screen;
  EXPECT_NE(screen.find("autograv wizard - sim:omni"), std::string::npos) << screen;
  EXPECT_NE(screen.find("step 6/8"), std::string::npos) << screen;
  EXPECT_NE(screen.find("Step 6 of 8: Review the result"), std::string::npos) << screen;
  EXPECT_NE(screen.find("Converged: 8 of 8 vertices."), std::string::npos) << screen;
  EXPECT_NE(screen.find("Keys: Enter save | q quit"), std::string::npos) << screen;
  // Nothing is saved before the user says so; the checkpoint holds the vertices meanwhile.
  EXPECT_FALSE(std::filesystem::exists(map_path));
  EXPECT_EQ(loadMap(map_path + ".partial").convergedCount(), 8);

  session.sendKeys("Enter");
  ASSERT_TRUE(session.waitFor("TTY_", screen)) << screen;
  EXPECT_NE(screen.find("WIZARD_EXIT=0"), std::string::npos) << screen;
  EXPECT_NE(screen.find("Map saved to " + map_path + ": 8 of 8 vertices converged."),
            std::string::npos)
      << screen;
  EXPECT_NE(screen.find("Release test with compensation on"), std::string::npos) << screen;
  EXPECT_NE(screen.find("TTY_icanon"), std::string::npos) << "terminal left in raw mode:\n"
                                                          << screen;

  const GravityMap map = loadMap(map_path);
  EXPECT_EQ(map.grid().vertexCount(), 8);
  EXPECT_EQ(map.grid().resolution(), Eigen::Vector3i::Constant(2));
  EXPECT_TRUE(map.grid().size_m().isApprox(Eigen::Vector3d::Constant(0.040), 1e-12));
  EXPECT_TRUE(map.isComplete());
  EXPECT_EQ(map.metadata().device_model, "sim:omni");
  for (const auto& vertex : map.vertices()) {
    // The Omni-like arm's apparent gravity is about half a newton, mostly up.
    EXPECT_GT(vertex.gravity_n.z(), 0.3);
    EXPECT_LT(vertex.gravity_n.z(), 0.8);
  }
  EXPECT_FALSE(std::filesystem::exists(map_path + ".partial"));
}

TEST_F(WizardTerminalTest, CtrlCCheckpointsRestoresTheTerminalAndResumeFinishesTheRun) {
  const std::string folder = this->folder("interrupt");
  const std::string map_path = folder + "/map.json";
  const std::string partial = map_path + ".partial";
  {
    // Three times real time: slow enough to interrupt mid-grid.
    TmuxSession session(kBinary + " wizard" + kRunOptions + " --speed 3 --out " + map_path, 100,
                        30);
    ASSERT_TRUE(session.started());
    std::string screen;
    ASSERT_TRUE(session.waitFor("Checkpoint: 2 vertices", screen)) << screen;
    EXPECT_NE(screen.find("Step 5 of 8: Automatic calibration"), std::string::npos) << screen;
    EXPECT_NE(screen.find("ETA"), std::string::npos) << screen;
    session.sendKeys("C-c");
    ASSERT_TRUE(session.waitFor("TTY_", screen)) << screen;
    EXPECT_NE(screen.find("WIZARD_EXIT=2"), std::string::npos) << screen;
    EXPECT_NE(screen.find("--resume"), std::string::npos) << screen;
    EXPECT_NE(screen.find("TTY_icanon"), std::string::npos) << "terminal left in raw mode:\n"
                                                            << screen;
  }
  ASSERT_TRUE(std::filesystem::exists(partial));
  const GravityMap checkpoint = loadMap(partial);
  ASSERT_GE(checkpoint.convergedCount(), 2);
  ASSERT_LT(checkpoint.convergedCount(), 8);
  EXPECT_FALSE(std::filesystem::exists(map_path));

  // Resume without a terminal: plain lines, prompts answered, the finished vertices kept.
  const CommandResult resumed =
      runCommand(kBinary + " wizard" + kRunOptions + " --resume --out " + map_path);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resuming " + std::to_string(checkpoint.convergedCount()) +
                                " converged vertices"),
            std::string::npos)
      << resumed.output;
  EXPECT_NE(resumed.output.find("[8/8] Done"), std::string::npos) << resumed.output;
  EXPECT_EQ(resumed.output.find("\033["), std::string::npos) << "escape codes in plain output";
  const GravityMap map = loadMap(map_path);
  EXPECT_TRUE(map.isComplete());
  for (int i = 0; i < 8; ++i) {
    const VertexEstimate& before = checkpoint.vertices()[static_cast<std::size_t>(i)];
    if (before.outcome != VertexOutcome::kConverged) continue;
    const VertexEstimate& after = map.vertices()[static_cast<std::size_t>(i)];
    EXPECT_EQ(after.gravity_n, before.gravity_n) << "vertex " << i;  // exact: bit for bit
    EXPECT_EQ(after.iterations, before.iterations) << "vertex " << i;
    EXPECT_EQ(after.seconds, before.seconds) << "vertex " << i;
  }
}

TEST_F(WizardTerminalTest, ANarrowTerminalKeepsThePromptAndQuittingKeepsTheCheckpoint) {
  const std::string folder = this->folder("narrow");
  const std::string map_path = folder + "/m.json";
  TmuxSession session(kBinary + " wizard" + kOmegaOptions + " --speed 0 --out " + map_path, 40, 14);
  ASSERT_TRUE(session.started());
  std::string screen;
  ASSERT_TRUE(session.waitFor("> Press Enter to save", screen)) << screen;
  for (const auto& line : lines(screen)) {
    EXPECT_LT(line.size(), 40u) << "'" << line << "' overflows the 40 columns";
  }
  EXPECT_NE(screen.find("Review the result"), std::string::npos) << screen;
  session.sendKeys("q");
  ASSERT_TRUE(session.waitFor("TTY_", screen)) << screen;
  EXPECT_NE(screen.find("WIZARD_EXIT=2"), std::string::npos) << screen;
  EXPECT_FALSE(std::filesystem::exists(map_path));
  ASSERT_TRUE(std::filesystem::exists(map_path + ".partial"));
  const GravityMap checkpoint = loadMap(map_path + ".partial");
  EXPECT_EQ(checkpoint.convergedCount(), 8);

  // `autograv calibrate` resumes the wizard's checkpoint: nothing left to visit, it saves it.
  const CommandResult calibrate = runCommand(
      kBinary + " calibrate --device sim:omega --grid 2 --side-mm 40 --resume --out " + map_path);
  ASSERT_EQ(calibrate.exit_code, 0) << calibrate.output;
  const GravityMap map = loadMap(map_path);
  ASSERT_EQ(map.convergedCount(), 8);
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(map.vertices()[static_cast<std::size_t>(i)].gravity_n,
              checkpoint.vertices()[static_cast<std::size_t>(i)].gravity_n)
        << "vertex " << i;
  }
}

/// The keys that carry the simulated hand along the move the Centre step asks for, e.g.
/// "move 13 mm away from you, 15 mm right, 74 mm up" (5 mm per key press).
std::string keysForMove(const std::string& screen) {
  const std::size_t start = screen.find("(move ");
  if (start == std::string::npos) return "";
  const std::size_t end = screen.find(')', start);
  std::string words = screen.substr(start + 6, end - start - 6);
  std::replace(words.begin(), words.end(), '\n', ' ');
  std::istringstream stream(words);
  std::string keys;
  double millimetres = 0.0;
  std::string unit, direction;
  while (stream >> millimetres >> unit >> direction) {
    if (direction == "away" || direction == "toward") {
      std::string skip;
      stream >> skip >> skip;  // "from you," / "you,"
      if (direction == "toward") skip.clear();
    }
    while (!direction.empty() && (direction.back() == ',' || direction.back() == '.')) {
      direction.pop_back();
    }
    const char* key = direction == "away"     ? "Up"
                      : direction == "toward" ? "Down"
                      : direction == "left"   ? "Left"
                      : direction == "right"  ? "Right"
                      : direction == "up"     ? "PageUp"
                                              : "PageDown";
    for (int i = 0; i < static_cast<int>(std::lround(millimetres / 5.0)); ++i) {
      keys += std::string(" ") + key;
    }
  }
  return keys;
}

TEST_F(WizardTerminalTest, TheUserCarriesTheEndEffectorWithTheKeysAndLetsGo) {
  const std::string folder = this->folder("keys");
  const std::string map_path = folder + "/m.json";
  // No --auto-hand: the keys move the simulated hand. --speed 0 makes the waits short.
  TmuxSession session(kBinary +
                          " wizard --device sim:omega --grid 2 --side-mm 40 --speed 0 "
                          "--verify-points 1 --out " +
                          map_path,
                      100, 30);
  ASSERT_TRUE(session.started());
  std::string screen;
  ASSERT_TRUE(session.waitFor("Simulated hand: not holding", screen)) << screen;
  EXPECT_NE(screen.find("g grab/let go | arrows move | PgUp/PgDn up/down"), std::string::npos)
      << screen;
  ASSERT_TRUE(session.waitFor("Distance to the centre", screen)) << screen;
  session.sendKeys("g");
  ASSERT_TRUE(session.waitFor("Simulated hand: holding", screen)) << screen;
  // Follow the directions on the screen until it says the end-effector is close enough.
  const std::string close_enough = "Hold it still there and press Enter";
  for (int attempt = 0; attempt < 6 && screen.find(close_enough) == std::string::npos; ++attempt) {
    const std::string keys = keysForMove(screen);
    ASSERT_FALSE(keys.empty()) << screen;
    session.sendKeys(keys);
    session.waitFor(close_enough, screen, 2.0);
  }
  ASSERT_NE(screen.find(close_enough), std::string::npos) << screen;
  // Enter is refused while the hand still glides to its goal ("it was moving"): press it again
  // until the wizard takes it, as a user would.
  for (int attempt = 0; attempt < 20 && screen.find("Step 3 of 8") == std::string::npos;
       ++attempt) {
    session.sendKeys("Enter");
    session.waitFor("Step 3 of 8", screen, 1.0);
  }
  ASSERT_NE(screen.find("Step 3 of 8: Let go in the spring field"), std::string::npos) << screen;
  // Still holding once the field is on: the wizard asks to let go and waits.
  ASSERT_TRUE(session.waitFor("Let go of it completely", screen)) << screen;
  session.sendKeys("g");
  ASSERT_TRUE(session.waitFor("Press Enter to save the map", screen)) << screen;
  EXPECT_NE(screen.find("Simulated hand: not holding"), std::string::npos) << screen;
  session.sendKeys("Enter");
  ASSERT_TRUE(session.waitFor("TTY_", screen)) << screen;
  EXPECT_NE(screen.find("WIZARD_EXIT=0"), std::string::npos) << screen;
  EXPECT_EQ(loadMap(map_path).convergedCount(), 8);
}

TEST_F(WizardTerminalTest, AnInterruptedCalibrateRunIsFinishedByTheWizard) {
  const std::string folder = this->folder("calibrate");
  const std::string map_path = folder + "/m.json";
  const std::string partial = map_path + ".partial";
  // 64 vertices: time enough to interrupt after the first few.
  const std::string grid = " --device sim:omega --grid 4 --side-mm 40";
  TmuxSession session(kBinary + " calibrate" + grid + " --out " + map_path, 100, 30);
  ASSERT_TRUE(session.started());
  // Interrupt `autograv calibrate` once its checkpoint holds a couple of vertices.
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < give_up) {
    if (std::filesystem::exists(partial) && loadMap(partial).convergedCount() >= 2) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  session.sendKeys("C-c");
  std::string screen;
  ASSERT_TRUE(session.waitFor("TTY_", screen)) << screen;
  EXPECT_NE(screen.find("WIZARD_EXIT=2"), std::string::npos) << screen;
  const GravityMap checkpoint = loadMap(partial);
  ASSERT_GE(checkpoint.convergedCount(), 2);
  ASSERT_LT(checkpoint.convergedCount(), 64);

  const CommandResult resumed =
      runCommand(kBinary + " wizard" + grid + " --auto-hand --resume --out " + map_path);
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  const GravityMap map = loadMap(map_path);
  EXPECT_TRUE(map.isComplete());
  for (int i = 0; i < 64; ++i) {
    const VertexEstimate& before = checkpoint.vertices()[static_cast<std::size_t>(i)];
    if (before.outcome != VertexOutcome::kConverged) continue;
    EXPECT_EQ(map.vertices()[static_cast<std::size_t>(i)].gravity_n, before.gravity_n)
        << "vertex " << i;
  }
}

TEST_F(WizardTerminalTest, WithoutATerminalItNeedsTheAutoHand) {
  const std::string folder = this->folder("plain");
  const CommandResult refused =
      runCommand(kBinary + " wizard --device sim:omni --out " + folder + "/m.json");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("add --auto-hand"), std::string::npos) << refused.output;

  const CommandResult run = runCommand(kBinary + " wizard" + kRunOptions + " --out " + folder +
                                       "/m.json --report " + folder + "/report.json");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  // One line per step, in order.
  std::size_t at = 0;
  for (const char* step :
       {"[1/8] Check", "[2/8] Bring the end-effector to the centre", "[3/8] Let go",
        "Initial estimate (eq. 7)", "[4/8] Explore the workspace", "explored: reach",
        "[5/8] Automatic calibration", "[6/8] Review the result", "[7/8] Save the map",
        "[8/8] Verify", "[8/8] Done"}) {
    const std::size_t found = run.output.find(step, at);
    ASSERT_NE(found, std::string::npos) << "'" << step << "' missing or out of order:\n"
                                        << run.output;
    at = found;
  }
  EXPECT_TRUE(std::filesystem::exists(folder + "/report.json"));
  EXPECT_EQ(loadMap(folder + "/m.json").convergedCount(), 8);
  // The saved map's measurements judged against one another, on screen and in the report.
  EXPECT_NE(run.output.find("leave-one-out"), std::string::npos) << run.output;
  std::ifstream report_file(folder + "/report.json");
  const nlohmann::json report = nlohmann::json::parse(report_file);
  EXPECT_TRUE(report.contains("leave_one_out_median_rel") ||
              report.contains("leave_one_out_unavailable"))
      << report.dump(2);
}

// A checkpoint or map with a number beyond the range of double is bad input like any other: the
// programs say which file and field, and never "unexpected error".
TEST_F(WizardTerminalTest, ANumberBeyondDoubleRangeIsAnErrorNamingFileAndField) {
  const std::string folder = this->folder("huge");
  const WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.04, 2);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  MapMetadata metadata;
  metadata.device_model = "sim:omega";
  std::string text = mapToJson(GravityMap(grid, vertices, metadata));
  const std::string size = "\"size_m\": [\n      0.04";
  ASSERT_NE(text.find(size), std::string::npos) << text;
  text.replace(text.find(size), size.size(), "\"size_m\": [\n      1e999");
  const std::string map_path = folder + "/m.json";
  for (const std::string& path : {map_path, map_path + ".partial"}) {
    std::ofstream(path) << text;
  }

  for (const std::string& command :
       {" inspect " + map_path,
        " calibrate --device sim:omega --grid 2 --side-mm 40 --resume --out " + map_path,
        " wizard" + kOmegaOptions + " --resume --out " + map_path}) {
    const CommandResult run = runCommand(kBinary + command);
    EXPECT_EQ(run.exit_code, 2) << command << "\n" << run.output;
    EXPECT_EQ(run.output.find("unexpected error"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("field /grid/size_m/0"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("beyond the range of double"), std::string::npos) << run.output;
  }
}

}  // namespace
}  // namespace autograv
