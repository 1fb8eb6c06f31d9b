// What the demo's readout says for given servo states, and its trail.
#include "demo_view.h"

#include <gtest/gtest.h>

namespace autograv::demo {
namespace {

bool contains(const std::vector<std::string>& lines, const std::string& text) {
  for (const std::string& line : lines) {
    if (line.find(text) != std::string::npos) return true;
  }
  return false;
}

ServoSnapshot floatingSnapshot() {
  ServoSnapshot s;
  s.ticks = 2000;
  s.time_s = 2.0;
  s.sample_valid = true;
  s.position_m = Eigen::Vector3d(0.0, 0.01, 0.02);
  s.force_sent_n = Eigen::Vector3d(0.138, -0.001, 1.786);
  s.compensation_enabled = true;
  s.compensation_level = 1.0;
  s.released = true;
  s.drift_m = 0.00034;
  s.since_release_s = 1.2;
  s.clamps = 3;
  s.device_saturations = 1;
  s.faults = 2;
  s.last_fault = ServoFault::kStalePosition;
  return s;
}

TEST(DemoViewTest, ReadoutShowsForceClampsFaultsAndDrift) {
  const DemoView view("SIM:OMNI");
  const auto lines = view.readout(floatingSnapshot(), nullptr, true);
  EXPECT_EQ(lines[0], "SIM:OMNI  NO MAP  COMPENSATION ON 100%");
  EXPECT_TRUE(contains(lines, "SERVO 1 KHZ ON SIMULATED TIME  T 2.00 S"));
  EXPECT_TRUE(contains(lines, "FORCE SENT +0.14 -0.00 +1.79 N  |F| 1.79 N"));
  EXPECT_TRUE(contains(lines, "CLAMPS 3  SATURATED 1  FAULTS 2 (stale_position)"));
  EXPECT_TRUE(contains(lines, "DRIFT SINCE RELEASE 0.3 MM IN 1.2 S"));
}

TEST(DemoViewTest, RealTimeReadoutShowsTheServoRateAndWorstBurst) {
  ServoSnapshot s = floatingSnapshot();
  s.realtime = true;
  s.timing.ticks = 2000;
  s.timing.rate_hz = 999.87;
  s.timing.worst_burst_ms = 2.26;
  s.timing.missed_ticks = 3;
  const auto lines = DemoView("SIM:OMEGA").readout(s, nullptr, false);
  EXPECT_TRUE(contains(lines, "SERVO 999.9 HZ  WORST BURST 2.3 MS  MISSED 3"));
}

TEST(DemoViewTest, ReadoutFollowsHandAndCalibration) {
  ServoSnapshot s = floatingSnapshot();
  s.hand_holding = true;
  s.mode = ServoMode::kCalibrating;
  WizardStatus calibration;
  calibration.step = WizardStep::kAutoCalibration;
  calibration.step_number = 5;
  calibration.title = "Auto-calibration";
  calibration.vertex_ordinal = 4;
  calibration.vertices_to_visit = 27;
  calibration.iteration = 2;
  calibration.converged = 3;
  calibration.paused = true;
  calibration.prompt = "p resumes, q aborts\nsecond line";
  const auto lines = DemoView("X").readout(s, nullptr, true, &calibration);
  EXPECT_TRUE(contains(lines, "HELD BY THE HAND"));
  EXPECT_FALSE(contains(lines, "DRIFT"));
  EXPECT_TRUE(contains(lines, "CALIBRATION STEP 5 OF 8: AUTO-CALIBRATION"));
  EXPECT_TRUE(contains(lines, "VERTEX 4 OF 27  ITERATION 2  CONVERGED 3  PAUSED (P)"));
  EXPECT_TRUE(contains(lines, "P RESUMES, Q ABORTS"));
  EXPECT_FALSE(contains(lines, "SECOND LINE"));  // one line of the prompt: the readout is short

  calibration.step = WizardStep::kCentre;
  calibration.step_number = 2;
  calibration.title = "Centre";
  calibration.centre_distance_m = 0.0042;
  calibration.centre_tolerance_m = 0.01;
  calibration.within_tolerance = true;
  EXPECT_TRUE(contains(DemoView("X").readout(s, nullptr, true, &calibration),
                       "TO THE CENTRE 4.2 MM (WITHIN 10 MM: ENTER)"));
}

TEST(DemoViewTest, TrailKeepsOnlyTheLastSecondsAndSceneCarriesTheState) {
  DemoView view("X", 1.0);
  ServoSnapshot s = floatingSnapshot();
  for (int i = 0; i <= 30; ++i) {
    s.time_s = 0.1 * i;
    s.position_m = Eigen::Vector3d(0.001 * i, 0.0, 0.0);
    view.record(s);
  }
  s.hand_holding = true;
  s.hand_target_m = Eigen::Vector3d(0.0, 0.0, 0.05);
  const gl::Scene scene = view.build(s, nullptr, gl::OrbitCamera{}, true, "STATUS");
  ASSERT_EQ(scene.trail_m.size(), 11u);  // t = 2.0 .. 3.0
  EXPECT_DOUBLE_EQ(scene.trail_m.front().x(), 0.020);
  EXPECT_DOUBLE_EQ(scene.trail_m.back().x(), 0.030);
  EXPECT_TRUE(scene.show_cursor);
  EXPECT_TRUE(scene.cursor_held);
  EXPECT_TRUE(scene.show_hand_target);
  EXPECT_TRUE(scene.force_n.isApprox(s.force_sent_n));
  EXPECT_EQ(scene.status_line, "STATUS");
}

}  // namespace
}  // namespace autograv::demo
