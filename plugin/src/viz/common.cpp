#include "autograv/viz/common.h"

#include <chrono>
#include <cstdlib>
#include <thread>

#include "autograv/error.h"
#include "viz/enum_names.h"
#include "viz/vtk_support.h"

// Xlib last: it defines macros (None, Status, Bool) that clash with other headers.
#include <X11/Xlib.h>

namespace autograv::viz {

namespace {

constexpr std::pair<Background, const char*> kBackgroundNames[] = {{Background::kWhite, "white"},
                                                                   {Background::kDark, "dark"}};
constexpr std::pair<ColorMap, const char*> kColorMapNames[] = {{ColorMap::kViridis, "viridis"},
                                                               {ColorMap::kCoolWarm, "coolwarm"},
                                                               {ColorMap::kGrayscale, "grayscale"}};

}  // namespace

const char* toString(Background background) noexcept {
  return detail::nameIn(kBackgroundNames, background);
}

bool parseBackground(const std::string& name, Background& background) noexcept {
  return detail::parseIn(kBackgroundNames, name, background);
}

const char* toString(ColorMap color_map) noexcept {
  return detail::nameIn(kColorMapNames, color_map);
}

bool parseColorMap(const std::string& name, ColorMap& color_map) noexcept {
  return detail::parseIn(kColorMapNames, name, color_map);
}

namespace detail {

void* openXDisplay(std::string* reason) {
  const char* name = std::getenv("DISPLAY");
  if (name == nullptr || *name == '\0') {
    if (reason != nullptr) {
      *reason =
          "no X display: DISPLAY is not set. VTK 9.1 as packaged by Debian renders through X "
          "even offscreen; run under a virtual display, e.g. `xvfb-run -a <command>` "
          "(package xvfb)";
    }
    return nullptr;
  }
  // A busy Xvfb now and then hangs up on a new client right after accepting it; a few retries
  // ride that out, while a server that is not there fails within about a second.
  constexpr int kAttempts = 20;
  for (int attempt = 0; attempt < kAttempts; ++attempt) {
    if (Display* display = XOpenDisplay(nullptr)) return display;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  if (reason != nullptr) {
    *reason = std::string("cannot open X display \"") + name +
              "\": no X server answers there. Start one or run under a virtual display, e.g. "
              "`xvfb-run -a <command>` (package xvfb)";
  }
  return nullptr;
}

void closeXDisplay(void* display) noexcept {
  if (display != nullptr) XCloseDisplay(static_cast<Display*>(display));
}

}  // namespace detail

bool displayAvailable(std::string* reason) {
  void* display = detail::openXDisplay(reason);
  detail::closeXDisplay(display);
  return display != nullptr;
}

void requireDisplay() {
  std::string reason;
  if (!displayAvailable(&reason)) throw Error(reason);
}

}  // namespace autograv::viz
