#pragma once
// The live window (GLFW): shows an RGB image the application composes and reports key presses.
// GLFW's headers stay in the .cc file. Must be created, used and destroyed on one thread (the
// process's main thread, as GLFW requires).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ihs::render {

/// What the user did in the window since the last poll.
struct WindowInput {
  /// Keys pressed, as lower-case ASCII characters ('s', 'r', 'q', …; Escape is reported as 'q').
  std::vector<char> keys;
  /// How far the mouse moved with its left button held (a drag), window pixels; y down.
  double drag_x = 0;
  double drag_y = 0;
};

/// A window that displays RGB8 images.
class LiveWindow {
 public:
  /// Opens a window of `width`×`height` pixels. Throws ihs::DeviceError (with GLFW's reason, e.g.
  /// no display) when it cannot.
  LiveWindow(const std::string& title, int width, int height);
  ~LiveWindow();
  LiveWindow(const LiveWindow&) = delete;
  LiveWindow& operator=(const LiveWindow&) = delete;

  /// Draws `rgb` (width·height·3 bytes, row-major from the top-left pixel), scaled to the window.
  void Show(const std::vector<std::uint8_t>& rgb, int width, int height);
  /// Processes window events; returns the keys pressed and the mouse dragged since the last
  /// call.
  WindowInput PollInput();
  /// What the window shows now, read back from its front buffer: RGB8, row-major from the
  /// top-left pixel, `*width`×`*height` pixels.
  std::vector<std::uint8_t> Screenshot(int* width, int* height);
  /// Whether the user closed the window.
  bool ShouldClose() const;

 private:
  // Draws the image shown last into the back buffer.
  void Draw();

  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace ihs::render
