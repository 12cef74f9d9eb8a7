#pragma once
// Preview images of a scan in progress: the camera's colour image beside the model so far (a
// raycast of the TSDF) and the posed hand model drawn by the off-screen renderer (OSMesa), both
// seen from the camera.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/triangle_mesh.h"

namespace ihs::render {
class OffscreenRenderer;
}

namespace ihs::app {

/// An RGB8 image, row-major from the top-left pixel.
struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
};

/// The model as the camera sees it: a shaded image and the depth of its surface per pixel (mm,
/// 0 where there is none), row-major.
struct ModelView {
  RgbImage image;
  std::vector<float> depth_mm;
};

/// Draws previews. One per thread (it owns an OSMesa context).
class PreviewRenderer {
 public:
  /// Throws ihs::DeviceError when OSMesa cannot create a context.
  explicit PreviewRenderer(const CameraIntrinsics& intrinsics);
  ~PreviewRenderer();

  /// The colour image of `frame` (its depth in grey when it has no colour) beside `model` with
  /// `hand` (camera frame, skin-coloured; may be null) drawn in where it is nearer.
  RgbImage Draw(const Frame& frame, const ModelView& model, const TriangleMesh* hand);

 private:
  std::unique_ptr<render::OffscreenRenderer> renderer_;
};

/// Labels the panel of `image` that starts at column `x0` and is `width` wide: `text` on a
/// dark strip along its top (the live window's and the previews' panels).
void DrawPanelLabel(RgbImage* image, int x0, int width, const std::string& text);

/// Writes `image` as a PNG, atomically. Throws ihs::OutputError when it cannot.
void WritePng(const std::filesystem::path& path, const RgbImage& image);

}  // namespace ihs::app
