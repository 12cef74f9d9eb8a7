#pragma once
// Online loop closure: a full turn brings the object back to views seen before, by then with
// the drift of every frame since. This keeps keyframes (the object's depth every few degrees of
// turn, and the pose it was fused at), registers each new keyframe against the earlier ones it
// sees the same side of — the views themselves, not the model that the drift has smeared —
// and, where such a loop disagrees with the chain of tracked poses, solves the pose graph over
// all keyframes (pose_graph.h). ObjectFusion then re-fuses the model from the keyframes at their
// corrected poses and carries on from the corrected pose (as Weise et al. 2011 close loops in
// their in-hand scanner, with the keyframes re-fused instead of a deformed surfel model).
//
// A loop is taken from a registration of the shapes only where it fixes every direction: a ball
// or a bottle turned about its axis looks the same from every side of the turn, so there its
// loop says nothing about the turn. There the keyframes' SIFT keypoints are registered instead
// where the object has colour (a label; LoopClosureOptions::feature_loops): the turn the hand
// carried drifts by tens of degrees over a whole turn, and its pattern shows where the object
// really is — unless the pattern repeats (then only loops within half a period of the chain
// count), and the correction goes into spins about the object's axis, which its shape and the
// chain fixed (a correction spread as shifts and tilts too would smear the re-fused model).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"
#include "fusion/icp.h"
#include "fusion/pose_graph.h"
#include "fusion/sift_matcher.h"
#include "fusion/tsdf_volume.h"

