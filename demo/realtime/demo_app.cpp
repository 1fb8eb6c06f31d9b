#include "demo_app.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <thread>

#include "autograv/devices/device_registry.h"
#include "autograv/error.h"
#include "autograv/gl/offscreen_context.h"
#include "autograv/gl/renderer.h"
#include "autograv/gl/window.h"
#include "autograv/map/map_io.h"
#include "autograv/map/map_library.h"
#include "demo_view.h"

namespace autograv::demo {

namespace {

constexpr double kDefaultHeadlessSeconds = 2.0;
constexpr int kHeadlessFramesPerSecond = 30;
constexpr const char* kDefaultMapPath = "autograv-map.json";
constexpr double kMessageSeconds = 6.0;

SessionOptions sessionOptions(const DemoOptions& options) {
  SessionOptions session = options.session;
  session.device = options.device;
  session.seed = options.seed;
  session.calibration_map_path = options.map_path.empty() ? kDefaultMapPath : options.map_path;
  session.realtime_priority = options.realtime_priority;
  return session;
}

/// Session with the map and script of the options. The script must outlive the session.
std::unique_ptr<DemoSession> makeSession(const DemoOptions& options, const HandScript& script) {
  auto session = std::make_unique<DemoSession>(sessionOptions(options));
  if (!options.map_path.empty()) session->publishMap(loadMapFor(*session, options.map_path));
  session->setScript(&script);
  return session;
}

HandScript loadScript(const DemoOptions& options) {
  return options.script_path.empty() ? HandScript() : HandScript::load(options.script_path);
}

gl::OrbitCamera initialCamera(const DemoSession& session) {
  const auto map = session.map();
  return gl::OrbitCamera::framing(map ? map->grid() : session.calibrationGrid());
}

gl::RendererOptions rendererOptions(const DemoOptions& options) {
  gl::RendererOptions renderer_options;
  renderer_options.shader_directory = options.shader_dir;
  return renderer_options;
}

/// What both headless runs draw with: the options' session (device, map, script) and an OSMesa
/// renderer with its view and camera. Members in construction order.
struct OffscreenRun {
  explicit OffscreenRun(const DemoOptions& options)
      : script(loadScript(options)),
        session(makeSession(options, script)),
        context(options.width > 0 ? options.width : 800, options.height > 0 ? options.height : 600),
        renderer(context, rendererOptions(options)),
        view(upperCase(options.device)),
        camera(initialCamera(*session)) {}

