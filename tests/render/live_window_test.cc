// The GLFW live window on a virtual X server (Xvfb): it shows an image exactly as given (read
// back from the window), and without a display it says so with a DeviceError.

#include "render/live_window.h"

#include <gtest/gtest.h>

#include <array>
#include <cstdlib>
#include <string>

#include "core/errors.h"
#include "tests/test_util.h"

namespace ihs::render {
namespace {

TEST(LiveWindowTest, ShowsAnImageAsGiven) {
  test::VirtualDisplay display(320, 240);
  if (!display.ok()) GTEST_SKIP() << "no Xvfb (Debian package xvfb) to open a window on";
  setenv("DISPLAY", display.name().c_str(), 1);
  LiveWindow window("test", 64, 48);
  // Left half red, right half blue, a green bottom row.
  std::vector<std::uint8_t> rgb(64 * 48 * 3);
  for (int v = 0; v < 48; ++v) {
    for (int u = 0; u < 64; ++u) {
      std::uint8_t* p = &rgb[(v * 64 + u) * 3];
      if (v == 47) {
        p[1] = 255;
      } else if (u < 32) {
        p[0] = 255;
      } else {
        p[2] = 255;
      }
    }
  }
  window.Show(rgb, 64, 48);
  const WindowInput input = window.PollInput();
  EXPECT_TRUE(input.keys.empty());
  EXPECT_EQ(input.drag_x, 0.0);
  EXPECT_EQ(input.drag_y, 0.0);
  EXPECT_FALSE(window.ShouldClose());
  int width = 0, height = 0;
  const std::vector<std::uint8_t> shot = window.Screenshot(&width, &height);
  ASSERT_EQ(width, 64);
  ASSERT_EQ(height, 48);
  auto pixel = [&](int u, int v) {
    const std::uint8_t* p = &shot[(v * width + u) * 3];
    return std::array<int, 3>{p[0], p[1], p[2]};
  };
  EXPECT_EQ(pixel(5, 5), (std::array<int, 3>{255, 0, 0}));
  EXPECT_EQ(pixel(60, 20), (std::array<int, 3>{0, 0, 255}));
  EXPECT_EQ(pixel(30, 47), (std::array<int, 3>{0, 255, 0}));  // Not upside down.
}

TEST(LiveWindowTest, WithoutADisplayItIsADeviceError) {
  const char* saved = std::getenv("DISPLAY");
  const std::string restore = saved ? saved : "";
  unsetenv("DISPLAY");
  unsetenv("WAYLAND_DISPLAY");
  try {
    LiveWindow window("test", 64, 48);
    ADD_FAILURE() << "a window opened without a display";
  } catch (const DeviceError& error) {
    EXPECT_NE(std::string(error.what()).find("cannot open a window"), std::string::npos);
  }
  if (!restore.empty()) setenv("DISPLAY", restore.c_str(), 1);
}

}  // namespace
}  // namespace ihs::render
