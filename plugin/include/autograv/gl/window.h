#pragma once

#include <functional>
#include <memory>
#include <string>

#include "autograv/gl/gl_context.h"
#include "autograv/image/rgb_image.h"

namespace autograv::gl {

/// Keys the window reports: printable keys as their upper-case ASCII code ('A', '1', ' '), the rest
/// as these codes.
enum WindowKey : int {
  kKeyEscape = 256,
  kKeyEnter = 257,
  kKeyTab = 258,
  kKeyBackspace = 259,
  kKeyOther = 511,
};

/// Mouse buttons the window reports.
enum class MouseButton { kLeft, kRight, kMiddle };

/// What the application hears from the window. Called on the thread that calls pollEvents().
struct WindowCallbacks {
  /// A key went down (repeats included). `key` is a WindowKey or an upper-case ASCII code.
  std::function<void(int key)> on_key;
  /// A button went down (`pressed` true) or up, at the cursor position. Unit: [px], from the
  /// top-left corner of the framebuffer.
  std::function<void(MouseButton button, bool pressed, double x_px, double y_px)> on_mouse_button;
  /// The cursor moved. Unit: [px], framebuffer pixels from the top-left corner.
  std::function<void(double x_px, double y_px)> on_cursor_move;
  /// The wheel turned; positive away from the user. Unit: [notches]
  std::function<void(double notches)> on_scroll;
};

/// A desktop window with an OpenGL 3.3 core context, through GLFW. Needs a display (X11 or an
/// Xvfb); use OffscreenContext without one. One Window per process at a time.
class Window final : public GlContext {
 public:
  /// Opens the window and makes its context current on the calling thread. Throws
  /// autograv::Error when GLFW cannot start (no display) or cannot give a 3.3 core context.
  /// Not real-time safe.
  Window(int width, int height, const std::string& title, bool vsync = true);
  ~Window() override;
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  void makeCurrent() override;
  int framebufferWidth() const override;
  /// Height of the window's framebuffer. Unit: [px]
  int framebufferHeight() const override;
  GlProcLoader procLoader() const override;

  /// Replaces the event callbacks. Not real-time safe.
  void setCallbacks(WindowCallbacks callbacks);
  /// Dispatches pending events to the callbacks. Not real-time safe.
  void pollEvents();
  /// Shows the frame just drawn. Not real-time safe.
  void swapBuffers();
  /// True once the user asked to close the window (or requestClose() was called).
  bool shouldClose() const;
  /// Makes shouldClose() true, as closing the window does. Not real-time safe.
  void requestClose();
  /// Sets the window's title bar text. Not real-time safe.
  void setTitle(const std::string& title);
  /// Reads the back buffer (call after drawing, before swapBuffers). Not real-time safe.
  RgbImage readImage();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace autograv::gl
