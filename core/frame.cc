#include "core/frame.h"

#include <algorithm>
#include <string>

#include "core/errors.h"

namespace ihs {

Frame Frame::Blank(int width, int height, bool with_color) {
  Frame frame;
  frame.width = width;
  frame.height = height;
  frame.depth_mm.assign(static_cast<size_t>(width) * height, 0);
  if (with_color) frame.rgb.assign(static_cast<size_t>(width) * height * 3, 0);
  return frame;
}

int Frame::ValidDepthCount() const {
  return static_cast<int>(
      std::count_if(depth_mm.begin(), depth_mm.end(), [](std::uint16_t d) { return d != 0; }));
}

void Frame::Check() const {
  const std::string where = "frame " + std::to_string(index) + ": ";
  if (width <= 0 || height <= 0) {
    throw InputError(where + "size " + std::to_string(width) + "x" + std::to_string(height) +
                     " is not positive");
  }
  const size_t pixels = static_cast<size_t>(width) * height;
  if (depth_mm.size() != pixels) {
    throw InputError(where + "depth has " + std::to_string(depth_mm.size()) + " values, expected " +
                     std::to_string(pixels));
  }
  if (!rgb.empty() && rgb.size() != pixels * 3) {
    throw InputError(where + "colour has " + std::to_string(rgb.size()) + " bytes, expected " +
                     std::to_string(pixels * 3));
  }
}

}  // namespace ihs
