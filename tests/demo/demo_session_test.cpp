// The demo's servo loop on simulated time: the decorator between the simulated device and the
// application, the hand, compensation on and off, and a servo tick that allocates nothing.
#include "demo_session.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "autograv/devices/device_registry.h"
#include "autograv/error.h"
#include "autograv/estimation/workspace_explorer.h"
#include "autograv/map/map_io.h"
#include "autograv/map/measurement_plan.h"

#include "allocation_counter.h"
#include "autograv/sim/simulated_device.h"
#include "scratch_folder.h"

namespace autograv::demo {
namespace {

/// A map of the device's own ground truth on its default grid: what a perfect calibration gives.
std::shared_ptr<const GravityMap> groundTruthMap(DemoSession& session) {
  const WorkspaceGrid grid = session.calibrationGrid();
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (int i = 0; i < grid.vertexCount(); ++i) {
    vertices[static_cast<std::size_t>(i)].gravity_n =
        session.simulation().trueGravity(grid.vertexPosition(i));
    vertices[static_cast<std::size_t>(i)].outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = session.simulation().specifications().model_name;
  return std::make_shared<const GravityMap>(grid, std::move(vertices), metadata);
}

constexpr std::int64_t kTicksPerSecond = 1000;

/// Runs `seconds` of servo time on the calling thread, letting the UI side move a calibration on
/// every 10 ms as a frame loop would. Returns the messages it gave, one per line.
std::string run(DemoSession& session, double seconds) {
  const auto frames = static_cast<std::int64_t>(seconds * 100.0);
  std::string messages;
  for (std::int64_t i = 0; i < frames; ++i) {
    session.runTicks(kTicksPerSecond / 100);
    const std::string message = session.updateCalibration();
    if (!message.empty()) std::printf("  session: %s\n", message.c_str());
    if (!message.empty()) messages += message + "\n";
  }
  return messages;
}

/// Lifts the end-effector 2 cm above the workspace centre with the hand (script positions are
/// absolute) and lets go after the compensation has ramped in.
HandScript liftAndRelease(const DemoSession& session) {
  const Eigen::Vector3d lifted_m =
      session.simulation().workspaceCenter_m() + Eigen::Vector3d(0.0, 0.0, 0.02);
  char move[96];
  std::snprintf(move, sizeof move, "at 0.05 move %.6f %.6f %.6f 0.1\n", lifted_m.x(), lifted_m.y(),
                lifted_m.z());
  return HandScript::parse(std::string("at 0.0 grab\n") + move + "at 0.8 release\n", "lift");
}

/// Publishes the ground-truth map, plays liftAndRelease (kept in `script`) and runs two seconds.
const ServoSnapshot& liftReleaseAndRun(DemoSession& session, HandScript& script) {
  session.publishMap(groundTruthMap(session));
  script = liftAndRelease(session);
  session.setScript(&script);
  run(session, 2.0);
  return session.snapshot();
}

TEST(DemoSessionTest, StartsHeldAtTheWorkspaceCentre) {
  DemoSession session(SessionOptions{});
  const ServoSnapshot& s = session.snapshot();
  EXPECT_TRUE(s.hand_holding);
  EXPECT_TRUE(s.position_m.isApprox(session.simulation().workspaceCenter_m(), 1e-9));
  EXPECT_EQ(s.mode, ServoMode::kApplication);
}

TEST(DemoSessionTest, ReleasedWithCompensationItFloats) {
  DemoSession session(SessionOptions{});
  HandScript script;
  const ServoSnapshot& s = liftReleaseAndRun(session, script);
  ASSERT_TRUE(s.released);
  EXPECT_NEAR(s.since_release_s, 1.2, 1e-9);
  EXPECT_LT(s.drift_m, 0.001) << "drift " << s.drift_m * 1e3 << " mm";
  EXPECT_NEAR(s.position_m.z() - session.simulation().workspaceCenter_m().z(), 0.02, 0.002);
  EXPECT_DOUBLE_EQ(s.compensation_level, 1.0);
  EXPECT_EQ(s.faults, 0u);
  // The force sent is the compensation: the apparent gravity where it floats.
  const Eigen::Vector3d truth = session.simulation().trueGravity(s.position_m);
  EXPECT_LT((s.force_sent_n - truth).norm(), 0.02 * truth.norm());
}

TEST(DemoSessionTest, ReleasedWithoutCompensationItFalls) {
  SessionOptions options;
  options.compensation.enabled = false;
  DemoSession session(options);
  HandScript script;
  const ServoSnapshot& s = liftReleaseAndRun(session, script);
  ASSERT_TRUE(s.released);
  EXPECT_GT(s.drift_m, 0.03);
  EXPECT_LT(s.position_m.z(), session.simulation().workspaceCenter_m().z() - 0.02);
  EXPECT_DOUBLE_EQ(s.compensation_level, 0.0);
}

TEST(DemoSessionTest, ScriptSwitchesCompensationWithARamp) {
  SessionOptions options;
  options.compensation.ramp_duration_s = 0.5;
  DemoSession session(options);
  session.publishMap(groundTruthMap(session));
  const HandScript script = HandScript::parse("at 1.0 compensation off\n", "toggle");
  session.setScript(&script);
  run(session, 1.0);
  EXPECT_DOUBLE_EQ(session.snapshot().compensation_level, 1.0);
  run(session, 0.25);
  EXPECT_TRUE(!session.snapshot().compensation_enabled);
  EXPECT_NEAR(session.snapshot().compensation_level, 0.5, 0.01);
  run(session, 0.5);
  EXPECT_DOUBLE_EQ(session.snapshot().compensation_level, 0.0);
}

TEST(DemoSessionTest, MouseCommandsMoveTheHand) {
  DemoSession session(SessionOptions{});
  const Eigen::Vector3d target =
      session.simulation().workspaceCenter_m() + Eigen::Vector3d(0.01, -0.015, 0.0);
  session.grab();
  session.setHandTarget(target);
  run(session, 1.0);
  const ServoSnapshot& s = session.snapshot();
  EXPECT_TRUE(s.hand_holding);
  EXPECT_TRUE(s.hand_target_m.isApprox(target, 1e-12));
  // No map: the hand's spring carries the whole weight, so the end-effector sags a little below
  // the target (|G| / stiffness) but follows it sideways.
  EXPECT_NEAR(s.position_m.x(), target.x(), 0.001);
  EXPECT_NEAR(s.position_m.y(), target.y(), 0.001);
  session.release();
  run(session, 0.01);
  EXPECT_FALSE(session.snapshot().hand_holding);
  EXPECT_TRUE(session.snapshot().released);
}

TEST(DemoSessionTest, ServoTicksAllocateNothing) {
  DemoSession session(SessionOptions{});
  session.publishMap(groundTruthMap(session));
  const HandScript script = liftAndRelease(session);
  session.setScript(&script);
  session.runTicks(10);
  session.setHandTarget(session.simulation().workspaceCenter_m());
  autograv::testing::AllocationCounter counter;
  session.runTicks(1500);  // script events, a command, the ramp, the release
  EXPECT_EQ(counter.count(), 0u);
  EXPECT_TRUE(session.snapshot().released);
}

/// A 3x3x3 calibration saving into `map_path`, with one release test.
SessionOptions calibrationOptions(const std::string& map_path) {
  SessionOptions options;
  options.calibration_resolution = 3;  // 27 vertices: the whole procedure, quickly
  options.calibration_map_path = map_path;
  options.calibration_verify_points = 1;
  return options;
}

/// What the user at the demo does on seeing `last`: the mouse hand carries the end-effector to
/// the centre and Enter confirms there; the mouse lets go once the field is on; Enter saves at
/// the review.
void actAsTheUser(DemoSession& session, const WizardStatus& last) {
  if (last.step == WizardStep::kCentre) {
    if (!session.snapshot().hand_holding) session.grab();
    session.setHandTarget(last.centre_m);
    if (last.within_tolerance) session.postCalibrationEvent(WizardEvent::kConfirm);
  } else if (last.step == WizardStep::kRelease && session.snapshot().hand_holding &&
             last.release_status != InitializationEstimator::Status::kRampingIn) {
    session.release();
  } else if (last.step == WizardStep::kReview && last.review_valid) {
    session.postCalibrationEvent(WizardEvent::kConfirm);
  }
}

/// The user at the demo (actAsTheUser) on simulated time, a frame every 10 ms. `stop_when` ends
/// the run early (true: stop); the session's messages go to `messages`. Returns the last status.
template <typename StopWhen>
WizardStatus calibrateAsTheUser(DemoSession& session, StopWhen stop_when,
                                std::string* messages = nullptr) {
  for (int frame = 0; frame < 20000 && session.calibrationRunning(); ++frame) {
    const std::string said = run(session, 0.01);
    if (messages != nullptr) *messages += said;
    const WizardStatus& last = session.lastCalibrationStatus();
    if (!session.calibrationRunning() || stop_when(last)) break;
    actAsTheUser(session, last);
  }
  return session.lastCalibrationStatus();
}

TEST(DemoSessionTest, CalibrationKeyRunsTheWizardSavesAndHandsTheMapToTheApplication) {
  const autograv::testing::ScratchFolder scratch("demo");
  const std::string map_path = scratch.file("map.json");
  SessionOptions options = calibrationOptions(map_path);
  // The calibration key's workflow, not the estimator's accuracy through friction (checked
  // below at 2 %): low friction.
  options.friction = sim::FrictionLevel::kLow;
  DemoSession session(options);
  EXPECT_FALSE(session.map());
  run(session, 0.2);
  EXPECT_NE(session.startCalibration().find("checkpoints go to " + map_path + ".partial"),
            std::string::npos);
  EXPECT_TRUE(session.calibrationRunning());
  run(session, 0.01);
  EXPECT_EQ(session.snapshot().mode, ServoMode::kCalibrating);
  bool checkpointed = false;
  bool explored = false;
  const WizardStatus last = calibrateAsTheUser(session, [&](const WizardStatus& status) {
    checkpointed = checkpointed || status.checkpoint_written;
    explored = explored || (status.step == WizardStep::kExplore && status.directions_probed > 0);
    return false;
  });
  ASSERT_FALSE(session.calibrationRunning()) << toString(last.step) << ": " << last.message;
  EXPECT_EQ(last.step, WizardStep::kDone);
  EXPECT_TRUE(checkpointed);  // finished vertices went to disk as the run went
  EXPECT_FALSE(std::filesystem::exists(map_path + ".partial"));  // superseded by the map

  // The saved file is the published map: the A key explored the workspace first (the wizard's
  // Explore step, the library's code) and fitted the grid to it.
  EXPECT_TRUE(explored);
  const auto map = session.map();
  ASSERT_TRUE(map);
  const ExploredWorkspace& workspace = map->metadata().workspace;
  ASSERT_EQ(workspace.directions().size(),
            static_cast<std::size_t>(WorkspaceExplorer::Options().directions));
  EXPECT_TRUE(
      map->grid().sameGeometry(gridAroundWorkspace(workspace, Eigen::Vector3i::Constant(3))))
      << map->grid().describe();
  EXPECT_EQ(map->grid().vertexCount(), 27);
  EXPECT_EQ(last.measured_at_vertex + last.measured_off_vertex + last.beyond_reach, 27);
  EXPECT_GT(last.measured_off_vertex, 0);
  EXPECT_EQ(map->convergedCount(), last.measured_at_vertex + last.measured_off_vertex);
  EXPECT_EQ(map->metadata().device_model, "sim:omega");
  const GravityMap saved = loadMap(map_path);
  EXPECT_EQ(saved.metadata().workspace.radii_m(), workspace.radii_m());
  for (int i = 0; i < map->grid().vertexCount(); ++i) {
    const auto index = static_cast<std::size_t>(i);
    const VertexEstimate& vertex = map->vertices()[index];
    EXPECT_EQ(saved.vertices()[index].gravity_n, vertex.gravity_n);
    if (vertex.outcome != VertexOutcome::kConverged) continue;
    // Measured where the hand can be: at the vertex, or just inside the stops.
    const Eigen::Vector3d at_m =
        vertex.measuredOffVertex() ? vertex.measured_at_m : map->grid().vertexPosition(i);
    EXPECT_TRUE(workspace.contains(at_m, 0.5 * kBoundaryMargin_m)) << "vertex " << i;
    const Eigen::Vector3d truth = session.simulation().trueGravity(at_m);
    const Eigen::Vector3d measured_n =
        vertex.measuredOffVertex() ? vertex.measured_gravity_n : vertex.gravity_n;
    EXPECT_LT((measured_n - truth).norm(), 0.02 * truth.norm()) << "vertex " << i;
  }
  // Back in the application loop with the new map; carried into the calibrated box and let go,
  // the end-effector stays where it was left.
  run(session, 1.0);
  const ServoSnapshot& s = session.snapshot();
  EXPECT_EQ(s.mode, ServoMode::kApplication);
  EXPECT_TRUE(s.compensation_enabled);
  EXPECT_DOUBLE_EQ(s.compensation_level, 1.0);
  EXPECT_FALSE(s.hand_holding);
  session.grab();
  session.setHandTarget(map->grid().center_m());
  run(session, 1.0);
  session.release();
  run(session, 0.5);
  const Eigen::Vector3d before = session.snapshot().position_m;
  run(session, 1.0);
  EXPECT_LT((session.snapshot().position_m - before).norm(), 0.002);
}

/// Runs the A key's calibration as the user until the initialization (Centre, Release) is over;
/// the messages the session gave meanwhile go to `messages`.
WizardStatus initializeAsTheUser(DemoSession& session, std::string& messages) {
  session.startCalibration();
  return calibrateAsTheUser(
      session,
      [](const WizardStatus& status) {
        return status.step != WizardStep::kCheck && status.step != WizardStep::kCentre &&
               status.step != WizardStep::kRelease;
      },
      &messages);
}

TEST(DemoSessionTest, CalibrationKeyInitializationAwayFromTheStopsSaysNothing) {
  const autograv::testing::ScratchFolder scratch("demo");
  DemoSession session(calibrationOptions(scratch.file("map.json")));
  run(session, 0.2);
  std::string messages;
  const WizardStatus last = initializeAsTheUser(session, messages);
  EXPECT_EQ(last.step, WizardStep::kExplore) << last.message;  // the A key explores next
  EXPECT_FALSE(session.initializationEndStopHit());
  EXPECT_EQ(messages.find("end stop"), std::string::npos) << messages;
  session.abortCalibration();
  run(session, 0.5);
}

TEST(DemoSessionTest, CalibrationKeyInitializationOnAnEndStopIsRefusedFromDriverData) {
  const autograv::testing::ScratchFolder scratch("demo");
  DemoSession session(calibrationOptions(scratch.file("map.json")));
  // The published map's grid is where the A key calibrates: one whose centre lies 1 mm above
  // the bottom of sim:omega's workspace sphere, so the end-effector sags onto the stop.
  const double radius_m = session.simulation().specifications().workspace_radius_m;
  const Eigen::Vector3d low_m =
      session.simulation().workspaceCenter_m() - Eigen::Vector3d(0.0, 0.0, radius_m - 0.001);
  const WorkspaceGrid grid(low_m, 0.01, 2);
  std::vector<VertexEstimate> vertices(static_cast<std::size_t>(grid.vertexCount()));
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    vertices[i].gravity_n = session.simulation().trueGravity(low_m);
    vertices[i].outcome = VertexOutcome::kConverged;
  }
  MapMetadata metadata;
  metadata.device_model = session.simulation().specifications().model_name;
  session.publishMap(std::make_shared<const GravityMap>(grid, std::move(vertices), metadata));
  run(session, 0.2);
  // The user carries the end-effector down to the stop, through the hand's grip.
  session.grab();
  session.setHandTarget(low_m);
  run(session, 1.0);
  // The wizard explores, finds the stop right under the settled point from driver data and
  // refuses the initialization; the simulator's own contact flag agrees (scoring only) and is
  // not what the user is told.
  std::string messages;
  session.startCalibration();
  const WizardStatus last = calibrateAsTheUser(
      session,
      [](const WizardStatus& status) { return status.step == WizardStep::kAutoCalibration; },
      &messages);
  EXPECT_EQ(last.step, WizardStep::kFault) << last.message;
  EXPECT_NE((messages + last.message).find("from a stop the exploration found"), std::string::npos)
      << messages << last.message;
  EXPECT_TRUE(session.initializationEndStopHit());
  EXPECT_EQ(messages.find("WARNING"), std::string::npos) << messages;
  if (session.calibrationRunning()) session.abortCalibration();
  run(session, 0.5);
}

/// The map the A key makes on `device` (3x3x3, seed 1), as the user at the demo would.
std::shared_ptr<const GravityMap> calibrateWithTheAKey(const std::string& device) {
  const autograv::testing::ScratchFolder scratch("demo");
  SessionOptions options = calibrationOptions(scratch.file("map.json"));
  options.device = device;
  DemoSession session(options);
  EXPECT_EQ(session.device().specifications().model_name, "sim:omni");
  run(session, 0.2);
  session.startCalibration();
  const WizardStatus last = calibrateAsTheUser(session, [](const WizardStatus&) { return false; });
  EXPECT_EQ(last.step, WizardStep::kDone) << last.message;
  return session.map();
}

TEST(DemoSessionTest, CalibrationKeyWorksOnAChai3dDeviceExactlyAsOnASimulatedOne) {
  if (!chai3dDevicesAvailable()) GTEST_SKIP() << "built without the CHAI3D bridge";
  // The stand-in's CHAI3D device is the same simulation (seed 1) behind CHAI3D's API.
  ::setenv("AUTOGRAV_STANDIN_DEVICES", "sim:omni", 1);
  const std::vector<DeviceListing> listed = listDevices();
  if (std::none_of(listed.begin(), listed.end(),
                   [](const DeviceListing& listing) { return listing.name == "chai3d:0"; })) {
    ::unsetenv("AUTOGRAV_STANDIN_DEVICES");
    GTEST_SKIP() << "no chai3d:0: built against the real CHAI3D with no device connected (the "
                    "stand-in provides a simulated one)";
  }
  const auto through_chai3d = calibrateWithTheAKey("chai3d:0");
  ::unsetenv("AUTOGRAV_STANDIN_DEVICES");
  const auto direct = calibrateWithTheAKey("sim:omni");
  ASSERT_TRUE(through_chai3d && direct);
  // Both explored the same workspace through the same wizard code; a 3x3x3 grid around it
  // leaves some vertices beyond reach.
  EXPECT_FALSE(through_chai3d->metadata().workspace.empty());
  EXPECT_EQ(through_chai3d->metadata().workspace.radii_m(), direct->metadata().workspace.radii_m());
  EXPECT_GE(through_chai3d->convergedCount(), 15);
  EXPECT_EQ(through_chai3d->convergedCount(), direct->convergedCount());
  for (std::size_t i = 0; i < direct->vertices().size(); ++i) {
    EXPECT_EQ(through_chai3d->vertices()[i].gravity_n, direct->vertices()[i].gravity_n) << i;
  }
}

TEST(DemoSessionTest, AbortedCalibrationKeepsItsVerticesAndTheNextOneResumes) {
  const autograv::testing::ScratchFolder scratch("demo");
  const std::string map_path = scratch.file("map.json");
  DemoSession session(calibrationOptions(map_path));
  session.publishMap(groundTruthMap(session));
  run(session, 0.6);
  session.startCalibration();
  const WizardStatus aborted_at = calibrateAsTheUser(session, [](const WizardStatus& status) {
    return status.step == WizardStep::kAutoCalibration && status.converged >= 4;
  });
  ASSERT_EQ(aborted_at.step, WizardStep::kAutoCalibration);
  session.abortCalibration();
  for (int i = 0; i < 100 && session.calibrationRunning(); ++i) run(session, 0.01);
  ASSERT_FALSE(session.calibrationRunning());
  run(session, 0.6);
  EXPECT_EQ(session.snapshot().mode, ServoMode::kApplication);
  EXPECT_TRUE(session.snapshot().compensation_enabled);  // as before the calibration
  ASSERT_TRUE(std::filesystem::exists(map_path + ".partial"));
  const GravityMap partial = loadMap(map_path + ".partial");
  ASSERT_FALSE(partial.metadata().workspace.empty());  // explored before the grid run
  const std::vector<VertexEstimate> checkpoint = partial.vertices();
  const auto finished = std::count_if(checkpoint.begin(), checkpoint.end(), [](const auto& v) {
    return v.outcome == VertexOutcome::kConverged;
  });
  EXPECT_GE(finished, 4);

  // The next press of A resumes: the finished vertices are kept bit for bit.
  EXPECT_NE(session.startCalibration().find("resuming"), std::string::npos);
  const WizardStatus last = calibrateAsTheUser(session, [](const WizardStatus&) { return false; });
  ASSERT_FALSE(session.calibrationRunning()) << toString(last.step) << ": " << last.message;
  EXPECT_EQ(last.step, WizardStep::kDone);
  EXPECT_GE(last.review.restored, 4);
  // Resumed on the checkpoint's grid and workspace: not explored again.
  const auto map = session.map();
  ASSERT_TRUE(map);
  EXPECT_TRUE(map->grid().sameGeometry(partial.grid()));
  EXPECT_EQ(map->metadata().workspace.radii_m(), partial.metadata().workspace.radii_m());
  EXPECT_EQ(last.exploration_elapsed_s, 0.0);
  EXPECT_EQ(map->convergedCount(), last.measured_at_vertex + last.measured_off_vertex);
  // The checkpoint's measurements are kept bit for bit (the values of vertices measured off
  // their position are solved again from all measurements).
  for (int i = 0; i < map->grid().vertexCount(); ++i) {
    const auto index = static_cast<std::size_t>(i);
    const VertexEstimate& before = checkpoint[index];
    if (before.outcome != VertexOutcome::kConverged) continue;
    const VertexEstimate& after = map->vertices()[index];
    EXPECT_EQ(after.iterations, before.iterations) << i;
    if (before.measuredOffVertex()) {
      EXPECT_EQ(after.measured_at_m, before.measured_at_m) << i;
      EXPECT_EQ(after.measured_gravity_n, before.measured_gravity_n) << i;
    } else {
      EXPECT_EQ(after.gravity_n, before.gravity_n) << i;
    }
  }
}

TEST(DemoSessionTest, MapOfAnotherDeviceIsRefused) {
  DemoSession session(SessionOptions{});
  WorkspaceGrid grid(Eigen::Vector3d::Zero(), 0.05, 2);
  std::vector<VertexEstimate> vertices(8);
  for (auto& v : vertices) v.gravity_n = Eigen::Vector3d(0, 0, 1);
  MapMetadata metadata;
  metadata.device_model = "some other device";
  EXPECT_THROW(session.publishMap(std::make_shared<const GravityMap>(grid, vertices, metadata)),
               Error);
}

TEST(DemoSessionTest, RealTimeThreadTicksAndReportsItsTiming) {
  SessionOptions options;
  options.realtime_priority = false;
  DemoSession session(options);
  const double simulation_start_s = session.simulation().time_s();
  const auto wall_start = std::chrono::steady_clock::now();
  session.startRealTime();
  EXPECT_TRUE(session.running());
  // Wait for ticks without asserting on their pace (speed belongs in benchmarks).
  for (int i = 0; i < 10000 && session.snapshot().ticks < 50; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  session.stopRealTime();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  EXPECT_FALSE(session.running());
  const ServoSnapshot& s = session.snapshot();
  EXPECT_GE(s.ticks, 50);
  // The simulation followed the time that really passed: each tick advances it by the time
  // since the previous one (not by a period after its work), so it never runs ahead of the wall
  // clock. (How much of a stall it covers depends on this machine's load: not asserted.)
  const double simulated_s = session.simulation().time_s() - simulation_start_s;
  EXPECT_GT(simulated_s, 0.0);
  EXPECT_LE(simulated_s, wall_s + 1e-9);
  EXPECT_TRUE(s.realtime);
  EXPECT_EQ(s.timing.ticks, s.ticks);
  EXPECT_GT(s.timing.rate_hz, 0.0);
}

TEST(DemoSessionTest, CalibrationKeyRunsBesideTheServoThread) {
  // The A key as in the demo: the servo thread ticks at 1 kHz on the wall clock while the UI
  // thread moves the wizard on and reads the end-stop watch (ThreadSanitizer runs this too).
  const autograv::testing::ScratchFolder scratch("demo");
  SessionOptions options = calibrationOptions(scratch.file("map.json"));
  options.realtime_priority = false;
  DemoSession session(options);
  session.startRealTime();
  session.startCalibration();
  WizardStatus last = session.lastCalibrationStatus();
  for (int frame = 0; frame < 6000 && session.calibrationRunning(); ++frame) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    session.updateCalibration();
    last = session.lastCalibrationStatus();
    // On into the exploration, the first of the steps in which the device moves by itself.
    if (last.step == WizardStep::kExplore && last.directions_probed >= 1) break;
    actAsTheUser(session, last);
  }
  EXPECT_EQ(last.step, WizardStep::kExplore) << last.message;
  EXPECT_GE(last.directions_probed, 1);
  EXPECT_FALSE(session.initializationEndStopHit());
  session.abortCalibration();
  for (int frame = 0; frame < 6000 && session.calibrationRunning(); ++frame) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    session.updateCalibration();
  }
  EXPECT_FALSE(session.calibrationRunning());
  EXPECT_EQ(session.lastCalibrationStatus().step, WizardStep::kAborted);
  session.stopRealTime();
}

}  // namespace
}  // namespace autograv::demo