namespace ihs::fusion {

/// Options of the loop closure (fusion.loop_closure.*; defaults: an object turned in one hand
/// at 0.4–0.9 m, Kinect-class depth).
struct LoopClosureOptions {
  bool enabled = true;
  /// A fused frame becomes a keyframe when the object has turned this far since the last one
  /// (degrees): a full turn keeps about 360 / this many. The model is re-fused from them.
  double keyframe_turn_deg = 6.0;
  /// At most this many keyframes (each the object's depth and colour: 20–100 kB); later frames
  /// are not kept and close no loop.
  int max_keyframes = 400;
  /// A loop joins two keyframes at least this many keyframes apart whose poses see the object
  /// from within `loop_max_turn_deg` of each other; at most `loop_tries` of the nearest such
  /// are registered per new keyframe.
  int loop_min_gap = 6;
  double loop_max_turn_deg = 25.0;
  int loop_tries = 3;
  /// A loop counts only once another loop agrees with it on where the object is, within
  /// `loop_agreement_mm` (at the graph's lever; the two carried to one keyframe along the
  /// chain): another of the same keyframe, or of one of the next `loop_pending_keyframes`. A
  /// view that registers where it is not (a cube's faces are alike) rarely does so twice alike.
  double loop_agreement_mm = 3.0;
  int loop_pending_keyframes = 4;
  /// The registration of a loop: ICP between the two keyframes' object points, pairs at most
  /// this far apart at first (mm), halved twice (the drift of a turn is more than the 5 mm
  /// of frame-to-frame ICP).
  double icp_start_mm = 20.0;
  /// It is a loop when at least this share of the new keyframe's points pair within the last
  /// pass's distance, at this RMS at most (mm), and it moves the estimate by less than
  /// `max_correction_mm` (at the graph's lever).
  double min_inlier_fraction = 0.5;
  double max_rms_mm = 1.5;
  double max_correction_mm = 80.0;
  /// The model is re-fused only when the solved graph moves some keyframe by more than this
  /// (mm at the lever): less is the keyframe registration's own noise.
  double refuse_min_mm = 1.5;
  /// The chain's edges (the tracked motion between consecutive keyframes) weigh by the least
  /// share of its first pairs that a frame's ICP between the two keyframes kept at its end
  /// (IcpResult): ((share − 0.5) / (chain_trusted_kept − 0.5))^4, clamped to [1e-4, 1]. A
  /// slide starts where that share drops (0.6–0.75 where a box slid 20 mm, 0.95–1 in most
  /// frames): a loop's correction then goes where the chain broke rather than spread over
  /// the turn, and evenly where nothing broke (a slow drift).
  double chain_trusted_kept = 0.95;
  /// Where the surface leaves the object's turn free (Observe's `turn_free`), keyframes with
  /// colour keep up to `feature_keypoints` SIFT keypoints, and a new one is registered by them
  /// to each earlier one at least loop_min_gap back within `feature_max_turn_deg` (the drift of
  /// the turn the hand carried reaches tens of degrees) that shares `feature_min_inliers`
  /// matches (Lowe's ratio), at most `feature_tries` of them, most matches first: RANSAC over
  /// the matched points, inliers within `feature_inlier_mm`. It is a loop where that many agree
  /// and no motion turned more than `feature_distinct_deg` from it has more than
  /// `feature_max_rival` of their number (a pattern that repeats round the object, as a
  /// checkerboard does every 60°, lets two motions explain the matches). Such loops are
  /// confirmed by a second one as every loop is. Off by default since the colour alignment
  /// (colour_align.h) registers every frame of a patterned object against the model: on 29
  /// patterned and labelled lathe and ball turns the keypoint loops then closed few loops,
  /// some of them wrong (a labelled pin's mesh.ply 0.29 -> 3.28 mm), and with them off the end
  /// error was 9.8 -> 8.5° (docs/fusion.md, "The colour where the shape leaves the turn free").
  bool feature_loops = false;
  int feature_keypoints = 150;
  double feature_max_turn_deg = 90.0;
  int feature_tries = 4;
  int feature_min_inliers = 12;
  double feature_inlier_mm = 4.0;
  double feature_distinct_deg = 25.0;
  double feature_max_rival = 0.5;
  /// A loop by keypoints may turn the chain's estimate of the newest keyframe by at most this
  /// share of the turn the chain travelled between the two keyframes (the sum of its steps),
  /// and at least `feature_min_gate_deg`: the turn the hand carries drifts as it goes (scans
  /// that follow a whole turn end 2-56° off after 300-360°), while a pattern that repeats (a
  /// checkerboard every 60°) matches a view a period away long before a drift that large.
  double feature_drift_share = 0.25;
  double feature_min_gate_deg = 5.0;
  /// A pattern that repeats shows itself: a registration by keypoints that turns the chain's
  /// estimate past the drift gate above, or two registrations of one new keyframe that place
  /// it more than `feature_distinct_deg` apart, is a view matched to a copy of its pattern
  /// (the least such turn seen so far is the period's estimate). From then on a loop by
  /// keypoints may turn the chain's estimate by less than this share of that turn (half a
  /// period: farther, a loop is as near its neighbour's alias as its own view; of a keyframe's
  /// registrations that disagree, those nearest the chain are kept).
  double feature_alias_share = 0.5;
  /// Where the surface leaves the turn free, the chain's steps measured everything but the
  /// object's spin well (its shape fixed the rest): the pose graph then spreads a loop's
  /// correction as spins about the line the largest correction so far turned about (its screw
  /// axis, once at least `spin_axis_min_deg`), holding that line (PoseGraphOptions::
  /// spin_weight), instead of as shifts and tilts that smear the re-fused model.
  bool spin_axis_loops = true;
  double spin_axis_min_deg = 5.0;
  /// A loop by keypoints: ICP of the two views from where the keypoints put them pairs at
  /// least this share of the new keyframe's points (views up to `feature_max_turn_deg` apart
  /// overlap less than a shape loop's views within `loop_max_turn_deg`).
  double feature_min_inlier_fraction = 0.25;
  PoseGraphOptions graph;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// A kept view: the object's depth (and colour) in its crop and where the object was.
struct Keyframe {
  /// ObjectFusion's count of fused frames when it was taken.
  int stamp = 0;
  Rigid3 cam_from_object;
  /// The crop: top-left pixel and size; depth (mm) where the object's mask was set, else 0;
  /// colour (3 bytes a pixel) when the frame had any.
  int u0 = 0, v0 = 0, width = 0, height = 0;
  std::vector<std::uint16_t> depth_mm;
  std::vector<std::uint8_t> rgb;
  /// Every other pixel's point in each direction (camera frame, mm): what a loop registers.
  std::vector<Eigen::Vector3f> points;
  /// Its SIFT keypoints' points (camera frame, mm) and descriptors (128 bytes each), kept where
  /// the surface left the turn free (LoopClosureOptions::feature_loops).
  std::vector<Eigen::Vector3f> keypoints;
  std::vector<std::uint8_t> descriptors;

  /// Writes its depth, colour and mask into full-size `frame` and `mask` (which must be
  /// zero there), and ClearFrom takes them out again.
  void PasteInto(Frame* frame, std::vector<std::uint8_t>* mask) const;
  void ClearFrom(Frame* frame, std::vector<std::uint8_t>* mask) const;
};

/// What a keyframe changed. Where `corrected`, every keyframe has a new pose: keyframe i's
/// object frame moved by `corrections[i]` (new cam_from_object = old · correction).
struct KeyframeUpdate {
  bool added = false;
  int loops = 0;
  /// Of those, registered by the keyframes' keypoints.
  int feature_loops = 0;
  bool corrected = false;
  /// The largest move of a keyframe (mm at the lever).
  double correction_mm = 0;
  std::vector<Rigid3> corrections;
};

/// The keyframes and the pose graph over them. Not thread-safe; ObjectFusion owns it.
class KeyframeGraph {
 public:
  KeyframeGraph(const CameraIntrinsics& intrinsics, LoopClosureOptions options = {},
                IcpOptions icp = {});

  /// Considers a fused frame: the object's pixels under `mask` inside `box` (u0, v0, u1, v1),
  /// fused at `cam_from_object`, the `stamp`-th fused frame, whose ICP kept `kept_pairs` of the
  /// pairs it started with (1 where it did not run); `turn_free`: the surface leaves the
  /// object's turn free (its loops are then registered by keypoints).
  KeyframeUpdate Observe(const Frame& frame, const std::vector<std::uint8_t>& mask,
                         const std::array<int, 4>& box, const Rigid3& cam_from_object, int stamp,
                         double kept_pairs = 1.0, bool turn_free = false);

