#include "tests/frame_fixtures.h"

namespace ihs::test {

Frame MakePatternFrame(std::int64_t index, int width, int height) {
  Frame frame = Frame::Blank(width, height);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const int i = v * width + u;
      const bool hole = (u * 7 + v * 13 + index) % 29 == 0;
      frame.depth_mm[i] =
          hole ? 0 : static_cast<std::uint16_t>(400 + (u * 3 + v * 2 + index * 5) % 1600);
      frame.rgb[3 * i + 0] = static_cast<std::uint8_t>(u + index);
      frame.rgb[3 * i + 1] = static_cast<std::uint8_t>(v * 2);
      frame.rgb[3 * i + 2] = static_cast<std::uint8_t>((u ^ v) + 3 * index);
    }
  }
  frame.index = index;
  frame.depth_timestamp_us = 1'000'000 + index * 33'333;
  frame.color_timestamp_us = frame.depth_timestamp_us + 1'000;
  return frame;
}

std::vector<Frame> MakePatternFrames(int count, int width, int height) {
  std::vector<Frame> frames;
  for (int i = 0; i < count; ++i) frames.push_back(MakePatternFrame(i, width, height));
  return frames;
}

}  // namespace ihs::test
