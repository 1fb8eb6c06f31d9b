// calibrate(): the wizard run to its end in one call, on the own-device example's driver (a
// HapticDevice with no autograv::sim behind it) and its simulated user.
#include "autograv/wizard/calibrate.h"

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "autograv/error.h"
#include "autograv/map/map_io.h"
#include "point_mass_device.h"
#include "scratch_folder.h"
#include "simulated_user.h"

namespace autograv {
namespace {

/// The example's quick run: a 3x3x3 grid fitted to the explored workspace, the servo loop at 200
/// times real time (the point mass runs in simulated time): about a second of simulated time per
/// frame, so that the frames see every step.
WizardConfig quickConfig(const std::string& map_path) {
  WizardConfig config;
  config.map_path = map_path;
  config.grid_resolution = Eigen::Vector3i::Constant(3);
  config.verify_points = 1;
  return config;
}

CalibrateOptions quickOptions(example::SimulatedUser& user) {
  CalibrateOptions options;
  options.speed = 200.0;
  options.frame_s = 0.005;
  options.on_status = [&user](const WizardStatus& status, CalibrationWizard&) { user.act(status); };
  return options;
}

TEST(CalibrateTest, CalibratesADeviceOfItsOwnToASavedMapInOneCall) {
  const testing::ScratchFolder folder("calibrate");
  const std::string path = folder.file("map.json");
  auto device = std::make_shared<example::PointMassDevice>();
  example::SimulatedUser user(*device);
  CalibrateOptions options = quickOptions(user);
  std::vector<std::string> lines;
  options.progress_period_s = 0.0;  // every frame
  options.on_progress = [&](const WizardStatus& status) { lines.push_back(progressLine(status)); };

  const CalibrateResult result = calibrate(device, quickConfig(path), options);
  ASSERT_TRUE(result.ok()) << result.status.message;
  EXPECT_EQ(result.status.step, WizardStep::kDone);
  ASSERT_TRUE(result.map);
  EXPECT_TRUE(result.map->isComplete());
  EXPECT_EQ(loadMap(path).vertices().size(), 27u);
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));  // the map supersedes it
  EXPECT_FALSE(result.servo_priority);                       // only a real-time loop asks
  EXPECT_GT(result.status.time_s, 10.0);                     // of simulated time
  // The map cancels the point mass's own gravity, where the hand goes.
  for (const Eigen::Vector3d& point :
       {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.02, -0.03, 0.01)}) {
    const Eigen::Vector3d residual_n =
        result.map->gravityAt(point) + example::PointMassDevice::gravityForce_n(point);
    EXPECT_LT(residual_n.norm(), 0.01) << point.transpose();
  }
  // What the driver was sent, known without a simulator.
  EXPECT_GT(result.status.force.peak_n, 0.5);
  EXPECT_EQ(result.status.force.limit_n, device->specifications().max_linear_force_n);
  // The progress: the steps in order, the long ones seen (a step shorter than a frame, as Save,
  // may pass between two), the last one Done. Review goes back to the calibration once, for the
  // redo (here: the first points measured again to see the motors warm).
  ASSERT_FALSE(lines.empty());
  EXPECT_NE(lines.back().find("[8/8] Done"), std::string::npos) << lines.back();
  int last_step = 0;
  int redos = 0;
  std::vector<int> seen;
  for (const std::string& line : lines) {
    ASSERT_EQ(line.rfind("[", 0), 0u) << line;
    const int step = line[1] - '0';
    if (step == 5 && last_step == 6) {
      ++redos;
    } else {
      EXPECT_GE(step, last_step) << line;
    }
    if (step != last_step) seen.push_back(step);
    last_step = step;
  }
  EXPECT_LE(redos, 1);
  for (const int step : {2, 4, 5, 8}) {
    EXPECT_NE(std::find(seen.begin(), seen.end(), step), seen.end()) << "step " << step;
  }
  EXPECT_FALSE(device->handHolding());
}

TEST(CalibrateTest, GivesUpAtCheckWithTheReasonWhenNobodyCanAnswer) {
  // Speed 1, as on a real device: the servo thread paces itself on the wall clock and asks for
  // real-time priority before the first tick.
  auto device = std::make_shared<example::PointMassDevice>();
  const testing::ScratchFolder folder("calibrate");
  WizardConfig config = quickConfig(folder.file("no such folder/map.json"));
  const CalibrateResult result = calibrate(device, config);
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(result.status.step, WizardStep::kCheck);
  EXPECT_EQ(result.status.check_issue, CheckIssue::kSettings);
  EXPECT_NE(result.status.message.find("WizardConfig::map_path"), std::string::npos)
      << result.status.message;
  EXPECT_FALSE(result.map);
  EXPECT_TRUE(result.servo_priority);
}

