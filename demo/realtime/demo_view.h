#pragma once

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "autograv/gl/frame_data.h"
#include "autograv/map/gravity_map.h"
#include "demo_session.h"

namespace autograv::demo {

/// `text` in capitals: the readout's font has no lower case.
std::string upperCase(std::string text);

/// Turns the servo loop's snapshots into what the renderer draws: the end-effector with a short
/// trail, the hand's target, the force being sent and the readout. UI thread only.
class DemoView {
 public:
  /// `device_name` heads the readout; the trail keeps `trail_s` of servo time. Unit: [s]
  explicit DemoView(std::string device_name, double trail_s = 1.5);

  /// Adds the end-effector position of `snapshot` to the trail (call once per frame).
  void record(const ServoSnapshot& snapshot);

  /// The scene of one frame. `simulated_time` says the loop runs on simulated time (headless),
  /// where wall-clock statistics mean nothing and are not shown. Not real-time safe.
  /// `calibration`: the running calibration's status, null when none runs.
  gl::Scene build(const ServoSnapshot& snapshot, std::shared_ptr<const GravityMap> map,
                  const gl::OrbitCamera& camera, bool simulated_time,
                  const std::string& status_line, const WizardStatus* calibration = nullptr) const;

  /// The readout lines alone (tested on their own).
  std::vector<std::string> readout(const ServoSnapshot& snapshot, const GravityMap* map,
                                   bool simulated_time,
                                   const WizardStatus* calibration = nullptr) const;

 private:
  struct TrailPoint {
    double time_s;
    Eigen::Vector3d position_m;
  };
  std::string device_name_;
  double trail_s_;
  std::deque<TrailPoint> trail_;
};

}  // namespace autograv::demo
