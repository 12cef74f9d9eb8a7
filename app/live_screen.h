#pragma once
// What the live window shows, as one image: the camera's colour image with the hand's skeleton
// and the contact points drawn over it, the shaded model beside it, a status line and the keys.

#include <string>

#include "app/pipeline.h"
#include "core/camera_intrinsics.h"

namespace ihs::app {

/// Composes the live window's image from `view` (two frames wide plus a status bar).
RgbImage ComposeLiveScreen(const LiveView& view, const CameraIntrinsics& intrinsics,
                           const std::string& status_line);

}  // namespace ihs::app
