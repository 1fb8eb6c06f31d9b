// autograv-demo: a simulated haptic device in your hand, with and without gravity compensation.
#include <cstdio>
#include <exception>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "autograv/error.h"
#include "autograv/gl/image.h"
#include "autograv/map/map_io.h"
#include "demo_app.h"
#include "friction_option.h"

namespace {

using autograv::demo::DemoOptions;

nlohmann::json timingJson(const autograv::demo::ServoTiming::Report& t) {
  return {{"ticks", t.ticks},
          {"elapsed_s", t.elapsed_s},
          {"rate_hz", t.rate_hz},
          {"missed_ticks", t.missed_ticks},
          {"worst_burst_ms", t.worst_burst_ms},
          {"max_lateness_ms", t.max_lateness_ms},
          {"mean_lateness_ms", t.mean_lateness_ms},
          {"max_gap_ms", t.max_gap_ms},
          {"max_tick_ms", t.max_tick_ms}};
}

void writeStats(const std::string& path, const DemoOptions& options,
                const autograv::demo::RealTimeCheck& check, double seconds) {
  // The servo loop's figures at the top level; the reference loop's beside them.
  nlohmann::json report = timingJson(check.last_snapshot.timing);
  report["device"] = options.device;
  report["friction"] = autograv::sim::toString(options.session.friction);
  report["map"] = options.map_path;
  report["script"] = options.script_path;
  report["seconds"] = seconds;
  report["sched_fifo"] = check.realtime_priority;
  report["memory_locked"] = check.memory_locked;
  report["reference"] = timingJson(check.reference);
  autograv::writeFileAtomically(path, report.dump(2) + "\n", "statistics");
}

int runHeadless(const DemoOptions& options) {
  const double seconds = options.seconds > 0.0 ? options.seconds : 2.0;
  const auto result = autograv::demo::runHeadlessFrames(options);
  const auto& s = result.last_snapshot;
  std::printf("autograv-demo headless: %s (friction %s), map %s, script %s\n",
              options.device.c_str(), autograv::sim::toString(options.session.friction),
              options.map_path.empty() ? "(none)" : options.map_path.c_str(),
              options.script_path.empty() ? "(none)" : options.script_path.c_str());
  std::printf("simulated time: %d frames x %lld ticks = %.3f s of servo time\n", result.frames,
              static_cast<long long>(result.ticks_per_frame), s.time_s);
  std::printf(
      "end-effector at (%.1f, %.1f, %.1f) mm, force sent (%.3f, %.3f, %.3f) N, "
      "compensation %s %.0f %%\n",
      s.position_m.x() * 1e3, s.position_m.y() * 1e3, s.position_m.z() * 1e3, s.force_sent_n.x(),
      s.force_sent_n.y(), s.force_sent_n.z(), s.compensation_enabled ? "on" : "off",
      100.0 * s.compensation_level);
  if (s.released) {
    std::printf("drift since release: %.2f mm in %.2f s\n", s.drift_m * 1e3, s.since_release_s);
  }
  std::printf("clamps %llu, device saturations %llu, faults %llu\n",
              static_cast<unsigned long long>(s.clamps),
              static_cast<unsigned long long>(s.device_saturations),
              static_cast<unsigned long long>(s.faults));
  if (!options.screenshot.empty()) {
    autograv::gl::writePng(result.last_frame, options.screenshot);
    std::printf("screenshot %s (%dx%d)\n", options.screenshot.c_str(), result.last_frame.width_px,
                result.last_frame.height_px);
  }
  if (options.realtime_check) {
    const auto check = autograv::demo::runRealTimeCheck(options, seconds);
    std::printf("real-time check over %.2f s: %s\n", seconds,
                autograv::demo::describeTiming(check.last_snapshot.timing).c_str());
    std::printf("reference loop beside it (same priority, empty tick): %s\n",
                autograv::demo::describeTiming(check.reference).c_str());
    if (!options.stats_json.empty()) writeStats(options.stats_json, options, check, seconds);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "autograv-demo - a simulated haptic device in your hand: drag the end-effector with the "
      "mouse, let go, and see it fall (compensation off) or float (compensation on)"};
  DemoOptions options;
  std::string size;
  bool no_compensation = false;
  bool no_realtime_check = false;
  bool no_priority = false;
  app.add_option("--device", options.device,
                 "Device with a simulation behind it: sim:omega, sim:omni, sim:falcon, or a "
                 "simulated CHAI3D device (chai3d:N)")
      ->capture_default_str();
  app.add_option("--map", options.map_path,
                 "Gravity map (JSON) to compensate with; also the file of the S and L keys "
                 "(window default: the device's map in the library)");
  app.add_option("--script", options.script_path,
                 "Scripted hand: lines 'at T grab', 'at T move X Y Z [SPEED]', 'at T release', "
                 "'at T compensation on|off' (seconds, metres)");
  app.add_flag("--headless", options.headless,
               "Render offscreen through OSMesa (no display needed), on simulated time");
  app.add_option("--frames", options.frames, "Headless: frames to render (default 30 per second)")
      ->check(CLI::PositiveNumber);
  app.add_option("--screenshot", options.screenshot, "Write the last frame to this PNG");
  app.add_option("--seconds", options.seconds,
                 "Run length in seconds (headless default 2; window: until closed)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--size", size, "Framebuffer size WxH (default 1024x768, headless 800x600)");
  app.add_option("--shader-dir", options.shader_dir,
                 "Read the GLSL files from this folder instead of the embedded copies");
  app.add_option("--seed", options.seed, "Seed of the simulated device")->capture_default_str();
  autograv::cli::addFrictionOption(app, options.session.friction);
  app.add_option("--ramp-s", options.session.compensation.ramp_duration_s,
                 "Compensation fade in/out time in seconds")
      ->capture_default_str();
  app.add_flag("--no-compensation", no_compensation, "Start with compensation off");
  app.add_flag("--no-realtime-check", no_realtime_check,
               "Headless: skip the real-time servo run after the deterministic frames");
  app.add_flag("--no-realtime-priority", no_priority,
               "Do not ask for SCHED_FIFO for the servo thread");
  app.add_option("--stats-json", options.stats_json,
                 "Headless: write the real-time servo statistics here");
  try {
    app.parse(argc, argv);
    if (!size.empty()) {
      char separator = 0;
      if (std::sscanf(size.c_str(), "%d%c%d", &options.width, &separator, &options.height) != 3 ||
          (separator != 'x' && separator != 'X') || options.width < 16 || options.height < 16) {
        throw autograv::Error("--size expects WIDTHxHEIGHT, e.g. 800x600, got '" + size + "'");
      }
    }
    options.session.compensation.enabled = !no_compensation;
    options.realtime_check = !no_realtime_check;
    options.realtime_priority = !no_priority;
    if (options.headless) return runHeadless(options);
    return autograv::demo::runWindowed(options);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  } catch (const autograv::Error& error) {
    std::fprintf(stderr, "autograv-demo: error: %s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "autograv-demo: unexpected error: %s\n", error.what());
    return 3;
  }
}
