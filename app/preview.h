#pragma once
// Preview images of a scan in progress, drawn by the off-screen renderer (OSMesa): the camera's
// colour image beside the model so far and the posed hand model, both seen from the camera.

#include <cstdint>
#include <filesystem>
#include <memory>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"
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

/// Draws previews. One per thread (it owns an OSMesa context).
class PreviewRenderer {
 public:
  /// Throws ihs::DeviceError when OSMesa cannot create a context.
  explicit PreviewRenderer(const CameraIntrinsics& intrinsics);
  ~PreviewRenderer();

  /// The colour image of `frame` (its depth in grey when it has no colour) beside `model`
  /// (object frame, placed by `cam_from_object`, in its vertex colours) and `hand` (camera
  /// frame, skin-coloured; may be null).
  RgbImage Draw(const Frame& frame, const TriangleMesh& model, const Rigid3& cam_from_object,
                const TriangleMesh* hand);

 private:
  std::unique_ptr<render::OffscreenRenderer> renderer_;
};

/// Writes `image` as a PNG, atomically. Throws ihs::OutputError when it cannot.
void WritePng(const std::filesystem::path& path, const RgbImage& image);

}  // namespace ihs::app
