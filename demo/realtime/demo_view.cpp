#include "demo_view.h"

#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "autograv/map/value_kind.h"

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

std::string firstLine(const std::string& text) { return text.substr(0, text.find('\n')); }

/// The calibration's lines of the readout: the step, its live numbers, what to do.
void calibrationLines(const WizardStatus& c, std::vector<std::string>& lines) {
  lines.push_back(format("CALIBRATION STEP %d OF %d: %s", c.step_number, WizardStatus::kStepCount,
                         upperCase(c.title).c_str()));
  switch (c.step) {
    case WizardStep::kCentre:
      lines.push_back(format("TO THE CENTRE %.1f MM (WITHIN %.0f MM%s)", c.centre_distance_m * 1e3,
                             c.centre_tolerance_m * 1e3, c.within_tolerance ? ": ENTER" : ""));
      break;
    case WizardStep::kRelease:
      lines.push_back(format("SAG %.1f MM  SPEED %.1f MM/S%s", c.sag_m * 1e3, c.speed_m_per_s * 1e3,
                             c.still_held ? "  STILL HELD: LET GO" : ""));
      break;
    case WizardStep::kExplore: {
      // The explored volume growing.
      const Eigen::Vector3d extent_m = c.explored_high_m - c.explored_low_m;
      lines.push_back(format("DIRECTION %d OF %d  REACH %.0f-%.0f MM  BOX %.0fX%.0fX%.0f MM",
                             c.directions_probed, c.direction_count, c.reach_min_m * 1e3,
                             c.reach_max_m * 1e3, extent_m.x() * 1e3, extent_m.y() * 1e3,
                             extent_m.z() * 1e3));
      break;
    }
    case WizardStep::kAutoCalibration:
      lines.push_back(format("VERTEX %d OF %d  ITERATION %d  CONVERGED %d%s", c.vertex_ordinal,
                             c.vertices_to_visit, c.iteration, c.converged,
                             c.paused ? "  PAUSED (P)" : ""));
      break;
    case WizardStep::kReview:
      if (c.review_valid) {
        lines.push_back(format("CONVERGED %d OF %d  ITERATIONS %d-%d", c.review.converged,
                               c.review.vertex_count, c.review.iterations_min,
                               c.review.iterations_max));
      }
      break;
    default:
      break;
  }
  const std::string prompt = firstLine(c.prompt.empty() ? c.message : c.prompt);
  if (!prompt.empty()) lines.push_back(upperCase(prompt));
}

}  // namespace

std::string upperCase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return text;
}

DemoView::DemoView(std::string device_name, double trail_s)
    : device_name_(std::move(device_name)), trail_s_(trail_s) {}

void DemoView::record(const ServoSnapshot& snapshot) {
  if (!snapshot.sample_valid) return;
  trail_.push_back({snapshot.time_s, snapshot.position_m});
  while (!trail_.empty() && trail_.front().time_s < snapshot.time_s - trail_s_) trail_.pop_front();
}

std::vector<std::string> DemoView::readout(const ServoSnapshot& s, const GravityMap* map,
                                           bool simulated_time,
                                           const WizardStatus* calibration) const {
  std::vector<std::string> lines;
  std::string first = device_name_;
  if (map != nullptr) {
    const Eigen::Vector3i& n = map->grid().resolution();
    first += format("  MAP %dX%dX%d", n.x(), n.y(), n.z());
    // Values not measured at all (out of reach), solved from the measurements around them.
    int solved = 0;
    for (const VertexEstimate& vertex : map->vertices()) {
      if (valueKind(vertex) == ValueKind::kSolved) ++solved;
    }
    if (solved > 0) first += format(" %d SOLVED", solved);
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
  if (calibration != nullptr) {
    calibrationLines(*calibration, lines);
  } else if (s.mode == ServoMode::kHandover) {
    lines.push_back("CALIBRATION: DONE, COMPENSATION TAKING OVER");
  }
  return lines;
}

gl::Scene DemoView::build(const ServoSnapshot& s, std::shared_ptr<const GravityMap> map,
                          const gl::OrbitCamera& camera, bool simulated_time,
                          const std::string& status_line, const WizardStatus* calibration) const {
  gl::Scene scene;
  scene.readout = readout(s, map.get(), simulated_time, calibration);
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
