#pragma once
// A registered pose the frame sees through: where the model, raycast at the frame's pose, says
// the object is, the frame's depth lies well behind it (the background, the table, the arm).
// The object cannot be both there and not there: the pose is off, slid beside the object.
//
// ICP pairs each of the frame's object points with the model near it; a pose slid along a face
// by a centimetre or two still pairs most of them (a box's face is larger than the slide), and
// nothing in ICP's cost sees the model overhang the object into empty space. The frame does: at
// a right pose the model's inner samples show the object (or the hand in front of it), at most
// 2.7 % of them on the integrated frames of 97 generated box, cube, lathe and ball turns; a
// cube found again 20 mm off after ten unseen frames showed the background through 18 % of the
// model's pixels (docs/fusion.md, "A pose the frame sees through").

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"
#include "fusion/tsdf_volume.h"

namespace ihs::fusion {

/// Options of the see-through check (defaults in the field comments).
struct SeeThroughOptions {
  /// A frame sees through the model at its registered pose where more than this share of the
  /// model's sampled inner pixels (those where the frame has depth: MeasureSeeThrough) lie
  /// farther than `margin_mm` in front of the frame's depth (0: not checked). ICP is then tried
  /// once more from the pose moved so that the model's visible part lies on the object's points
  /// (kept where it pairs no fewer points and sees through less); a frame that still sees
  /// through is tracked but not integrated (FusionResult::see_through_held; see
  /// `max_held_frames`).
  double max_share = 0.05;
  /// How far behind the model the frame's depth must lie to be seen through (mm): the model's
  /// edges and the sensor's noise stay within it.
  double margin_mm = 10.0;
  /// At most this many frames in a row are held out for seeing through; later ones are
  /// integrated as registered until a frame does not see through (0: none held, the pose only
  /// tried again). Where the model, not the pose, is what the frames contradict — a finger the
  /// segmentation gave the object for a few frames, fused into the model — every later frame
  /// sees through it at the right pose (12-14 % for a 60 x 18 mm finger beside a 90 x 60 mm box
  /// face, ObjectFusionTest), and holding them all out would lose the rest of the scan.
  int max_held_frames = 10;
  /// The model is raycast at every this-many-th pixel along each image axis: a share needs a
  /// sample, not every pixel (a box at 60 cm covers some 10 000 pixels, 600 at 4); a full
  /// raycast of the whole view took 8 ms a frame.
  int step_px = 4;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The model's pixels against the frame's depth.
struct SeeThrough {
  /// Model pixels where the frame has depth (the model's inner ones: MeasureSeeThrough).
  int in_view = 0;
  /// ... of which the frame's depth lies more than the margin behind the model.
  int through = 0;
  /// The centroid (camera frame, mm) of the model's points not hidden by something in front
  /// of them (the hand): those the frame would show if the model were there.
  Eigen::Vector3d visible_centroid = Eigen::Vector3d::Zero();
  int visible = 0;

  double share() const { return in_view > 0 ? static_cast<double>(through) / in_view : 0.0; }
};

/// The pixels to raycast for the check (TsdfVolume::Raycast's near depth, cast with a window of
/// kSeeThroughWindowMm): every `step_px`-th pixel along each axis where the frame has depth,
/// there the frame's depth; 0 elsewhere.
void SeeThroughPixels(const Frame& frame, int step_px, std::vector<std::uint16_t>* near_depth);
/// The image box (u0, v0, u1, v1; exclusive ends) the volume's `observed` box projects into,
/// seen from `cam_from_volume`: the model cannot show outside it. The whole image ({0, 0, 0, 0})
/// where the box reaches behind the camera.
std::array<int, 4> ImageBoxOf(const Eigen::AlignedBox3f& observed, const Rigid3& cam_from_volume,
                              const CameraIntrinsics& intrinsics);
/// A window that takes each such ray all through the model.
inline constexpr float kSeeThroughWindowMm = 1e5f;

/// Compares `model` (a raycast from the frame's camera) with the frame's depth.
/// Only the pixels SeeThroughPixels sampled count, and of those in_view and through only the
/// model's inner ones (each of the four samples beside it on the model too).
SeeThrough MeasureSeeThrough(const RaycastImage& model, const Frame& frame,
                             const CameraIntrinsics& intrinsics, const SeeThroughOptions& options);

}  // namespace ihs::fusion
