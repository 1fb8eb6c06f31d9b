// A device that stops answering mid-vertex, mid-move and mid-verify, and bursts of NaN from the
// driver: the run stops (or rides the burst out), the force goes to zero, and every vertex
// finished before is kept bit for bit, on disk and through a resume.
#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <unistd.h>

#include "autograv/device/forwarding_device.h"
#include "autograv/map/map_io.h"
#include "autograv/sim/procedures.h"
#include "autograv/sim/scripted_wizard_user.h"
#include "autograv/sim/simulated_device.h"
#include "autograv/wizard/calibration_wizard.h"
#include "fault_test_support.h"
#include "subprocess.h"

namespace autograv {
namespace {

namespace fs = std::filesystem;
using testing::convergedCount;
using testing::expectKept;
using testing::TestFolder;

/// A calibration of a 2x2x2 grid on sim:omega whose device misbehaves when `when` first holds;
/// finished vertices are checkpointed to a file as `autograv calibrate` does.
struct FaultyRun {
  sim::CalibrationRunResult result;
  std::vector<VertexEstimate> checkpoint;  ///< What the checkpoint file holds afterwards.
  int faulted_vertex = -1;                 ///< Vertex being approached or estimated at the fault.
  AutoCalibrator::Status state_at_fault = AutoCalibrator::Status::kIdle;
  Eigen::Vector3d applied_after_n = Eigen::Vector3d::Constant(NAN);  ///< Unit: [N]
};

sim::CalibrationRunOptions smallGrid(const sim::SimulatedDevice& device) {
  sim::CalibrationRunOptions options;
  options.grid_center_m = device.workspaceCenter_m();
  options.grid_size_m = Eigen::Vector3d::Constant(0.04);
  options.grid_resolution = Eigen::Vector3i::Constant(2);
  options.redo_passes = 0;
  return options;
}

/// Runs the grid; `script` is called every servo tick with the calibrator and the device, and
/// may inject or heal faults; the first tick on which it returns true (it injected) is recorded.
FaultyRun runWithScript(
    const TestFolder& folder,
    const std::function<bool(const AutoCalibrator&, sim::SimulatedDevice&)>& script) {
  auto device = sim::makeSimulatedDevice("sim:omega", 7);
  EXPECT_TRUE(device->open());
  sim::CalibrationRunOptions options = smallGrid(*device);
  const std::string checkpoint = folder.file("map.json.partial");
  MapMetadata metadata;
  metadata.device_model = "sim:omega";
  FaultyRun run;
  bool injected = false;
  options.progress_period_s = 0.0;  // the script sees every tick
  options.on_progress = [&](const AutoCalibrator& calibrator) {
    if (script(calibrator, *device) && !injected) {
      injected = true;
      run.faulted_vertex = calibrator.currentVertex();
      run.state_at_fault = calibrator.state();
    }
  };
  options.on_vertex_finished = [&](const AutoCalibrator& calibrator, int) {
    saveMap(calibrator.makeMap(metadata), checkpoint);
  };
  run.result = sim::runSimulatedCalibration(*device, options);
  run.applied_after_n = device->appliedForce_n();
  if (fs::exists(checkpoint)) run.checkpoint = loadMap(checkpoint).vertices();
  return run;
}

/// Resumes from the checkpoint on a fresh device (another seed: another process) and expects the
/// whole grid, with every checkpointed vertex kept.
void expectResumeFinishesKeeping(const std::vector<VertexEstimate>& checkpoint) {
  auto device = sim::makeSimulatedDevice("sim:omega", 8);
  ASSERT_TRUE(device->open());
  sim::CalibrationRunOptions options = smallGrid(*device);
  options.redo_passes = 1;
  options.resume_from = checkpoint;
  const sim::CalibrationRunResult resumed = sim::runSimulatedCalibration(*device, options);
  EXPECT_EQ(resumed.status, AutoCalibrator::Status::kFinished);
  EXPECT_EQ(convergedCount(resumed.vertices), 8);
  expectKept(checkpoint, resumed.vertices, "the resumed run");
}

/// The run stopped on a device fault with zero force, and the checkpoint holds every vertex the
/// run had finished, identical to the run's own copy.
void expectStoppedKeepingTheFinishedVertices(const FaultyRun& run) {
  EXPECT_EQ(run.result.status, AutoCalibrator::Status::kDeviceFault);
  EXPECT_EQ(run.applied_after_n, Eigen::Vector3d::Zero());
  const int finished = convergedCount(run.result.vertices);
  EXPECT_GE(finished, 3);
  EXPECT_LT(finished, 8);
  EXPECT_EQ(convergedCount(run.checkpoint), finished);
  expectKept(run.result.vertices, run.checkpoint, "the checkpoint");
}

bool afterThreeVertices(const AutoCalibrator& calibrator) {
  return convergedCount(calibrator.vertices()) >= 3;
}

TEST(DeviceFaultTest, StopsAnsweringMidVertex) {
  const TestFolder folder;
  const FaultyRun run = runWithScript(folder, [](const AutoCalibrator& c, sim::SimulatedDevice& d) {
    if (!afterThreeVertices(c) || c.state() != AutoCalibrator::Status::kEstimating ||
        c.iteration() < 2) {
      return false;
    }
    d.injectFault(sim::DeviceFault::kStopsAnswering);
    return true;
  });
  ASSERT_EQ(run.state_at_fault, AutoCalibrator::Status::kEstimating);
  expectStoppedKeepingTheFinishedVertices(run);
  // The interrupted vertex says what happened; it is not passed off as converged.
  EXPECT_EQ(run.result.vertices[static_cast<std::size_t>(run.faulted_vertex)].outcome,
            VertexOutcome::kDeviceFault);
  expectResumeFinishesKeeping(run.checkpoint);
}

TEST(DeviceFaultTest, StopsAnsweringMidMove) {
  const TestFolder folder;
  const FaultyRun run = runWithScript(folder, [](const AutoCalibrator& c, sim::SimulatedDevice& d) {
    if (!afterThreeVertices(c) || c.state() != AutoCalibrator::Status::kMoving) return false;
    d.injectFault(sim::DeviceFault::kStopsAnswering);
    return true;
  });
  ASSERT_EQ(run.state_at_fault, AutoCalibrator::Status::kMoving);
  expectStoppedKeepingTheFinishedVertices(run);
  // The vertex it was travelling to was never started.
  EXPECT_EQ(run.result.vertices[static_cast<std::size_t>(run.faulted_vertex)].outcome,
            VertexOutcome::kPending);
  expectResumeFinishesKeeping(run.checkpoint);
}

/// Injects NaN positions for `ticks` servo ticks in the middle of the fourth vertex's estimation.
FaultyRun runWithNanBurst(const TestFolder& folder, int ticks) {
  int left = -1;
  return runWithScript(folder, [&left, ticks](const AutoCalibrator& c, sim::SimulatedDevice& d) {
    if (left > 0 && --left == 0) d.injectFault(sim::DeviceFault::kNone);
    if (left >= 0 || !afterThreeVertices(c) || c.state() != AutoCalibrator::Status::kEstimating ||
        c.iteration() < 2) {
      return false;
    }
    d.injectFault(sim::DeviceFault::kNanPosition);
    left = ticks;
    return true;
  });
}

TEST(DeviceFaultTest, AShortNanBurstIsRiddenOutAndTheGridFinishes) {
  // 10 ms of NaN: the calibrator holds the last force and goes on once the driver heals.
  const TestFolder folder;
  const FaultyRun run = runWithNanBurst(folder, 10);
  ASSERT_EQ(run.state_at_fault, AutoCalibrator::Status::kEstimating);
  EXPECT_EQ(run.result.status, AutoCalibrator::Status::kFinished);
  EXPECT_EQ(convergedCount(run.result.vertices), 8);
  for (const VertexEstimate& v : run.result.vertices) EXPECT_TRUE(v.gravity_n.allFinite());
  // The estimate at the vertex of the burst is as good as its neighbours'.
  auto device = sim::makeSimulatedDevice("sim:omega", 7);
  const WorkspaceGrid grid(device->workspaceCenter_m(), 0.04, 2);
  const Eigen::Vector3d truth = device->trueGravity(grid.vertexPosition(run.faulted_vertex));
  const VertexEstimate& hit = run.result.vertices[static_cast<std::size_t>(run.faulted_vertex)];
  EXPECT_LT((hit.gravity_n - truth).norm(), 0.03 * truth.norm());
}

TEST(DeviceFaultTest, ALongNanBurstIsADeviceFaultThatKeepsTheFinishedVertices) {
  // 200 ms of NaN: more than the 20 invalid samples a calibration tolerates.
  const TestFolder folder;
  const FaultyRun run = runWithNanBurst(folder, 200);
  ASSERT_EQ(run.state_at_fault, AutoCalibrator::Status::kEstimating);
  expectStoppedKeepingTheFinishedVertices(run);
  EXPECT_EQ(run.result.vertices[static_cast<std::size_t>(run.faulted_vertex)].outcome,
            VertexOutcome::kDeviceFault);
  expectResumeFinishesKeeping(run.checkpoint);
}

// --- the calibration wizard ---------------------------------------------------------------------

/// Forwards to a simulated device, except that every setForce fails once refuse() was called: a
/// driver whose force writes fail (a USB link that drops output reports).
class RefusingForces final : public ForwardingDevice {
 public:
  explicit RefusingForces(std::shared_ptr<sim::SimulatedDevice> inner)
      : ForwardingDevice(std::move(inner)) {}
  void refuse() { refusing_ = true; }
  bool setForce(const Eigen::Vector3d& force_n) override {
    // A refused write leaves the actuators as a driver that lost the link does: unpowered.
    return !refusing_ ? ForwardingDevice::setForce(force_n)
                      : (ForwardingDevice::setForce(Eigen::Vector3d::Zero()), false);
  }

