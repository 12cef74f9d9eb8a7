#include "app/preview.h"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <ostream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "render/offscreen_renderer.h"

namespace ihs::app {

PreviewRenderer::PreviewRenderer(const CameraIntrinsics& intrinsics) {
  render::RendererOptions options;
  options.background = {40, 40, 48};
  renderer_ = std::make_unique<render::OffscreenRenderer>(intrinsics, options);
}

PreviewRenderer::~PreviewRenderer() = default;

RgbImage PreviewRenderer::Draw(const Frame& frame, const ModelView& model,
                               const TriangleMesh* hand) {
  std::vector<render::RenderItem> items;
  if (hand && !hand->faces.empty()) {
    render::RenderItem item;
    item.mesh = hand;
    item.color = {225, 170, 140};
    item.label = render::kHand;
    items.push_back(item);
  }
  const render::RenderOutput rendered = renderer_->Render(items);
  const int width = rendered.width, height = rendered.height;
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  const bool model_fits =
      model.image.width == width && model.image.height == height && model.depth_mm.size() == pixels;

  RgbImage image;
  image.width = 2 * width;
  image.height = height;
  image.rgb.assign(static_cast<std::size_t>(image.width) * height * 3, 0);
  const bool same_size = frame.width == width && frame.height == height;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * width + u;
      std::uint8_t* left = &image.rgb[(static_cast<std::size_t>(v) * image.width + u) * 3];
      if (same_size && frame.HasColor()) {
        std::copy_n(&frame.rgb[i * 3], 3, left);
      } else if (same_size) {
        const int depth = frame.DepthAt(u, v);
        const auto grey = static_cast<std::uint8_t>(depth ? 255 - std::min(depth / 6, 230) : 0);
        std::fill_n(left, 3, grey);
      }
      // The nearer of the model and the hand, over the renderer's background.
      std::uint8_t* right = left + width * 3;
      const float model_depth = model_fits ? model.depth_mm[i] : 0.0f;
      const float hand_depth = rendered.depth_mm[i];
      if (model_depth > 0 && (hand_depth <= 0 || model_depth < hand_depth)) {
        std::copy_n(&model.image.rgb[i * 3], 3, right);
      } else {
        std::copy_n(&rendered.rgb[i * 3], 3, right);
      }
    }
  }
  DrawPanelLabel(&image, 0, width, "camera");
  DrawPanelLabel(&image, width, width, "model and fitted hand, as the camera sees them");
  return image;
}

void DrawPanelLabel(RgbImage* image, int x0, int width, const std::string& text) {
  constexpr int kStrip = 24;
  if (image->width <= 0 || x0 < 0 || width <= 0 || x0 + width > image->width ||
      image->height < kStrip) {
    return;
  }
  cv::Mat all(image->height, image->width, CV_8UC3, image->rgb.data());
  cv::Mat strip = all(cv::Rect(x0, 0, width, kStrip));
  strip *= 0.35;  // Darkened, the image still showing through.
  cv::putText(strip, text, cv::Point(8, 17), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(240, 240, 240), 1, cv::LINE_AA);
}

void WritePng(const std::filesystem::path& path, const RgbImage& image) {
  cv::Mat rgb(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<std::uint8_t> bytes;
  if (!cv::imencode(".png", bgr, bytes)) {
    throw OutputError(path.string() + ": cannot encode the image");
  }
  WriteFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
}

}  // namespace ihs::app
