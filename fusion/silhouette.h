#pragma once
// The object's silhouette as an ICP term. A box turning in the hand shows, for a few frames,
// one face head-on and its neighbours edge-on: then nothing in the depth fixes the shift along
// the edge-on faces' normal, and the head-on face's outline against the background is what
// does. Each point of the frame's occluding contour (the object's edge against the background,
// not against the hand) is paired with the model raycast's own edge along the outline's normal
// in the image; the residual is their distance there, in mm at the point's depth.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "fusion/tsdf_volume.h"

namespace ihs::fusion {

/// Options of the silhouette term (`fusion.silhouette.*`).
struct SilhouetteOptions {
  /// Each contour point weighs this many of ICP's surface point pairs (0: the term is off).
  double weight = 1.0;
  /// How far along the outline's normal the model's edge is looked for, pixels (either way).
  int search_px = 4;
  /// A neighbour of an object pixel is background (the object's edge occludes it) when it has
  /// no depth or lies at least this much farther away; a nearer or equally near one (the hand,
  /// pixels the segmentation left out) makes no contour.
  double background_gap_mm = 15.0;
  /// Contour points kept at most (evenly spaced along the image's rows).
  int max_points = 600;
  /// The model's edge counts only where its surface still faces the camera by at least this
  /// (cosine): a crease where the surface ends (a face's edge, a bottle's cap). Where the
  /// surface turns away (a ball's outline, a bottle's sides) the raycast's last pixel falls
  /// short of the true outline, which would pull the object toward its unhidden side.
  double min_edge_facing = 0.3;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// A point of the frame's occluding contour: camera frame (mm) and the outline's outward
/// normal in the image (unit).
struct ContourPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();
};

/// The occluding contour of the object's pixels (`mask` non-zero, with depth) inside `box`
/// (u0, v0, u1, v1; exclusive ends): object pixels with a background 4-neighbour
/// (SilhouetteOptions::background_gap_mm) and none nearer than themselves.
std::vector<ContourPoint> FindContour(const Frame& frame, const std::vector<std::uint8_t>& mask,
                                      const std::array<int, 4>& box,
                                      const CameraIntrinsics& intrinsics,
                                      const SilhouetteOptions& options);

/// Marks, in `near_depth_mm`, the pixels within `search_px` + 1 outside each contour point
/// along its normal with the point's depth (where nothing is marked yet), so that the model is
/// raycast there too and its edge can be found.
void MarkContourBand(const std::vector<ContourPoint>& contour, const CameraIntrinsics& intrinsics,
                     int search_px, std::vector<std::uint16_t>* near_depth_mm);

/// One contour point's equation: `point` is the contour point where ICP's current correction
/// puts it (the model's camera frame). Returns false where the model's edge is not within the
/// search (or is not an edge against nothing: the model has surface in front there, or its
/// surface at the edge faces the camera less than `min_edge_facing`). Else
/// `direction` (the row's direction, as a point-to-plane pair's normal) and `residual_mm`:
/// residual = direction · (moved point − its place on the edge) to first order.
bool PairContourPoint(const Eigen::Vector3d& point, const Eigen::Vector2d& normal,
                      const RaycastImage& model, const CameraIntrinsics& intrinsics,
                      double depth_gate_mm, int search_px, double min_edge_facing,
                      Eigen::Vector3d* direction, double* residual_mm);

}  // namespace ihs::fusion
