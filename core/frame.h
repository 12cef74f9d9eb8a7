#pragma once
// One RGB-D frame as it comes from a sensor: depth in millimetres and colour registered to it.

#include <cstdint>
#include <vector>

namespace ihs {

/// An RGB-D frame. Depth and colour share one pixel grid (depth registered to colour); pixel
/// (u, v) is column u, row v, row-major. Immutable once a sensor has delivered it.
struct Frame {
  /// Width of both images in pixels.
  int width = 0;
  /// Height of both images in pixels.
  int height = 0;
  /// Depth in millimetres, width·height values, 0 = no measurement.
  std::vector<std::uint16_t> depth_mm;
  /// Colour as RGB8 triplets, width·height·3 bytes; empty when the source has no colour.
  std::vector<std::uint8_t> rgb;
  /// Device timestamp of the depth image, microseconds.
  std::int64_t depth_timestamp_us = 0;
  /// Device timestamp of the colour image, microseconds.
  std::int64_t color_timestamp_us = 0;
  /// Index of the frame in its stream, counting from 0.
  std::int64_t index = 0;

  /// A frame of the given size with zero depth and black colour.
  static Frame Blank(int width, int height, bool with_color = true);

  /// Number of pixels.
  int PixelCount() const { return width * height; }
  /// Depth at pixel (u, v) in mm (0 = invalid); (u, v) must be inside the image.
  std::uint16_t DepthAt(int u, int v) const { return depth_mm[v * width + u]; }
  /// Whether the frame has a colour image.
  bool HasColor() const { return !rgb.empty(); }
  /// Number of pixels with a depth measurement.
  int ValidDepthCount() const;
  /// Throws ihs::InputError unless the sizes are consistent (positive size, depth of
  /// width·height values, colour empty or of width·height·3 bytes).
  void Check() const;
};

}  // namespace ihs
