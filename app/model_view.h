#pragma once
// The model as a person looks at it: a raycast of the TSDF lit so its shape reads, either from
// the camera (the previews, where the posed hand is drawn over it) or fitted to the image and
// turned by the user about its centre (the live window's model panel).

#include <Eigen/Geometry>

#include "app/preview.h"
#include "core/camera_intrinsics.h"
#include "core/rigid3.h"
#include "fusion/tsdf_volume.h"

namespace ihs::app {

/// How the live window's model panel is turned away from the camera's view, about the model's
/// centre. Zero: the camera's view (the object as the camera sees it, centred and fitted).
struct ModelViewpoint {
  /// About the view's vertical axis, degrees (dragging the mouse right turns the model's front
  /// to the right).
  double yaw_deg = 0;
  /// About the view's horizontal axis, degrees (dragging down turns the model's front down);
  /// kept within ±kMaxPitchDeg.
  double pitch_deg = 0;
  static constexpr double kMaxPitchDeg = 89;

  /// This viewpoint turned further by a mouse drag of (`dx`, `dy`) window pixels.
  ModelViewpoint Dragged(double dx, double dy) const;
};

/// The model seen from the camera at `cam_from_object`, lit, with its depth (previews).
ModelView ViewModelFromCamera(const fusion::TsdfVolume& volume, const CameraIntrinsics& intrinsics,
                              const Rigid3& cam_from_object);

/// The pose of a virtual camera with `intrinsics` that sees the whole of `box` (object frame,
/// mm; not empty) centred in its image, looking at it from the direction of the camera at
/// `cam_from_object` turned by `viewpoint` about the box's centre.
Rigid3 FittedViewPose(const Eigen::AlignedBox3f& box, const CameraIntrinsics& intrinsics,
                      const Rigid3& cam_from_object, const ModelViewpoint& viewpoint);

/// The model fitted to the image and turned by `viewpoint` (the live window's model panel);
/// an image of `intrinsics`' size, black where there is no model (all black before it starts).
RgbImage ViewModelFitted(const fusion::TsdfVolume& volume, const CameraIntrinsics& intrinsics,
                         const Rigid3& cam_from_object, const ModelViewpoint& viewpoint);

/// A raycast shaded for a person: its colours (grey where it has none, dark ones lifted) under
/// a key light from the upper left, a light from the viewer and a highlight. Black where the
/// rays missed.
RgbImage ShadeRaycast(const fusion::RaycastImage& cast);

}  // namespace ihs::app
