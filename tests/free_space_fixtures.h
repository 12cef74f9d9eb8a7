#pragma once
// A cube's depth as a camera sees it, ray-cast analytically (no renderer): the evidence the
// free-space and closure tests carve with.

#include <array>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"

namespace ihs::test {

/// Edge of the rendered cube, mm (centred on its frame's origin).
inline constexpr float kCubeEdgeMm = 40.0f;

/// A depth frame and the cube's pixels' bounding box (u0, v0, u1, v1; exclusive ends).
struct RenderedView {
  Frame frame;
  std::array<int, 4> object_box = {0, 0, 0, 0};
};

/// The cube seen by `camera` at `cam_from_cube`: depth (whole mm) where a pixel's ray meets it,
/// 0 elsewhere (nothing behind it).
RenderedView CubeView(const CameraIntrinsics& camera, const Rigid3& cam_from_cube);

}  // namespace ihs::test
