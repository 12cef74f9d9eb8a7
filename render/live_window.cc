#include "render/live_window.h"

#define GLFW_INCLUDE_NONE
#include <GL/gl.h>
#include <GLFW/glfw3.h>

#include <algorithm>
#include <mutex>
#include <utility>

#include "core/errors.h"

namespace ihs::render {
namespace {

std::mutex error_mutex;
std::string last_glfw_error;

void RememberError(int code, const char* description) {
  std::lock_guard<std::mutex> lock(error_mutex);
  last_glfw_error = description ? description : "unknown GLFW error";
}

std::string TakeError() {
  std::lock_guard<std::mutex> lock(error_mutex);
  return last_glfw_error.empty() ? "unknown reason" : last_glfw_error;
}

}  // namespace

// The OpenGL functions the window uses, from the window's own context (glfwGetProcAddress):
// this library also links OSMesa, whose gl* symbols the off-screen renderer calls, so the
// window must not call gl* by name.
struct GlFunctions {
  void (*Viewport)(GLint, GLint, GLsizei, GLsizei) = nullptr;
  void (*ClearColor)(GLfloat, GLfloat, GLfloat, GLfloat) = nullptr;
  void (*Clear)(GLbitfield) = nullptr;
  void (*MatrixMode)(GLenum) = nullptr;
  void (*LoadIdentity)() = nullptr;
  void (*RasterPos2f)(GLfloat, GLfloat) = nullptr;
  void (*PixelZoom)(GLfloat, GLfloat) = nullptr;
  void (*PixelStorei)(GLenum, GLint) = nullptr;
  void (*DrawPixels)(GLsizei, GLsizei, GLenum, GLenum, const void*) = nullptr;
  void (*ReadBuffer)(GLenum) = nullptr;
  void (*ReadPixels)(GLint, GLint, GLsizei, GLsizei, GLenum, GLenum, void*) = nullptr;
  void (*Finish)() = nullptr;

  template <typename F>
  static void Load(F*& function, const char* name) {
    function = reinterpret_cast<F*>(glfwGetProcAddress(name));
    if (!function) throw DeviceError(std::string("cannot open a window: OpenGL lacks ") + name);
  }
  void LoadAll() {
    Load(Viewport, "glViewport");
    Load(ClearColor, "glClearColor");
    Load(Clear, "glClear");
    Load(MatrixMode, "glMatrixMode");
    Load(LoadIdentity, "glLoadIdentity");
    Load(RasterPos2f, "glRasterPos2f");
    Load(PixelZoom, "glPixelZoom");
    Load(PixelStorei, "glPixelStorei");
    Load(DrawPixels, "glDrawPixels");
    Load(ReadBuffer, "glReadBuffer");
    Load(ReadPixels, "glReadPixels");
    Load(Finish, "glFinish");
  }
};

struct LiveWindow::State {
  GLFWwindow* window = nullptr;
  GlFunctions gl;
  WindowInput input;  // Since the last PollInput().
  // Where the cursor was when last seen with the left button held (none: not dragging).
  bool dragging = false;
  double cursor_x = 0, cursor_y = 0;
  // The image shown last, drawn again for a screenshot.
  std::vector<std::uint8_t> shown;
  int shown_width = 0;
  int shown_height = 0;
};

LiveWindow::LiveWindow(const std::string& title, int width, int height)
    : state_(std::make_unique<State>()) {
  glfwSetErrorCallback(RememberError);
  if (!glfwInit()) throw DeviceError("cannot open a window: " + TakeError());
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  state_->window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!state_->window) {
    const std::string error = TakeError();
    glfwTerminate();
    throw DeviceError("cannot open a window: " + error);
  }
  glfwMakeContextCurrent(state_->window);
  try {
    state_->gl.LoadAll();
  } catch (...) {
    glfwDestroyWindow(state_->window);
    glfwTerminate();
    throw;
  }
  glfwSwapInterval(0);
  glfwSetWindowUserPointer(state_->window, state_.get());
  glfwSetKeyCallback(state_->window, [](GLFWwindow* window, int key, int, int action, int) {
    if (action != GLFW_PRESS) return;
    auto* state = static_cast<State*>(glfwGetWindowUserPointer(window));
    if (key == GLFW_KEY_ESCAPE) {
      state->input.keys.push_back('q');
    } else if (key >= GLFW_KEY_A && key <= GLFW_KEY_Z) {
      state->input.keys.push_back(static_cast<char>('a' + (key - GLFW_KEY_A)));
    }
  });
  glfwSetMouseButtonCallback(state_->window, [](GLFWwindow* window, int button, int action, int) {
    if (button != GLFW_MOUSE_BUTTON_LEFT) return;
    auto* state = static_cast<State*>(glfwGetWindowUserPointer(window));
    state->dragging = action == GLFW_PRESS;
    if (state->dragging) glfwGetCursorPos(window, &state->cursor_x, &state->cursor_y);
  });
  glfwSetCursorPosCallback(state_->window, [](GLFWwindow* window, double x, double y) {
    auto* state = static_cast<State*>(glfwGetWindowUserPointer(window));
    if (!state->dragging) return;
    state->input.drag_x += x - state->cursor_x;
    state->input.drag_y += y - state->cursor_y;
    state->cursor_x = x, state->cursor_y = y;
  });
}