 private:
  bool refusing_ = false;
};

/// The wizard on a 2x2x2 grid of sim:omega, driven frame by frame with the scripted user of
/// `autograv wizard --auto-hand`.
struct WizardRun {
  std::shared_ptr<sim::SimulatedDevice> simulated = sim::makeSimulatedDevice("sim:omega", 1);
  std::shared_ptr<RefusingForces> device = std::make_shared<RefusingForces>(simulated);
  std::unique_ptr<CalibrationWizard> wizard;
  sim::ScriptedWizardUser hand{*simulated};

  explicit WizardRun(const std::string& map_path) {
    WizardConfig config;
    config.centre_m = simulated->workspaceCenter_m();
    config.advanced.box_size_m = Eigen::Vector3d::Constant(0.04);
    config.grid_resolution = Eigen::Vector3i::Constant(2);
    config.map_path = map_path;
    config.verify_points = 3;
    config.advanced.explore = false;  // the faults of the grid run on this box
    wizard = std::make_unique<CalibrationWizard>(device, config);
  }

  /// One UI frame: the scripted user, 20 servo ticks, the service.
  void frame() {
    if (wizard->step() == WizardStep::kCentre || wizard->step() == WizardStep::kRelease ||
        simulated->hand().holding()) {
      hand.update(wizard->status());
    }
    for (int i = 0; i < 20; ++i) {
      wizard->servoTick();
      simulated->advance(1e-3);
    }
    wizard->service();
  }

