#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "autograv/gl/image.h"
#include "autograv/map/gravity_map.h"
#include "demo_session.h"

namespace autograv::demo {

/// Options of `autograv-demo`.
struct DemoOptions {
  std::string device = "sim:omega";
  std::string map_path;     ///< Map to load at start (and the S/L keys' file).
  std::string script_path;  ///< Scripted hand (see HandScript).
  bool headless = false;
  int frames = 0;          ///< Headless frames; 0: 30 per second of --seconds.
  std::string screenshot;  ///< PNG of the last frame.
  double seconds = 0.0;    ///< Run length; 0: until the window closes (headless: 2 s). [s]
  int width = 0;           ///< Framebuffer size; 0: 1024x768 window, 800x600 headless.
  int height = 0;
  std::string shader_dir;  ///< Read GLSL from here instead of the embedded copies.
  std::uint64_t seed = 1;
  bool realtime_check = true;  ///< Headless: also run the servo thread in real time, report it.
  bool realtime_priority = true;
  std::string stats_json;  ///< Where to write the real-time servo statistics as JSON.
  /// Servo loop and compensation settings.
  SessionOptions session;
};

/// Loads `path` for the session's device, refusing a map of another model. Throws
/// autograv::Error. Not real-time safe.
std::shared_ptr<const GravityMap> loadMapFor(const DemoSession& session, const std::string& path);

/// What a deterministic headless run produced.
struct HeadlessResult {
  RgbImage last_frame;
  ServoSnapshot last_snapshot;
  int frames = 0;
  std::int64_t ticks_per_frame = 0;
};

/// Renders `frames` frames through OSMesa with the servo loop on simulated time, stepping a fixed
/// number of ticks per frame, so that the same options always give the same picture. Throws
/// autograv::Error. Not real-time safe.
HeadlessResult runHeadlessFrames(const DemoOptions& options);

/// What runRealTimeCheck measured.
struct RealTimeCheck {
  ServoSnapshot last_snapshot;  ///< The servo loop's state and timing at the end.
  /// An empty loop paced beside it at the same priority: what the machine alone imposes.
  ServoTiming::Report reference;
  bool realtime_priority = false;  ///< The servo thread got SCHED_FIFO.
  bool memory_locked = false;      ///< mlockall succeeded.
};
/// The servo thread at 1 kHz on the wall clock for `seconds`, with the same device, map and
/// script, while this thread renders offscreen frames as a window would, and a ReferenceLoop
/// beside it. Throws autograv::Error. Not real-time safe.
RealTimeCheck runRealTimeCheck(const DemoOptions& options, double seconds);

/// The interactive program: a GLFW window, the servo thread at 1 kHz, the mouse as the hand.
/// Returns the process exit code. Throws autograv::Error. Not real-time safe.
int runWindowed(const DemoOptions& options);

/// One line with the servo statistics of a real-time run.
std::string describeTiming(const ServoTiming::Report& timing);

}  // namespace autograv::demo