  HandScript script;  // outlives the session, which plays it
  std::unique_ptr<DemoSession> session;
  gl::OffscreenContext context;
  gl::Renderer renderer;
  DemoView view;
  gl::OrbitCamera camera;
};

/// One frame's scene; without a map the lattice of the grid a calibration would visit is shown.
gl::Scene frameScene(const DemoView& view, const ServoSnapshot& snapshot,
                     const DemoSession& session, const gl::OrbitCamera& camera, bool simulated_time,
                     const std::string& status) {
  gl::Scene scene = view.build(snapshot, session.map(), camera, simulated_time, status,
                               session.calibrationStatus());
  if (!scene.map) scene.grid = session.calibrationGrid();
  return scene;
}

}  // namespace

std::shared_ptr<const GravityMap> loadMapFor(const DemoSession& session, const std::string& path) {
  MapLoadOptions load;
  load.expected_device_model = session.simulation().specifications().model_name;
  return std::make_shared<const GravityMap>(loadMap(path, load));
}

std::string describeTiming(const ServoTiming::Report& t) {
  char text[400];
  std::snprintf(text, sizeof text,
                "servo rate %.2f Hz average over %lld ticks in %.3f s; worst missed-deadline burst "
                "%.2f ms; missed ticks %lld; max lateness %.3f ms; mean lateness %.3f ms; longest "
                "gap between ticks %.3f ms; longest tick %.3f ms",
                t.rate_hz, static_cast<long long>(t.ticks), t.elapsed_s, t.worst_burst_ms,
                static_cast<long long>(t.missed_ticks), t.max_lateness_ms, t.mean_lateness_ms,
                t.max_gap_ms, t.max_tick_ms);
  return text;
}

HeadlessResult runHeadlessFrames(const DemoOptions& options) {
  const double seconds = options.seconds > 0.0 ? options.seconds : kDefaultHeadlessSeconds;
  HeadlessResult result;
  result.frames =
      options.frames > 0
          ? options.frames
          : std::max(1, static_cast<int>(std::lround(kHeadlessFramesPerSecond * seconds)));
  const double period_s = options.session.servo_period_s;
  result.ticks_per_frame =
      std::max<std::int64_t>(1, std::llround(seconds / result.frames / period_s));

  OffscreenRun run(options);
  DemoSession& session = *run.session;
  std::string message;
  for (int frame = 1; frame <= result.frames; ++frame) {
    session.runTicks(result.ticks_per_frame);
    const std::string update = session.updateCalibration();
    if (!update.empty()) message = update;
    const ServoSnapshot& snapshot = session.snapshot();
    run.view.record(snapshot);
    char status[128];
    std::snprintf(status, sizeof status, "HEADLESS  FRAME %d OF %d  %lld TICKS PER FRAME", frame,
                  result.frames, static_cast<long long>(result.ticks_per_frame));
    run.renderer.render(frameScene(run.view, snapshot, session, run.camera, true,
                                   message.empty() ? status : upperCase(message)));
  }
  result.last_frame = run.context.readImage();
  result.last_snapshot = session.snapshot();
  return result;
}

RealTimeCheck runRealTimeCheck(const DemoOptions& options, double seconds) {
  OffscreenRun run(options);
  DemoSession& session = *run.session;
  // The reference loop first, so that both run through the whole measurement.
  ReferenceLoop reference(std::llround(options.session.servo_period_s * 1e9));
  session.startRealTime();
  // Render at a window's pace meanwhile: the servo thread must hold its rate under that load.
  const auto frame_period = std::chrono::microseconds(1000000 / kHeadlessFramesPerSecond);
  const auto start = std::chrono::steady_clock::now();
  const auto end = start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(seconds));
  auto next_frame = start;
  while (std::chrono::steady_clock::now() < end) {
    const ServoSnapshot& snapshot = session.snapshot();
    run.view.record(snapshot);
    run.renderer.render(
        frameScene(run.view, snapshot, session, run.camera, false, "REAL-TIME CHECK"));
    next_frame += frame_period;
    std::this_thread::sleep_until(std::min(next_frame, end));
  }
  session.stopRealTime();
  RealTimeCheck check;
  check.reference = reference.stop();
  check.last_snapshot = session.snapshot();
  check.realtime_priority = session.realtimePriority();
  check.memory_locked = session.memoryLocked();
  std::printf("real-time check: servo thread %s SCHED_FIFO, memory %s\n",
              check.realtime_priority ? "at" : "without (not permitted here, normal priority)",
              check.memory_locked ? "locked" : "not locked (not permitted here)");
  return check;
}

