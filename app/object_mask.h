#pragma once
// Keeping the hand out of the object model: the pixels the posed hand model covers (where it is
// not hidden behind the observed surface), grown by a few pixels, are taken out of the object
// mask, so hand points the skin segmentation missed never reach the TSDF or the features.

#include <cstdint>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/triangle_mesh.h"

namespace ihs::app {

/// Clears the entries of `object_mask` (one per pixel of `frame`) that `mesh` (camera frame, mm)
/// covers where it lies no more than `depth_margin_mm` behind the observed depth, dilated by
/// `dilation_px` pixels. Returns how many object pixels were cleared.
int RemoveMeshPixels(const TriangleMesh& mesh, const Frame& frame,
                     const CameraIntrinsics& intrinsics, int dilation_px, double depth_margin_mm,
                     std::vector<std::uint8_t>* object_mask);

}  // namespace ihs::app