  const std::vector<Keyframe>& keyframes() const { return keyframes_; }
  /// The least turn a registration by keypoints was seen to be off by (a pattern's period,
  /// see LoopClosureOptions::feature_alias_share), degrees; infinite where none was.
  double alias_deg() const { return alias_deg_; }
  /// How the object frame of a frame with `stamp` moved in the last correction: the
  /// correction of the keyframes around it, interpolated by stamp.
  static Rigid3 CorrectionAt(const std::vector<Keyframe>& keyframes,
                             const std::vector<Rigid3>& corrections, int stamp);

  /// The motion from keyframe `from`'s camera to keyframe `to`'s that registers the first's
  /// points on the second's surface, starting from their poses; none where that is not a
  /// loop (see LoopClosureOptions).
  std::optional<Rigid3> Register(const Keyframe& from, const Keyframe& to);
  /// The same motion from the two keyframes' keypoints (see LoopClosureOptions::feature_loops):
  /// their matches place `from` (RANSAC), ICP of the views from there fixes what the shapes fix
  /// and leaves the turn they leave free where the keypoints put it; none where they do not
  /// make it a loop.
  std::optional<Rigid3> RegisterByKeypoints(const Keyframe& from, const Keyframe& to);

 private:
  // A loop waiting for another to agree with it: its edge, where it puts its keyframe's
  // object (cam_from_object) and whether one did.
  struct Loop {
    PoseGraphEdge edge;
    Rigid3 placed;
    bool confirmed = false;
    bool by_keypoints = false;
  };
  // The turn the chain travelled from keyframe `from` to `to` (the sum of its steps), degrees.
  double Travelled(int from, int to) const;
  // The keyframe of a fused frame.
  Keyframe Keep(const Frame& frame, const std::vector<std::uint8_t>& mask,
                const std::array<int, 4>& box, const Rigid3& cam_from_object, int stamp) const;
  // ICP of `from`'s points on scratch_ (the target drawn) from `start`, coarse to fine: the
  // motion where it is a loop (and its pairs in `inliers`); with `free_allowed`, also where
  // the surfaces leave directions free (they stay where `start` put them).
  std::optional<Rigid3> Align(const Keyframe& from, const Rigid3& start, int* inliers,
                              bool free_allowed = false) const;
  // The newest keyframe's edge to the one before: the tracked motion, weighed by chain_kept_
  // (spin-free where the surface leaves the turn free).
  void AddChainEdge(bool spin_free);
  // Registers the newest keyframe against earlier ones (by keypoints: `by_keypoints`), adds the
  // loops that a second one confirms (its own or pending ones) to the graph and returns how
  // many; a confirmed loop by keypoints may set spin_axis_.
  int AddConfirmedLoops(bool by_keypoints);
  // The newest keyframe's loops by keypoints with the earlier keyframes, less those a
  // repeating pattern may have placed (LoopClosureOptions::feature_alias_share).
  std::vector<Loop> KeypointLoops();
  // The earlier keyframes the newest one is tried against, nearest turn first.
  std::vector<int> LoopCandidates() const;
  // Those it is tried against by keypoints, most matches first.
  std::vector<int> KeypointCandidates() const;
  // Whether a loop's motion from `from` to `to` moves `from` by at most max_correction_mm.
  bool Plausible(const Rigid3& motion, const Keyframe& from, const Keyframe& to) const;
  // `keyframe`'s surface as ICP's model image (scratch_), normals from its depth.
  void DrawTarget(const Keyframe& keyframe);
  // Solves the graph; where it moves a keyframe by more than refuse_min_mm, takes the new
  // poses and says so in `update`.
  void Solve(KeyframeUpdate* update);

  const CameraIntrinsics intrinsics_;
  const LoopClosureOptions options_;
  IcpOptions icp_;
  std::vector<Keyframe> keyframes_;
  std::vector<PoseGraphEdge> edges_;
  std::vector<Loop> pending_;
  // The least share of its first pairs a frame's ICP kept since the last keyframe.
  double chain_kept_ = 1.0;
  // Loops registered by keypoints among those the last AddConfirmedLoops confirmed.
  int feature_loops_ = 0;
  // The least turn (degrees) a registration by keypoints was seen to be off by where the
  // pattern repeats (LoopClosureOptions::feature_alias_share); infinite before.
  double alias_deg_ = std::numeric_limits<double>::infinity();
  // The line the largest loop correction by keypoints turned about (object frame), and by how
  // much (degrees); see LoopClosureOptions::spin_axis_loops.
  std::optional<SpinAxis> spin_axis_;
  double spin_axis_deg_ = 0;
  RaycastImage scratch_;
};

}  // namespace ihs::fusion