int runWindowed(const DemoOptions& given) {
  DemoOptions options = given;
  if (options.map_path.empty()) {
    // The device's map in the library, found by model and serial, as the CLI and the bridge do;
    // a calibration (A) saves it there too.
    options.map_path =
        MapLibrary().pathFor(makeDevice(options.device, options.seed).device->specifications());
    std::error_code ignored;
    std::filesystem::create_directories(std::filesystem::path(options.map_path).parent_path(),
                                        ignored);
  }
  const HandScript script = loadScript(options);
  auto session = std::make_unique<DemoSession>(sessionOptions(options));
  const std::string map_path = options.map_path;
  std::string message;
  if (!options.map_path.empty()) {
    if (std::filesystem::exists(options.map_path)) {
      session->publishMap(loadMapFor(*session, options.map_path));
      message = "map " + options.map_path + " loaded";
    } else {
      message = "no map at " + options.map_path + " yet: press A to calibrate, S to save it there";
    }
  } else {
    message = "no map: press A to calibrate (or start with --map FILE)";
  }
  session->setScript(&script);

  gl::Window window(options.width > 0 ? options.width : 1024,
                    options.height > 0 ? options.height : 768, "autograv-demo - " + options.device);
  gl::Renderer renderer(window, rendererOptions(options));
  std::printf("autograv-demo: OpenGL %s, shaders %s\n", renderer.glVersion().c_str(),
              renderer.shaderOrigin().c_str());
  DemoView view(upperCase(options.device));
  gl::OrbitCamera camera = initialCamera(*session);
  auto message_time = std::chrono::steady_clock::now();
  const auto say = [&](const std::string& text) {
    message = text;
    message_time = std::chrono::steady_clock::now();
    std::printf("%s\n", text.c_str());
  };
  bool show_map = true;
  bool show_workspace = true;  // the map's explored workspace (W)

  struct Drag {
    bool hand = false;
    bool view = false;
    double x0 = 0.0, y0 = 0.0, last_x = 0.0, last_y = 0.0;
    Eigen::Vector3d anchor_m = Eigen::Vector3d::Zero();
  } drag;

  gl::WindowCallbacks callbacks;
  callbacks.on_mouse_button = [&](gl::MouseButton button, bool pressed, double x, double y) {
    try {
      if (button == gl::MouseButton::kLeft) {
        if (pressed) {
          drag.hand = true;
          drag.x0 = x;
          drag.y0 = y;
          drag.anchor_m = session->snapshot().position_m;
          session->grab();
        } else if (drag.hand) {
          drag.hand = false;
          session->release();
        }
      } else {
        drag.view = pressed;
        drag.last_x = x;
        drag.last_y = y;
      }
    } catch (const Error& error) {
      say(error.what());
    }
  };
  callbacks.on_cursor_move = [&](double x, double y) {
    try {
      if (drag.hand) {
        session->setHandTarget(drag.anchor_m + camera.dragDelta_m(x - drag.x0, y - drag.y0,
                                                                  drag.anchor_m,
                                                                  window.framebufferHeight()));
      }
      if (drag.view) {
        camera.orbit(x - drag.last_x, y - drag.last_y);
        drag.last_x = x;
        drag.last_y = y;
      }
    } catch (const Error& error) {
      say(error.what());
    }
  };
  callbacks.on_scroll = [&](double notches) { camera.zoom(notches); };
  callbacks.on_key = [&](int key) {
    try {
      switch (key) {
        case 'C': {
          const bool enable = !session->snapshot().compensation_enabled;
          session->setCompensationEnabled(enable);
          say(enable ? "compensation on (ramping in)" : "compensation off (ramping out)");
          break;
        }
        case 'A':
          if (session->calibrationRunning()) {
            session->abortCalibration();
            say("calibration: aborting, finished vertices are kept");
          } else {
            say(session->startCalibration());
          }
          break;
        case gl::kKeyEnter:
          session->postCalibrationEvent(WizardEvent::kConfirm);
          break;
        case 'P':
          if (const WizardStatus* status = session->calibrationStatus()) {
            session->postCalibrationEvent(status->paused ? WizardEvent::kResume
                                                         : WizardEvent::kPause);
          }
          break;
        case 'X':
          session->postCalibrationEvent(WizardEvent::kRedoFailed);
          break;
        case 'S':
          if (const auto map = session->map()) {
            saveMap(*map, map_path);
            say("map saved to " + map_path);
          } else {
            say("no map to save yet: press A to calibrate");
          }
          break;
        case 'L':
          if (session->calibrationRunning()) {
            say("a calibration is running: press A to abort it first");
            break;
          }
          session->publishMap(loadMapFor(*session, map_path));
          camera = initialCamera(*session);
          say("map loaded from " + map_path);
          break;
        case 'G':
          show_map = !show_map;
          break;
        case 'W':
          show_workspace = !show_workspace;
          break;
        case 'R':
          camera = initialCamera(*session);
          break;
        case 'Q':
        case gl::kKeyEscape:
          window.requestClose();
          break;
        default:
          break;
      }
    } catch (const Error& error) {
      say(std::string("error: ") + error.what());
    }
  };
  window.setCallbacks(callbacks);

  session->startRealTime();
  const auto start = std::chrono::steady_clock::now();
  const char* const help =
      "LEFT DRAG: HAND  RIGHT DRAG: VIEW  C: COMPENSATION  A: CALIBRATE  ENTER: CONFIRM  "
      "S/L: SAVE/LOAD  Q: QUIT";
  RgbImage last_frame;
  while (!window.shouldClose()) {
    window.pollEvents();
    const std::string update = session->updateCalibration();
    if (!update.empty()) say(update);
    const ServoSnapshot& snapshot = session->snapshot();
    view.record(snapshot);
    const bool recent = std::chrono::steady_clock::now() - message_time <
                        std::chrono::duration<double>(kMessageSeconds);
    gl::Scene scene = frameScene(view, snapshot, *session, camera, false,
                                 recent && !message.empty() ? upperCase(message) : help);
    scene.show_arrows = show_map;
    scene.show_grid = show_map;
    scene.show_measurements = show_map;
    scene.show_workspace = show_workspace;
    renderer.render(scene);
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const bool last = options.seconds > 0.0 && elapsed_s >= options.seconds;
    if (last && !options.screenshot.empty()) last_frame = window.readImage();
    window.swapBuffers();
    if (last) break;
  }
  session->stopRealTime();
  if (!options.screenshot.empty() && last_frame.width_px > 0) {
    gl::writePng(last_frame, options.screenshot);
    std::printf("screenshot %s\n", options.screenshot.c_str());
  }
  const ServoSnapshot& final_state = session->snapshot();
  std::printf("%s\n", describeTiming(final_state.timing).c_str());
  return 0;
}

}  // namespace autograv::demo