TEST(CalibrateTest, AnEarlierCheckpointIsNeitherReplacedNorResumedUnasked) {
  const testing::ScratchFolder folder("calibrate");
  const std::string path = folder.file("earlier.json");
  auto device = std::make_shared<example::PointMassDevice>();
  example::SimulatedUser user(*device);
  // A run stopped during the grid leaves its checkpoint.
  std::atomic<bool> stop{false};
  CalibrateOptions options = quickOptions(user);
  options.stop_requested = &stop;
  options.on_status = [&](const WizardStatus& status, CalibrationWizard&) {
    user.act(status);
    if (status.step == WizardStep::kAutoCalibration && status.converged >= 2) stop = true;
  };
  const CalibrateResult stopped = calibrate(device, quickConfig(path), options);
  EXPECT_EQ(stopped.status.step, WizardStep::kAborted);
  EXPECT_FALSE(stopped.ok());
  ASSERT_TRUE(std::filesystem::exists(path + ".partial"));
  const auto checkpoint_time = std::filesystem::last_write_time(path + ".partial");

  // The next run stops at Check, saying what to do; the checkpoint is untouched.
  auto again = std::make_shared<example::PointMassDevice>();
  example::SimulatedUser user_again(*again);
  const CalibrateResult refused = calibrate(again, quickConfig(path), quickOptions(user_again));
  EXPECT_EQ(refused.status.step, WizardStep::kCheck);
  EXPECT_EQ(refused.status.check_issue, CheckIssue::kEarlierCheckpoint);
  EXPECT_NE(refused.status.prompt.find("WizardConfig::resume = true"), std::string::npos);
  EXPECT_EQ(std::filesystem::last_write_time(path + ".partial"), checkpoint_time);

  // Resumed, it keeps the finished vertices and ends with the map.
  WizardConfig resume = quickConfig(path);
  resume.resume = true;
  auto third = std::make_shared<example::PointMassDevice>();
  example::SimulatedUser user_third(*third);
  const CalibrateResult resumed = calibrate(third, resume, quickOptions(user_third));
  ASSERT_TRUE(resumed.ok()) << resumed.status.message;
  EXPECT_GE(resumed.status.review.restored, 2);
}

TEST(CalibrateTest, AsFastAsTheProcessorAllows) {
  const testing::ScratchFolder folder("calibrate");
  const std::string path = folder.file("fast.json");
  auto device = std::make_shared<example::PointMassDevice>();
  example::SimulatedUser user(*device);
  CalibrateOptions options = quickOptions(user);
  options.speed = 0.0;
  const CalibrateResult result = calibrate(device, quickConfig(path), options);
  EXPECT_TRUE(result.ok()) << result.status.message;
}

TEST(CalibrateTest, RefusesOptionsItCannotUseBeforeAnythingMoves) {
  auto device = std::make_shared<example::PointMassDevice>();
  const testing::ScratchFolder folder("calibrate");
  const WizardConfig config = quickConfig(folder.file("refused.json"));
  const auto refusal = [&](const CalibrateOptions& options) {
    try {
      calibrate(device, config, options);
    } catch (const Error& error) {
      return std::string(error.what());
    }
    return std::string("(nothing was thrown)");
  };
  CalibrateOptions options;
  options.speed = -1.0;
  EXPECT_NE(refusal(options).find("CalibrateOptions::speed"), std::string::npos);
  options = CalibrateOptions{};
  options.frame_s = 0.0;
  EXPECT_NE(refusal(options).find("CalibrateOptions::frame_s"), std::string::npos);
  // The wizard's own refusals come through as they are.
  WizardConfig unused = config;
  unused.verify_points = 0;
  unused.advanced.verify_release_s = 1.0;
  EXPECT_THROW(calibrate(device, unused), Error);
  EXPECT_FALSE(device->handHolding());
}

TEST(CalibrateTest, AProgressLineIsTheStepTheFirstLineAndThePrompt) {
  WizardStatus status;
  status.step = WizardStep::kAutoCalibration;
  status.step_number = 5;
  status.title = "Automatic calibration";
  status.message = "Vertex 3 of 27\nConverged 2 of 27";
  status.prompt = "p pauses";
  EXPECT_EQ(progressLine(status), "[5/8] Automatic calibration: Vertex 3 of 27 > p pauses");
  status.step = WizardStep::kAborted;
  status.step_number = 0;
  status.title = "Stopped";
  status.message = "Stopped by you.";
  status.prompt.clear();
  EXPECT_EQ(progressLine(status), "Stopped: Stopped by you.");
}

}  // namespace
}  // namespace autograv
