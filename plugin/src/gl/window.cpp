#include "autograv/gl/window.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <GL/glcorearb.h>

#include <atomic>
#include <string>

#include "autograv/error.h"

namespace autograv::gl {

namespace {

std::atomic<bool> g_window_open{false};
std::string g_last_glfw_error;

void recordGlfwError(int code, const char* description) {
  g_last_glfw_error = "GLFW error " + std::to_string(code) + ": " +
                      (description != nullptr ? description : "(no description)");
}

int translateKey(int key) {
  if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) return 'A' + (key - GLFW_KEY_A);
  if (key >= GLFW_KEY_0 && key <= GLFW_KEY_9) return '0' + (key - GLFW_KEY_0);
  switch (key) {
    case GLFW_KEY_SPACE:
      return ' ';
    case GLFW_KEY_ESCAPE:
      return kKeyEscape;
    case GLFW_KEY_ENTER:
      return kKeyEnter;
    case GLFW_KEY_TAB:
      return kKeyTab;
    case GLFW_KEY_BACKSPACE:
      return kKeyBackspace;
    default:
      return kKeyOther;
  }
}

}  // namespace

struct Window::State {
  GLFWwindow* window = nullptr;
  WindowCallbacks callbacks;

  /// Framebuffer pixels per screen unit (2 on a HiDPI screen).
  double pixelScale() const {
    int window_w = 1;
    int framebuffer_w = 1;
    int height = 0;
    glfwGetWindowSize(window, &window_w, &height);
    glfwGetFramebufferSize(window, &framebuffer_w, &height);
    return window_w > 0 ? static_cast<double>(framebuffer_w) / window_w : 1.0;
  }
  static State& of(GLFWwindow* window) {
    return *static_cast<State*>(glfwGetWindowUserPointer(window));
  }
};

Window::Window(int width, int height, const std::string& title, bool vsync)
    : state_(std::make_unique<State>()) {
  if (g_window_open.exchange(true)) {
    throw Error("only one autograv::gl::Window can be open at a time");
  }
  glfwSetErrorCallback(&recordGlfwError);
  if (glfwInit() != GLFW_TRUE) {
    g_window_open = false;
    throw Error("cannot start GLFW (" + g_last_glfw_error +
                "); is there a display? Without one, run headless (OSMesa) instead");
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  state_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (state_->window == nullptr) {
    glfwTerminate();
    g_window_open = false;
    throw Error("cannot open a window with an OpenGL 3.3 core context (" + g_last_glfw_error + ")");
  }
  glfwSetWindowUserPointer(state_->window, state_.get());
  glfwMakeContextCurrent(state_->window);
  glfwSwapInterval(vsync ? 1 : 0);

  glfwSetKeyCallback(state_->window, [](GLFWwindow* w, int key, int, int action, int) {
    State& state = State::of(w);
    if (action != GLFW_RELEASE && state.callbacks.on_key) state.callbacks.on_key(translateKey(key));
  });
  glfwSetMouseButtonCallback(state_->window, [](GLFWwindow* w, int button, int action, int) {
    State& state = State::of(w);
    if (!state.callbacks.on_mouse_button) return;
    MouseButton which = MouseButton::kLeft;
    if (button == GLFW_MOUSE_BUTTON_RIGHT) which = MouseButton::kRight;
    if (button == GLFW_MOUSE_BUTTON_MIDDLE) which = MouseButton::kMiddle;
    double x = 0.0;
    double y = 0.0;
    glfwGetCursorPos(w, &x, &y);
    const double scale = state.pixelScale();
    state.callbacks.on_mouse_button(which, action == GLFW_PRESS, x * scale, y * scale);
  });
  glfwSetCursorPosCallback(state_->window, [](GLFWwindow* w, double x, double y) {
    State& state = State::of(w);
    const double scale = state.pixelScale();
    if (state.callbacks.on_cursor_move) state.callbacks.on_cursor_move(x * scale, y * scale);
  });
  glfwSetScrollCallback(state_->window, [](GLFWwindow* w, double, double y) {
    State& state = State::of(w);
    if (state.callbacks.on_scroll) state.callbacks.on_scroll(y);
  });
}

Window::~Window() {
  glfwDestroyWindow(state_->window);
  glfwTerminate();
  g_window_open = false;
}

void Window::makeCurrent() { glfwMakeContextCurrent(state_->window); }

int Window::framebufferWidth() const {
  int width = 0;
  int height = 0;
  glfwGetFramebufferSize(state_->window, &width, &height);
  return width;
}

int Window::framebufferHeight() const {
  int width = 0;
  int height = 0;
  glfwGetFramebufferSize(state_->window, &width, &height);
  return height;
}

GlProcLoader Window::procLoader() const { return &glfwGetProcAddress; }

void Window::setCallbacks(WindowCallbacks callbacks) { state_->callbacks = std::move(callbacks); }
void Window::pollEvents() { glfwPollEvents(); }
void Window::swapBuffers() { glfwSwapBuffers(state_->window); }
bool Window::shouldClose() const { return glfwWindowShouldClose(state_->window) == GLFW_TRUE; }
void Window::requestClose() { glfwSetWindowShouldClose(state_->window, GLFW_TRUE); }
void Window::setTitle(const std::string& title) {
  glfwSetWindowTitle(state_->window, title.c_str());
}

RgbImage Window::readImage() {
  const auto finish = reinterpret_cast<PFNGLFINISHPROC>(glfwGetProcAddress("glFinish"));
  const auto pixel_store =
      reinterpret_cast<PFNGLPIXELSTOREIPROC>(glfwGetProcAddress("glPixelStorei"));
  const auto read_buffer =
      reinterpret_cast<PFNGLREADBUFFERPROC>(glfwGetProcAddress("glReadBuffer"));
  const auto read_pixels =
      reinterpret_cast<PFNGLREADPIXELSPROC>(glfwGetProcAddress("glReadPixels"));
  if (finish == nullptr || pixel_store == nullptr || read_buffer == nullptr ||
      read_pixels == nullptr) {
    throw Error("the window's GL context lacks glReadPixels; cannot take a screenshot");
  }
  RgbImage image;
  image.width_px = framebufferWidth();
  image.height_px = framebufferHeight();
  std::vector<std::uint8_t> bottom_up(static_cast<std::size_t>(image.width_px) * image.height_px *
                                      3);
  finish();
  read_buffer(GL_BACK);
  pixel_store(GL_PACK_ALIGNMENT, 1);
  read_pixels(0, 0, image.width_px, image.height_px, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
  image.rgb.resize(bottom_up.size());
  const std::size_t row = static_cast<std::size_t>(image.width_px) * 3;
  for (int y = 0; y < image.height_px; ++y) {
    std::copy_n(bottom_up.data() + static_cast<std::size_t>(image.height_px - 1 - y) * row, row,
                image.rgb.data() + static_cast<std::size_t>(y) * row);
  }
  return image;
}

}  // namespace autograv::gl