  /// Frames until `done` or `max_s` of simulated time; whether `done` came.
  bool runUntil(const std::function<bool()>& done, double max_s) {
    const double end_s = simulated->time_s() + max_s;
    while (!done() && simulated->time_s() < end_s) frame();
    return done();
  }
  bool runUntilStep(WizardStep step, double max_s) {
    return runUntil([&] { return wizard->step() == step; }, max_s);
  }
};

TEST(DeviceFaultTest, StopsAnsweringMidVerifyKeepsTheSavedMapAndSaysSo) {
  const TestFolder folder;
  const std::string path = folder.file("map.json");
  WizardRun run(path);
  ASSERT_TRUE(run.runUntilStep(WizardStep::kReview, 200.0)) << run.wizard->status().message;
  run.wizard->post(WizardEvent::kConfirm);
  // In the middle of the second release test.
  ASSERT_TRUE(run.runUntil(
      [&] {
        const WizardStatus status = run.wizard->status();
        return status.step == WizardStep::kVerify && status.verify_index == 1;
      },
      30.0))
      << run.wizard->status().message;
  const std::string saved = testing::readFile(path);
  ASSERT_FALSE(saved.empty());
  run.simulated->injectFault(sim::DeviceFault::kStopsAnswering);
  ASSERT_TRUE(run.runUntilStep(WizardStep::kFault, 1.0));
  run.frame();
  EXPECT_TRUE(run.wizard->finished());
  const WizardStatus status = run.wizard->status();
  EXPECT_NE(status.message.find("stopped answering"), std::string::npos) << status.message;
  EXPECT_NE(status.message.find("The map had been saved to " + path), std::string::npos)
      << status.message;
  EXPECT_EQ(testing::readFile(path), saved) << "the saved map changed";
  EXPECT_EQ(loadMap(path).convergedCount(), 8);
  EXPECT_EQ(run.simulated->appliedForce_n(), Eigen::Vector3d::Zero());
}

TEST(DeviceFaultTest, ForcesTheDeviceRefusesMidGridAreAFaultThatKeepsTheFinishedVertices) {
  const TestFolder folder;
  const std::string path = folder.file("map.json");
  WizardRun run(path);
  ASSERT_TRUE(run.runUntil([&] { return run.wizard->status().converged >= 3; }, 200.0))
      << run.wizard->status().message;
  run.device->refuse();
  ASSERT_TRUE(run.runUntilStep(WizardStep::kFault, 1.0)) << run.wizard->status().message;
  run.frame();
  EXPECT_TRUE(run.wizard->finished());
  const WizardStatus status = run.wizard->status();
  EXPECT_NE(status.message.find("refused the forces"), std::string::npos) << status.message;
  EXPECT_NE(status.message.find("WizardConfig::resume = true"), std::string::npos)
      << status.message;
  const std::vector<VertexEstimate> finished = run.wizard->vertices();
  const std::vector<VertexEstimate> on_disk = loadMap(path + ".partial").vertices();
  EXPECT_GE(convergedCount(on_disk), 3);
  EXPECT_EQ(convergedCount(on_disk), convergedCount(finished));
  expectKept(finished, on_disk, path + ".partial");
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
}  // namespace autograv
