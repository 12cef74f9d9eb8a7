#include "tools/bench/plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"

namespace ihs::bench {
namespace {

cv::Scalar Bgr(const std::array<std::uint8_t, 3>& rgb) {
  return cv::Scalar(rgb[2], rgb[1], rgb[0]);
}

// A step of 1, 2 or 5 × 10^k giving about `target` intervals over `span`.
double NiceStep(double span, int target) {
  const double raw = span / std::max(1, target);
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * magnitude >= raw) return m * magnitude;
  return 10 * magnitude;
}

std::string TickLabel(double value, double step) {
  char text[32];
  if (step >= 1 || step <= 0) {
    std::snprintf(text, sizeof(text), "%.0f", value);
  } else {
    const int decimals = std::min(6, static_cast<int>(std::ceil(-std::log10(step))));
    std::snprintf(text, sizeof(text), "%.*f", decimals, value);
  }
  return text;
}

void WritePng(const cv::Mat& image, const std::filesystem::path& path) {
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image);
  } catch (const cv::Exception&) {
    ok = false;
  }
  if (!ok) throw OutputError(path.string() + ": cannot write the image");
}

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

}  // namespace

std::array<std::uint8_t, 3> PaletteColor(int i) {
  static const std::array<std::uint8_t, 3> kPalette[] = {
      {0, 114, 178}, {213, 94, 0},   {0, 158, 115},   {204, 121, 167},
      {230, 159, 0}, {86, 180, 233}, {120, 120, 120}, {0, 0, 0}};
  return kPalette[static_cast<size_t>(i) % (sizeof(kPalette) / sizeof(kPalette[0]))];
}

void WriteChartPng(const Chart& chart, const std::filesystem::path& path) {
  cv::Mat image(chart.height, chart.width, CV_8UC3, cv::Scalar(255, 255, 255));
  auto ty = [&](double y) { return chart.log_y ? std::log10(y) : y; };
  auto usable = [&](double x, double y) {
    return std::isfinite(x) && std::isfinite(y) && (!chart.log_y || y > 0);
  };
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Series& s : chart.series) {
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!usable(s.x[i], s.y[i])) continue;
      x0 = std::min(x0, s.x[i]);
      x1 = std::max(x1, s.x[i]);
      y0 = std::min(y0, ty(s.y[i]));
      y1 = std::max(y1, ty(s.y[i]));
    }
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  if (x1 <= x0) x1 = x0 + 1;
  if (!chart.log_y) y0 = std::min(y0, 0.0);
  if (y1 <= y0) y1 = y0 + 1;
  const double y_step = chart.log_y ? 1.0 : NiceStep(y1 - y0, 6);
  y0 = std::floor(y0 / y_step) * y_step;
  y1 = std::ceil(y1 / y_step - 1e-9) * y_step;
  const double x_step = NiceStep(x1 - x0, 8);

  // Plot area.
  const int left = 70, right = chart.width - 170, top = 36, bottom = chart.height - 50;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * (right - left); };
  auto py = [&](double y) { return bottom - (ty(y) - y0) / (y1 - y0) * (bottom - top); };
  const cv::Scalar grid(225, 225, 225), ink(40, 40, 40);
  for (double y = y0; y <= y1 + 1e-9; y += y_step) {
    const int v = static_cast<int>(std::lround(bottom - (y - y0) / (y1 - y0) * (bottom - top)));
    cv::line(image, {left, v}, {right, v}, grid, 1);
    const std::string label =
        chart.log_y ? TickLabel(std::pow(10.0, y), std::pow(10.0, y)) : TickLabel(y, y_step);
    cv::putText(image, label, {8, v + 4}, kFont, 0.4, ink, 1, cv::LINE_AA);
  }
  for (double x = std::ceil(x0 / x_step) * x_step; x <= x1 + 1e-9; x += x_step) {
    const int u = static_cast<int>(std::lround(px(x)));
    cv::line(image, {u, top}, {u, bottom}, grid, 1);
    cv::putText(image, TickLabel(x, x_step), {u - 10, bottom + 16}, kFont, 0.4, ink, 1,
                cv::LINE_AA);
  }
  cv::rectangle(image, {left, top}, {right, bottom}, ink, 1);
  cv::putText(image, chart.title, {left, 22}, kFont, 0.55, ink, 1, cv::LINE_AA);
  cv::putText(image, chart.x_label, {(left + right) / 2 - 40, chart.height - 14}, kFont, 0.45, ink,
              1, cv::LINE_AA);
  cv::putText(image, chart.y_label, {left + 4, top + 14}, kFont, 0.4, ink, 1, cv::LINE_AA);

  // Lines, then the legend.
  for (size_t k = 0; k < chart.series.size(); ++k) {
    const Series& s = chart.series[k];
    const cv::Scalar color = Bgr(s.color);
    bool have_previous = false;
    cv::Point2d previous;
    int segment = 0;
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!usable(s.x[i], s.y[i])) {
        have_previous = false;
        continue;
      }
      const cv::Point2d p(px(s.x[i]), py(s.y[i]));
      if (have_previous && (!s.dashed || (segment++ / 3) % 2 == 0))
        cv::line(image, previous, p, color, 2, cv::LINE_AA);
      if (s.markers) cv::circle(image, p, 4, color, cv::FILLED, cv::LINE_AA);
      previous = p;
      have_previous = true;
    }
    const int v = top + 12 + static_cast<int>(k) * 20;
    cv::line(image, {right + 12, v - 4}, {right + 36, v - 4}, color, 2, cv::LINE_AA);
    cv::putText(image, s.name, {right + 42, v}, kFont, 0.42, ink, 1, cv::LINE_AA);
  }
  WritePng(image, path);
}

void WriteTileGridPng(const std::vector<Tile>& tiles, int width, int height, int columns,
                      const std::filesystem::path& path) {
  if (tiles.empty() || width <= 0 || height <= 0 || columns <= 0)
    throw OutputError(path.string() + ": no images to place");
  const int caption = 24;
  const int rows = (static_cast<int>(tiles.size()) + columns - 1) / columns;
  const int cols = std::min<int>(columns, static_cast<int>(tiles.size()));
  cv::Mat grid(rows * (height + caption), cols * width, CV_8UC3, cv::Scalar(255, 255, 255));
  for (size_t i = 0; i < tiles.size(); ++i) {
    const int r = static_cast<int>(i) / columns, c = static_cast<int>(i) % columns;
    const cv::Rect cell(c * width, r * (height + caption) + caption, width, height);
    if (tiles[i].rgb.size() == static_cast<size_t>(width) * height * 3) {
      const cv::Mat rgb(height, width, CV_8UC3, const_cast<std::uint8_t*>(tiles[i].rgb.data()));
      cv::cvtColor(rgb, grid(cell), cv::COLOR_RGB2BGR);
    }
    cv::putText(grid, tiles[i].caption, {c * width + 6, r * (height + caption) + 17}, kFont, 0.5,
                cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
  }
  WritePng(grid, path);
}

}  // namespace ihs::bench
