#pragma once
// Line charts as PNG images for the benchmark report (OpenCV's drawing, no plotting library):
// one or more named series of (x, y) points, axes with rounded ticks, a legend.

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace ihs::bench {

/// One line of a chart.
struct Series {
  std::string name;
  std::vector<double> x, y;
  /// RGB8.
  std::array<std::uint8_t, 3> color = {0, 0, 0};
  /// Mark each point with a dot (for a few points, e.g. a parameter sweep).
  bool markers = false;
  /// Dashed (e.g. the ground truth under the estimates).
  bool dashed = false;
};

struct Chart {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  /// Size of the image, pixels.
  int width = 720, height = 420;
  /// Use a logarithmic y axis (all y must be > 0 then; others are left out).
  bool log_y = false;
};

/// A distinct colour for the i-th series (a fixed palette, readable on white).
std::array<std::uint8_t, 3> PaletteColor(int i);

/// Draws `chart` and writes it as a PNG. Series without points are listed in the legend only.
/// Throws ihs::OutputError when the file cannot be written.
void WriteChartPng(const Chart& chart, const std::filesystem::path& path);

/// Places images (RGB8, all of size `width`×`height`) in a grid of `columns` with a caption
/// above each, and writes the grid as a PNG. Throws ihs::OutputError when writing fails.
struct Tile {
  std::string caption;
  std::vector<std::uint8_t> rgb;
};
void WriteTileGridPng(const std::vector<Tile>& tiles, int width, int height, int columns,
                      const std::filesystem::path& path);

}  // namespace ihs::bench