LiveWindow::~LiveWindow() {
  if (state_->window) glfwDestroyWindow(state_->window);
  glfwTerminate();
}

void LiveWindow::Show(const std::vector<std::uint8_t>& rgb, int width, int height) {
  if (width <= 0 || height <= 0 || rgb.size() < static_cast<std::size_t>(width) * height * 3) {
    return;
  }
  state_->shown = rgb;
  state_->shown_width = width;
  state_->shown_height = height;
  Draw();
  glfwSwapBuffers(state_->window);
}

void LiveWindow::Draw() {
  const std::vector<std::uint8_t>& rgb = state_->shown;
  const int width = state_->shown_width, height = state_->shown_height;
  glfwMakeContextCurrent(state_->window);
  const GlFunctions& gl = state_->gl;
  int window_width = 0, window_height = 0;
  glfwGetFramebufferSize(state_->window, &window_width, &window_height);
  gl.Viewport(0, 0, window_width, window_height);
  gl.ClearColor(0.1f, 0.1f, 0.12f, 1.0f);
  gl.Clear(GL_COLOR_BUFFER_BIT);
  // Images are stored top row first; OpenGL draws bottom-up: start at the top-left corner and
  // zoom by a negative factor vertically.
  const float zoom = std::min(static_cast<float>(window_width) / width,
                              static_cast<float>(window_height) / height);
  gl.MatrixMode(GL_PROJECTION);
  gl.LoadIdentity();
  gl.MatrixMode(GL_MODELVIEW);
  gl.LoadIdentity();
  gl.RasterPos2f(-1.0f, 1.0f);
  gl.PixelZoom(zoom, -zoom);
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  if (!rgb.empty()) gl.DrawPixels(width, height, GL_RGB, GL_UNSIGNED_BYTE, rgb.data());
}

WindowInput LiveWindow::PollInput() {
  glfwPollEvents();
  WindowInput input;
  std::swap(input, state_->input);
  return input;
}

std::vector<std::uint8_t> LiveWindow::Screenshot(int* width, int* height) {
  // Drawn again and read from the back buffer: the front buffer's content is not reliably
  // readable (X servers without compositing, Xvfb).
  Draw();
  const GlFunctions& gl = state_->gl;
  glfwGetFramebufferSize(state_->window, width, height);
  std::vector<std::uint8_t> bottom_up(static_cast<std::size_t>(*width) * *height * 3);
  gl.Finish();
  gl.ReadBuffer(GL_BACK);
  gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
  gl.ReadPixels(0, 0, *width, *height, GL_RGB, GL_UNSIGNED_BYTE, bottom_up.data());
  std::vector<std::uint8_t> rgb(bottom_up.size());
  const std::size_t row = static_cast<std::size_t>(*width) * 3;
  for (int v = 0; v < *height; ++v) {
    std::copy_n(&bottom_up[(*height - 1 - v) * row], row, &rgb[v * row]);
  }
  glfwSwapBuffers(state_->window);
  return rgb;
}

bool LiveWindow::ShouldClose() const { return glfwWindowShouldClose(state_->window); }

}  // namespace ihs::render
