#pragma once
// The object's colour against the model's, in the directions its shape leaves free (beyond the
// paper). A ball's turns and a bottle's spin are not fixed by ICP against the model; features
// matched to the previous frame and the hand carry them, and their errors add up frame after
// frame. Where the object wears a pattern, the model (the TSDF keeps a colour per voxel) shows
// where that pattern was seen: this refines the pose ICP found along its free directions so
// that the frame's colours land on the model's (a direct, photometric alignment after Steinbrücker
// et al. 2011 and Park et al. 2017's coloured ICP, here only where the shape says nothing). The
// frame is then registered against everything fused before, not chained to the last frame.
//
// Both grey images are compared over the pixels both hold, as the log of the grey less its
// slow changes, less what the surface's normals explain (the shading, which a spin does not
// move: left in, it held uniform bottles still); where that leaves no pattern in the frame or
// the model, nothing moves. Then both are blurred (a normalised Gaussian within the object's
// pixels: the model's colour is that of 1.4 mm voxels and a mean over many frames), coarse to
// fine; a gain and an offset take up the difference in exposure; residuals weigh by Huber's
// rule; the motion stays near ICP's under a Gaussian prior (ColourAlignOptions::prior_mm), each
// direction as far as the colour's basin holds it.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"
#include "fusion/icp.h"
#include "fusion/tsdf_volume.h"

namespace ihs::fusion {

/// Options of the colour alignment (fusion.colour.*; defaults: Kinect-class colour at 0.4-0.9 m).
struct ColourAlignOptions {
  bool enabled = true;
  /// Both grey images are compared as the log of the grey less its blur by this (pixels): the
  /// light's shading multiplies the pattern and changes slowly across the object (0: as they are).
  double shading_blur_px = 6.0;
  /// What smooth functions of the surface's normal explain of both details (the shading of a
  /// light fixed to the camera) is taken out: on a uniform object it is all there is, and it
  /// held untextured bottles and balls still against their turn.
  bool remove_shading = true;
  /// Where the shading explains more than this share of the frame's detail, the object shows
  /// no pattern and nothing is aligned (measured: 0.6-0.85 on untextured bottles, pins and
  /// balls, 0.02-0.04 on patterned and labelled ones; medians over the frames).
  double max_shading_share = 0.5;
  /// Gaussian blur of both grey images, pixels: first the coarse one (reach), then the fine one.
  double coarse_blur_px = 3.0;
  double fine_blur_px = 1.0;
  /// Gauss–Newton iterations per blur at most (a step under 0.01 mm ends them).
  int iterations = 8;
  /// The object's pixels used: every `stride`-th in each direction, sparser where that would be
  /// more than `max_points` (a bowling pin near the camera has 30 000 pixels).
  int stride = 2;
  int max_points = 3000;
  /// The prior on the motion away from ICP's pose, mm (RMS over the object's points): a
  /// frame's turn is known from features, contacts or the hand to about this.
  double prior_mm = 2.0;
  /// A point is compared with the model only where the model's surface through its pixel is
  /// within this depth of it, mm (not across the hand or an edge).
  double max_depth_gap_mm = 5.0;
  /// ...and where the model's surface faces the camera at least this much (the cosine between
  /// its normal and the ray): near the outline the shading changes fast and the model's colour
  /// is a smear of glancing views.
  double min_facing = 0.5;
  /// How far the colour fixes a free direction is judged from its basin: the cost this far
  /// either way from the fit (mm) against the fit's, its residuals taken as correlated over
  /// `correlated_samples` points (neighbours within a blur footprint). The fitted motion is
  /// kept in each direction in proportion to that information against the prior's.
  double profile_mm = 2.0;
  double correlated_samples = 4.0;
  /// The model's colour is compared only where at least this many pixels coloured it: the
  /// surface just turning into view is coloured by a few glancing views (with the frame's
  /// pixels cut to the model's, this kept an analytic ball with one colour edge and exact
  /// contacts on its turn: docs/fusion.md).
  int min_model_colourings = 8;
  /// Points needed, and the least spread of the frame's detail after the shading (standard
  /// deviation of 100 × log grey: about a percentage of contrast) that counts as a pattern.
  /// Measured per frame on generated turns: 30-50 on patterned and labelled bottles, pins and
  /// balls (10th-90th percentile; a small bottle's label half out of view 14), 55-90 on a
  /// patterned box; 0-22 on uniform ones (hand edges, shadows and what the shading model
  /// leaves): below it a uniform object's frames were aligned to that and lost their turn.
  int min_points = 100;
  double min_grey_spread = 25.0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// What the colour alignment did.
struct ColourAlignResult {
  /// Whether it ran and moved the pose (else `reason`).
  bool applied = false;
  std::string reason;
  /// Whether it stopped because the object's colours show no pattern: the shading explains
  /// them (max_shading_share) or what is left spreads too little (min_grey_spread).
  bool no_pattern = false;
  /// predicted_from_current (as IcpResult's correction): takes the current camera's points to
  /// where the model's raycast sees them.
  Rigid3 correction;
  /// The motion it made, mm RMS over the points, and its turn, degrees.
  double moved_mm = 0;
  double turn_deg = 0;
  /// How well the colour fixes the free directions: the posterior standard deviation of the
  /// least fixed one, mm (the prior's where the colour fixes nothing).
  double uncertainty_mm = 0;
  /// The share of the frame's detail that the shading explained (ColourAlignOptions::
  /// remove_shading).
  double shading_share = 0;
  /// The standard deviation of the frame's detail or the model's, the less (after the shading;
  /// 100 × log grey).
  double pattern_spread = 0;
  /// Points compared in the last iteration, and their residuals' robust scale (grey levels).
  int points = 0;
  double sigma = 0;
  /// The correlation of the frame's grey with the model's where they pair, at the fitted
  /// motion (on the fine blur; 0 where it did not get that far).
  double correlation = 0;
};

/// Refines `correction` (predicted_from_current, ICP's) along `free` (about `centre`, in the
/// predicted camera's frame, as IcpResult gives them) so that the colours of `frame`'s pixels
/// under `mask` inside `box` (u0, v0, u1, v1) land on `model`'s (the raycast ICP paired with).
ColourAlignResult AlignColour(const Frame& frame, const std::vector<std::uint8_t>& mask,
                              const std::array<int, 4>& box, const RaycastImage& model,
                              const CameraIntrinsics& intrinsics, const Rigid3& correction,
                              const std::vector<FreeDirection>& free, const Eigen::Vector3d& centre,
                              const ColourAlignOptions& options = {});

}  // namespace ihs::fusion
