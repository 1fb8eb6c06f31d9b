#include "demo_view.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

namespace autograv::demo {

namespace {

std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* pattern, ...) {
  char text[256];
  va_list arguments;
  va_start(arguments, pattern);
  std::vsnprintf(text, sizeof text, pattern, arguments);
  va_end(arguments);
  return text;
}

const char* initializationText(InitializationEstimator::Status status) {
  switch (status) {
    case InitializationEstimator::Status::kRampingIn:
      return "FIELD RAMPING IN";
    case InitializationEstimator::Status::kWaiting:
      return "LET GO, WAITING TO SETTLE";
    case InitializationEstimator::Status::kStillHeld:
      return "STILL HELD: LET GO";
    case InitializationEstimator::Status::kDone:
      return "G0 FOUND";
    case InitializationEstimator::Status::kDeviceFault:
      return "DEVICE FAULT";
  }
  return "?";
}

}  // namespace

DemoView::DemoView(std::string device_name, double trail_s)
    : device_name_(std::move(device_name)), trail_s_(trail_s) {}

void DemoView::record(const ServoSnapshot& snapshot) {
  if (!snapshot.sample_valid) return;
  trail_.push_back({snapshot.time_s, snapshot.position_m});
  while (!trail_.empty() && trail_.front().time_s < snapshot.time_s - trail_s_) trail_.pop_front();
}

std::vector<std::string> DemoView::readout(const ServoSnapshot& s, const GravityMap* map,
                                           bool simulated_time) const {
  std::vector<std::string> lines;
  std::string first = device_name_;
  if (map != nullptr) {
    const int n = map->grid().resolution();
    first += format("  MAP %dX%dX%d", n, n, n);
  } else {
    first += "  NO MAP";
  }
  first += format("  COMPENSATION %s %3.0f%%", s.compensation_enabled ? "ON" : "OFF",
                  100.0 * s.compensation_level);
  lines.push_back(first);
  if (simulated_time) {
    lines.push_back(format("SERVO 1 KHZ ON SIMULATED TIME  T %.2f S", s.time_s));
  } else if (s.realtime && s.timing.ticks > 1) {
    lines.push_back(format("SERVO %.1f HZ  WORST BURST %.1f MS  MISSED %lld", s.timing.rate_hz,
                           s.timing.worst_burst_ms, static_cast<long long>(s.timing.missed_ticks)));
  } else {
    lines.push_back("SERVO STARTING");
  }
  const Eigen::Vector3d& f = s.force_sent_n;
  lines.push_back(
      format("FORCE SENT %+.2f %+.2f %+.2f N  |F| %.2f N", f.x(), f.y(), f.z(), f.norm()));
  std::string faults =
      format("CLAMPS %llu  SATURATED %llu  FAULTS %llu", static_cast<unsigned long long>(s.clamps),
             static_cast<unsigned long long>(s.device_saturations),
             static_cast<unsigned long long>(s.faults));
  if (s.last_fault != ServoFault::kNone) faults += std::string(" (") + toString(s.last_fault) + ")";
  lines.push_back(faults);
  if (s.hand_holding) {
    lines.push_back("HELD BY THE HAND");
  } else if (s.released) {
    lines.push_back(
        format("DRIFT SINCE RELEASE %.1f MM IN %.1f S", s.drift_m * 1e3, s.since_release_s));
  } else {
    lines.push_back("NOT TOUCHED YET");
  }
  switch (s.mode) {
    case ServoMode::kApplication:
      break;
    case ServoMode::kInitializing:
    case ServoMode::kInitialized:
      lines.push_back(std::string("CALIBRATION: ") + initializationText(s.initialization));
      break;
    case ServoMode::kAutoCalibrating:
      lines.push_back(format("CALIBRATION: %s VERTEX %d OF %d", toString(s.calibration),
                             s.calibration_done, s.calibration_total));
      break;
    case ServoMode::kCalibrated:
      lines.push_back("CALIBRATION: DONE, PUBLISHING THE MAP");
      break;
    case ServoMode::kHandover:
      lines.push_back("CALIBRATION: DONE, COMPENSATION TAKING OVER");
      break;
  }
  return lines;
}

gl::Scene DemoView::build(const ServoSnapshot& s, std::shared_ptr<const GravityMap> map,
                          const gl::OrbitCamera& camera, bool simulated_time,
                          const std::string& status_line) const {
  gl::Scene scene;
  scene.readout = readout(s, map.get(), simulated_time);
  scene.map = std::move(map);
  scene.camera = camera;
  scene.show_cursor = s.sample_valid || s.ticks == 0;
  scene.cursor_m = s.position_m;
  scene.cursor_held = s.hand_holding;
  scene.trail_m.reserve(trail_.size());
  for (const TrailPoint& point : trail_) scene.trail_m.push_back(point.position_m);
  scene.show_hand_target = s.hand_holding;
  scene.hand_target_m = s.hand_target_m;
  scene.show_force = true;
  scene.force_n = s.force_sent_n;
  scene.status_line = status_line;
  return scene;
}

}  // namespace autograv::demo
