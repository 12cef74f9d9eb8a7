#pragma once
// Off-screen rendering with OSMesa (no display): depth (mm), shaded colour and a per-pixel label
// image of posed meshes seen by a pinhole camera. Used by the synthetic sequence generator and
// for preview images. OSMesa's headers stay in the .cc file.

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace ihs::render {

/// Pixel labels.
enum Label : std::uint8_t { kBackground = 0, kHand = 1, kObject = 2 };

/// One mesh to draw.
struct RenderItem {
  /// The mesh (not owned); vertex colours are used when present and `use_vertex_colors` is set.
  const TriangleMesh* mesh = nullptr;
  /// Where the mesh is: mesh frame → camera frame (OpenCV convention, mm).
  Rigid3 cam_from_mesh;
  /// Colour of the whole mesh, RGB8.
  std::array<std::uint8_t, 3> color = {200, 200, 200};
  bool use_vertex_colors = false;
  /// Label written for its pixels.
  std::uint8_t label = kObject;
};

/// Options of the renderer.
struct RendererOptions {
  /// Near and far clipping distances along the optical axis, mm.
  double near_mm = 100.0;
  double far_mm = 10000.0;
  /// Background colour, RGB8.
  std::array<std::uint8_t, 3> background = {0, 0, 0};

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// What one render produced, row-major from the top-left pixel.
struct RenderOutput {
  int width = 0;
  int height = 0;
  /// Depth along the optical axis, mm, 0 where nothing was drawn.
  std::vector<float> depth_mm;
  /// Colour, RGB8, with Lambertian shading from a light at the camera.
  std::vector<std::uint8_t> rgb;
  /// Label of the nearest surface per pixel (see Label).
  std::vector<std::uint8_t> labels;

  /// Depth rounded to whole millimetres as a sensor delivers it (0 = nothing).
  std::vector<std::uint16_t> DepthMillimetres() const;
};

/// Makes OSMesa render the same pixels on every machine: Mesa's softpipe rasteriser (plain C)
/// instead of llvmpipe, which compiles its rasteriser for the CPU at hand and whose depth then
/// differs in the last bits between CPUs (with AVX-512 or without), so that a generator sequence
/// of a given seed was not the same sequence everywhere. The generator is as fast with it (its
/// cost is elsewhere). Call it at the start of main, before any thread; it leaves a
/// GALLIUM_DRIVER the user set alone. The test suite sets the same variable for its tests (tests/CMakeLists.txt).
void UseMachineIndependentRasteriser();

/// Renders meshes into images of the size of `intrinsics`. One renderer per thread.
class OffscreenRenderer {
 public:
  /// Creates the OSMesa context. Throws ihs::DeviceError if OSMesa cannot create one.
  explicit OffscreenRenderer(const CameraIntrinsics& intrinsics, RendererOptions options = {});
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  /// Draws `items` and returns depth, colour and labels.
  RenderOutput Render(const std::vector<RenderItem>& items);

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }

 private:
  struct Context;
  const CameraIntrinsics intrinsics_;
  const RendererOptions options_;
  std::unique_ptr<Context> context_;
};

}  // namespace ihs::render
