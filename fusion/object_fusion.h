#pragma once
// The fusion stage: per frame, the object's motion since the previous frame from its
// correspondences (features and fingertip contacts, pairwise_registration.h), refined by ICP
// against the model (icp.h), then the object's pixels integrated into the TSDF (tsdf_volume.h).
// One obvious entry point: Fuse(input). The volume is placed around the object in the first
// frame; its frame is the object frame of everything that follows.

#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"
#include "core/stopwatch.h"
#include "core/triangle_mesh.h"
#include "fusion/colour_align.h"
#include "fusion/free_space.h"
#include "fusion/hidden_span.h"
#include "fusion/icp.h"
#include "fusion/keyframe_graph.h"
#include "fusion/model_contacts.h"
#include "fusion/pairwise_registration.h"
#include "fusion/see_through.h"
#include "fusion/tsdf_volume.h"
#include "fusion/turn_carry.h"
#include "fusion/view_coverage.h"

namespace ihs::fusion {

/// Options of the fusion stage (defaults: the paper's).
struct FusionOptions {
  TsdfOptions tsdf;
  PairwiseOptions pairwise;
  IcpOptions icp;
  /// Fingertip contacts found against the model besides the tracker's (model_contacts.h);
  /// they need FusionInput's hand vertices and fingertips.
  ModelContactOptions model_contacts;
  /// How the share of the object seen so far is counted (FusionResult::coverage).
  ViewCoverageOptions coverage;
  /// Which registered frames' depth is kept to bound the closure by the space seen empty.
  FreeSpaceOptions free_space;
  /// The turn the hand carries where the surface leaves it free (turn_carry.h); it needs
  /// FusionInput::hand_motion.
  TurnCarryOptions turn_carry;
  /// Keyframes, loops after a turn and the drift they correct (keyframe_graph.h).
  LoopClosureOptions loop_closure;
  /// After ICP, the frame's colours against the model's in the directions the surface leaves
  /// free (colour_align.h).
  ColourAlignOptions colour;
  /// ICP's silhouette term: the frame's outline against the background held to the model's
  /// edge (silhouette.h).
  SilhouetteOptions silhouette;
  /// Frames that show the object mostly hidden (behind the hand) are tracked, not integrated
  /// (hidden_span.h).
  HiddenOptions hidden;
  /// Frames whose registered pose the frame's depth sees through (the model where the frame
  /// shows what is behind it): tried again from the object's points, else tracked, not
  /// integrated (see_through.h).
  SeeThroughOptions see_through;
  /// Refine with ICP against the model (the paper does; off is its "no ICP" baseline).
  bool use_icp = true;
  /// When ICP from the registration's pose pairs fewer than this share of the object's points,
  /// it is tried again from the previous pose, and that result kept if it pairs
  /// icp_retry_gain times as many.
  double icp_retry_fraction = 0.7;
  /// It is also tried again where it pairs less than this share of what the last frame's ICP
  /// paired, where the surface fixes every direction (0: never). A start the registration
  /// put beside the object (a few fingertips or features moving together, wrongly) can hold ICP
  /// in a minimum that pairs markedly fewer points than the frames around it, yet more than the
  /// absolute share above: on a left-handed box turn, 8.7 mm along a face in one frame with
  /// 75 % paired (87 % the frame before). Where the surface leaves a turn free the object where
  /// it was pairs as many points as where the correspondences turned it, and the turn would be
  /// lost: there only the absolute share counts. Measured on 58 scans (docs/fusion.md, "A start
  /// that pairs fewer points than the last frame's").
  double icp_retry_drop = 0.9;
  /// The retry's result is kept where it pairs this many times the first's points (at 1.05,
  /// with the drop rule at 0.95, more of the box turns developed on held, but a held-out cube
  /// turn broke: docs/fusion.md).
  double icp_retry_gain = 1.2;
  /// Where the surface leaves a turn free and the object shows a pattern (a patterned or
  /// labelled ball, bottle or pin: ColourAlignOptions::min_grey_spread), the turn the
  /// correspondences or the hand gave the frame in those free directions is weighed against the
  /// object standing still: ICP (without the contacts, which may be what turned it) and the
  /// colours once more from the previous pose, and that kept where its colours match the
  /// model's better (their correlation, ColourAlignResult::correlation, higher by more than
  /// `colour_still_margin`). Fingertips lifted off to re-grasp and still taken for contacts
  /// turn a ball that stands still; the colours, which see its pattern stand, tell.
  bool colour_weighs_still = true;
  double colour_still_margin = 0.0;
  /// After a frame whose colours showed no pattern (ColourAlignOptions::max_shading_share,
  /// min_grey_spread), the colour alignment looks again only this many frames later: the side
  /// the camera sees changes over many frames, and on a uniform object every frame's look cost
  /// 2.3-3.1 ms for nothing (docs/app.md). A label turning into view is aligned at most this
  /// many frames late. 1: every frame.
  int colour_recheck_frames = 8;
  /// Where the pairwise registration has nothing (no features, no contacts), whether the
  /// object is predicted to move on as between the last two fused frames (constant velocity)
  /// rather than to stand still — only when the last frame's ICP left no direction free (where
  /// it did, a ball's spin or a bottle's about its axis, ICP keeps that direction at the
  /// prediction and a ball would spin on by itself). Off: measured on ten scripted box and
  /// cube turns it ends four of them within 0.6 mm where they ended 52-74 mm off, but three
  /// others slide mid-turn where they did not (docs/fusion.md, 2026-11-28).
  bool predict_moving = false;
  /// Where the hand turns back (HandTurn::kBack: it swings back to re-grasp while the object
  /// stays), visual pairs its motion explains better than standing still are left out: they
  /// are on the hand (or on its edge with the object), and would turn the object back with it.
  bool drop_features_moving_back = true;
  /// Where the surface leaves a turn free (TurnCarry::SurfaceLeavesTurnFree: a ball, a bottle),
  /// the features alone show that turn: a visual set needs at least
  /// `free_turn_min_visual_inliers` inliers there (PairwiseOptions::min_visual_inliers where
  /// larger), and its turn is shrunk with a prior of `free_turn_visual_prior_deg` instead of
  /// PairwiseOptions::visual_turn_prior_deg. Measured on 41 generated turns (docs/fusion.md,
  /// 2026-11-30): on untextured bottles the visual sets are 6-8 pairs on the edges and the
  /// hand, in a few frames, and turn the object wrongly; on patterned ones 11-114 pairs in every
  /// frame, of whose turn the prior of 1° kept 10-100 % a frame (what a frame loses is lost).
  /// Where the surface fixes the turn (boxes) the pairwise options apply as they are.
  int free_turn_min_visual_inliers = 10;
  double free_turn_visual_prior_deg = 0.0;
  /// A frame needs this many object points.
  int min_object_points = 200;
  /// Fingertip contacts the tracker found only farther than this from the object's points
  /// (FusionInput::contact_threshold_mm, its grown threshold) are loose, as are those it held
  /// without finding them (FusionInput::contacts_held): they are used only where the surface
  /// leaves a turn free (TurnCarryOptions), where nothing but the hand shows the turn. Where
  /// the surface fixes the motion (a box, a cube) ICP follows the object, and loose contacts —
  /// a hand lifting off to re-grasp is among them — only pull it along with the hand
  /// (docs/fusion.md, "Loose contacts").
  double loose_contact_mm = 10.0;
  /// A pose that moves the object's centre farther than this, or turns it by more than this,
  /// from the previous frame is implausible: the frame is skipped, not integrated.
  double max_jump_mm = 40.0;
  double max_jump_deg = 30.0;
  /// ... unless the jump holds: found again by ICP where the surface fixes every direction (a
  /// box; not a ball's turn, which the frame's motion alone gives), each within those limits of
  /// the last, in this many frames in a row, and within `max_jump_deg` of the turn the tracked
  /// hand made since the last pose; then the object did move there (it turned while the hand
  /// hid it, and every later frame finds it there) and the pose is taken (0: never). Without
  /// it a box that turned 33° while nothing of it was seen was refused in every one of the 42
  /// frames that followed (docs/fusion.md, "The object hidden behind the hand").
  int jump_held_frames = 3;
  /// A fingertip contact held over consecutive frames is anchored at one point of the object
  /// (the mean of where it was seen, in the object frame) rather than only at where the
  /// previous frame had it: while a grasp holds, the hand tracker's noise does not add up from
  /// frame to frame (the paper chains frame pairs and drifts). A contact farther than
  /// `anchor_slip_mm` from its anchor after registration has slipped and starts anew.
  bool anchor_contacts = true;
  double anchor_slip_mm = 4.0;
  /// Visual features matched from frame to frame (a source's pairs with ids: SIFT's keypoint
  /// tracks) are anchored the same way: at the mean of where the track was seen in the object
  /// frame, so that the features of a face seen over many frames hold it where they first saw
  /// it rather than let it walk a little every frame (a flat face's slide along itself, which
  /// its surface does not fix). A feature farther than `anchor_slip_mm` from its anchor starts
  /// anew.
  bool anchor_features = false;
  /// How much the contacts hold ICP follows how well they agree with the registered motion:
  /// `icp.anchor_share` is their share at `contact_noise_reference_mm` of disagreement (a
  /// running mean of each frame's median distance between the contacts and where the final pose
  /// puts them, over about 20 frames where the contacts held ICP), and it
  /// scales with 1/disagreement² (inverse-variance weighting; clamped to 1/100 … 100 times).
  /// Accurate contacts then decide what the surface leaves weak; noisy ones cannot drag what it
  /// fixes. 0 keeps `icp.anchor_share` fixed.
  double contact_noise_reference_mm = 1.0;
  /// Whether the contacts hold ICP only when they spread like the registration asks
  /// (PairwiseOptions::min_contact_spread_mm; the paper's two contact bones). Off: contacts
  /// that do not spread so far (one fingertip's patch, two neighbouring fingertips) hold it
  /// too, but only in the directions the surface leaves free (IcpOptions::
  /// anchors_free_directions_only). Alone, a 10 mm patch fixes a point of the object but
  /// hardly its turn; with the surface, which fixes all but the turns it leaves free (a ball's,
  /// a bottle's about its axis), the patch's shift at its distance from the axis is that turn.
  bool icp_contacts_need_spread = false;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// One frame for the fusion stage.
struct FusionInput {
  /// Depth (mm) with registered colour.
  const Frame* frame = nullptr;
  /// Per pixel: non-zero where the object is (the tracker's object mask).
  const std::vector<std::uint8_t>* object_mask = nullptr;
  /// Correspondences with the previous frame (camera frame, mm), one set per source
  /// (correspondence_source.h). A contact pair with an id (the touching skin point's vertex) is
  /// anchored while its grasp holds (FusionOptions::anchor_contacts); one without is not.
  PairwiseInput correspondences;
  /// The posed hand model in this frame (camera frame, mm) and each fingertip's vertex
  /// indices: with both, fingertips on the model's surface are contacts too
  /// (FusionOptions::model_contacts). Null: only the contact sets of `correspondences`. The
  /// hand's volume is space the object is not in (free_space.h).
  const TriangleMesh* hand = nullptr;
  const std::vector<std::vector<int>>* fingertips = nullptr;
  /// The hand's motion since the previous frame (camera frame: current_from_previous of its
  /// root), where the tracker followed it from there; none otherwise (turn_carry.h).
  std::optional<Rigid3> hand_motion = std::nullopt;
  /// The distance at which the tracker found the contacts of the contact pairs
  /// (tracker::Contacts::threshold_mm; a pair joins this frame's and the previous frame's
  /// contacts: the larger of the two; 0: unknown, taken as firm), and whether it held either
  /// without finding them (tracker::GraspHold): held ones are loose too (FusionOptions::
  /// loose_contact_mm).
  double contact_threshold_mm = 0;
  bool contacts_held = false;
};

/// What happened to a frame.
enum class FusionStatus {
  kStarted,  ///< The first frame: the volume is placed around the object and fused.
  kFused,    ///< Registered and integrated.
  kSkipped,  ///< Not integrated; `reason` says why.
};

/// A short name for stats and logs ("started", "fused", "skipped").
const char* ToString(FusionStatus status);

/// The stage's result for one frame.
struct FusionResult {
  FusionStatus status = FusionStatus::kSkipped;
  std::string reason;
  /// The object's pose in this frame (the previous one when skipped).
  Rigid3 cam_from_object;
  /// How the pose was found.
  PairwiseResult pairwise;
  IcpResult icp;
  /// The colour alignment after ICP (colour_align.h; not run: reason says why).
  ColourAlignResult colour;
  int integrated_voxels = 0;
  /// The share of directions around the object the registered frames so far have seen it
  /// from (view_coverage.h), this frame included when registered: how complete the model is.
  double coverage = 0;
  /// Contacts registered against their anchor rather than the previous frame.
  int anchored_contacts = 0;
  /// Visual feature pairs registered against their anchor (FusionOptions::anchor_features).
  int anchored_features = 0;
  /// Visual pairs left out as moving with the hand turning back
  /// (FusionOptions::drop_features_moving_back).
  int features_moving_back = 0;
  /// Contact pairs found against the model that the tracker's contacts did not have (they are
  /// part of `pairwise.contacts` when used).
  int model_contacts = 0;
  /// Contacts that held ICP as anchors (FusionOptions::icp_contacts_need_spread).
  int icp_anchors = 0;
  /// How the hand turned against the recognised one-way turn (turn_carry.h; kUnknown where
  /// that does not apply), and how far it carried the object where nothing else registered
  /// the frame, degrees. Where it turned back, the contacts were not used.
  HandTurn hand_turn = HandTurn::kUnknown;
  double hand_carried_deg = 0;
  /// How far the hand's turn moved the registered one about the recognised axis, where the
  /// two were weighed (TurnCarryOptions::hand_weight), degrees.
  double hand_blended_deg = 0;
  /// Where this frame recognised the one-way turn: the turn of the earlier frames nothing
  /// registered, caught up from the next frame on (TurnCarryOptions::catch_up_frames), degrees.
  double hand_caught_up_deg = 0;
  /// Whether the contacts took part: in the registration or as ICP's anchors.
  bool ContactsUsed() const { return pairwise.contacts > 0 || icp_anchors > 0; }
  /// The contacts' disagreement with the final pose in this frame (median distance, mm; 0
  /// without contacts), and the running estimate that weighs them in ICP (see
  /// FusionOptions::contact_noise_reference_mm).
  double contact_residual_mm = 0;
  double contact_noise_mm = 0;
  /// Whether this frame became a keyframe, how many loops it closed with earlier keyframes,
  /// and, where they corrected the drift, by how much (mm at the pose graph's lever; the model
  /// was re-fused from the keyframes and `cam_from_object` is the corrected pose).
  bool keyframe = false;
  int loops = 0;
  /// Of those, registered by the keyframes' keypoints (LoopClosureOptions::feature_loops).
  int feature_loops = 0;
  /// The least turn a registration by keypoints was seen off by so far (a pattern that
  /// repeats, or a drift past the gate; KeyframeGraph::alias_deg: loops by keypoints stay within
  /// half of it), degrees; 0 where none was.
  double keypoint_alias_deg = 0;
  double loop_correction_mm = 0;
  double refuse_ms = 0;
  /// Whether ICP started from the previous pose won over the registration's (see
  /// FusionOptions::icp_retry_fraction).
  bool icp_from_previous = false;
  /// Whether the frame showed the object mostly hidden (FusionOptions::hidden): registered and
  /// tracked, not integrated (nor taken to show what the surface leaves free).
  bool hidden = false;
  /// The share of the model's pixels, raycast at the registered pose, that the frame sees
  /// through (see_through.h; NaN where not checked); whether ICP tried again from the object's
  /// points moved the pose (see_through_moved), and whether the frame was held out for it
  /// (see_through_held: tracked, not integrated; `hidden` is then true too).
  double see_through_share = std::numeric_limits<double>::quiet_NaN();
  bool see_through_moved = false;
  bool see_through_held = false;
  /// Whether the pose jumped farther from the previous one than FusionOptions::max_jump_mm or
  /// max_jump_deg allow and was taken, the jump having held (FusionOptions::jump_held_frames).
  bool jump_taken = false;
  /// Where the colours weighed the object standing still (FusionOptions::colour_weighs_still):
  /// their correlation there (else NaN), and whether it won.
  double colour_still_correlation = std::numeric_limits<double>::quiet_NaN();
  bool colour_kept_still = false;
  /// Time spent, ms: in all, and on the pairwise solve, the model's raycast, ICP and the
  /// integration.
  double milliseconds = 0;
  double pairwise_ms = 0;
  double raycast_ms = 0;
  double icp_ms = 0;
  double colour_ms = 0;
  double integrate_ms = 0;
};

/// The model as an export needs it, an immutable copy: the raw marching-cubes mesh (object
/// frame, mm) and the views that bound its closure (free_space.h).
struct ModelSnapshot {
  TriangleMesh raw;
  FreeSpace free_space;
};

/// Registers and fuses an object frame by frame. Not thread-safe; the fusion thread owns it.
class ObjectFusion {
 public:
  ObjectFusion(const CameraIntrinsics& intrinsics, FusionOptions options = {});

  FusionResult Fuse(const FusionInput& input);
  /// The result for a frame the caller does not fuse (`reason`: why): skipped, with the pose
  /// and the coverage so far.
  FusionResult Skip(std::string reason) const;

  /// The raw marching-cubes mesh of the model so far (object frame, mm).
  TriangleMesh ExtractMesh() const { return volume_.ExtractMesh(); }
  /// The raw mesh with the free-space views (they are shared, not copied).
  ModelSnapshot Snapshot() const { return {volume_.ExtractMesh(), free_space_}; }
  const FreeSpace& free_space() const { return free_space_; }
  const TsdfVolume& volume() const { return volume_; }
  const KeyframeGraph& keyframes() const { return keyframes_; }
  bool started() const { return started_; }
  const FusionOptions& options() const { return options_; }

 private:
  // A frame's object: its pixels' points (camera frame, mm) and their bounding box in the image
  // (u0, v0, u1, v1; end exclusive).
  struct ObjectPixels {
    const Frame& frame;
    const std::vector<std::uint8_t>& mask;
    std::vector<Eigen::Vector3f> points;
    std::array<int, 4> box;
  };
  // What ICP needs for a frame: the image region the model is raycast in, how far in front of
  // the object's points the rays start, and its options for the frame.
  struct IcpSetup {
    std::array<int, 4> roi;
    float window = 0;
    IcpOptions options;
    // The frame's occluding contour (FusionOptions::silhouette); no points where it is off.
    IcpContour contour;
  };

  // Completes `result` with `status` and `reason`, keeps the hand and the coverage of a
  // registered frame, and returns it.
  FusionResult Finish(const FusionInput& input, SteadyClock::time_point started_at,
                      FusionStatus status, std::string reason, FusionResult* result);
  // The object's points under `mask`.
  ObjectPixels FindObject(const Frame& frame, const std::vector<std::uint8_t>& mask) const;
  // The first frame: places the volume around the object and integrates it.
  void Start(const FusionInput& input, const ObjectPixels& object, FusionResult* result);
  // Takes `pose` as the object's (the motion from the previous one as the last step).
  void Follow(const Rigid3& pose, FusionResult* result);
  // Takes `pose` as the object's, integrates the frame at it and keeps its free space.
  void Integrate(const FusionInput& input, const ObjectPixels& object, const Rigid3& pose,
                 FusionResult* result);
  // Keeps the fused frame as a keyframe where it is one, and applies what its loops corrected.
  void CloseLoops(const ObjectPixels& object, FusionResult* result);
  // Re-fuses the model from the keyframes at their corrected poses and moves everything kept
  // in the object frame (the pose, the views of free space, the anchors) by `update`.
  void ApplyCorrection(const KeyframeUpdate& update, FusionResult* result);
  // The correspondences' motion applied to the previous pose (that pose where the registration
  // fails); `contacts` gets the contact pairs used (the model's included, anchors applied),
  // none without `with_contacts`, the model's alone without `with_tracker_contacts`.
  Rigid3 Register(const FusionInput& input, bool with_contacts, bool with_tracker_contacts,
                  std::vector<PointMatch>* contacts, FusionResult* result) const;
  // How the hand turns in this frame, where the object's surface leaves a turn free.
  HandTurn JudgeHandTurn(const FusionInput& input);
  // ICP from the registered `pose` (and from the previous one where that pairs too few), which
  // it replaces when ICP succeeds; false when neither the registration nor ICP found a pose.
  bool Refine(const ObjectPixels& object, const std::vector<PointMatch>& contacts, Rigid3* pose,
              FusionResult* result);
  // Whether the frame shows the object at fewer than FusionOptions::hidden's shown_share of the
  // pixels where the model, raycast at `pose` over the whole image, is in view.
  bool ShowsLittleOfModel(const ObjectPixels& object, const Rigid3& pose);
  // The frame's depth against the model at `pose` (see_through.h); where it sees through, ICP
  // once more from the model's visible part moved onto the object's points, kept where it
  // pairs no fewer points and sees through less. Sets result's see_through fields.
  void CheckSeeThrough(const ObjectPixels& object, const IcpSetup& setup, Rigid3* pose,
                       FusionResult* result);
  // ICP without the contacts from `pose` moved by the object points' centroid less `seen`'s
  // visible centroid; taken (with `seen` updated) where it pairs no fewer points than the
  // frame's ICP and sees through less.
  void RetryOnObjectCentre(const ObjectPixels& object, const IcpSetup& setup, SeeThrough* seen,
                           Rigid3* pose, FusionResult* result);
  // Where the hand turns on: the registered turn about the recognised axis moved toward the
  // hand's (TurnCarryOptions::hand_weight), then ICP without the contacts from there, against
  // the model as last raycast; `icp_predicted` becomes the pose that raycast was cast at.
  void BlendHandTurn(const ObjectPixels& object, const IcpSetup& setup, Rigid3* icp_predicted,
                     Rigid3* pose, FusionResult* result);
  SeeThrough SeeThroughAt(const ObjectPixels& object, const Rigid3& pose, FusionResult* result);
  // Whether the registration's contacts spread far enough to fix a turn.
  bool ContactsSpread(const FusionResult& result) const;
  // The contacts that hold ICP, at where the registered `pose` moves them.
  std::vector<IcpAnchor> ContactAnchors(const std::vector<PointMatch>& contacts, const Rigid3& pose,
                                        const FusionResult& result) const;
  // The raycast region, the near depth (near_depth_) and the ICP options for a frame at `pose`.
  IcpSetup PrepareIcp(const ObjectPixels& object, const Rigid3& pose, const FusionResult& result);
  // Raycasts the model at `predicted` and aligns the object's points to it (timed in `result`).
  IcpResult AlignAt(const ObjectPixels& object, const IcpSetup& setup, const Rigid3& predicted,
                    const std::vector<IcpAnchor>& anchors, FusionResult* result);
  // Aligns the object's points, without anchors, from `start` to the model as last raycast
  // (model_image_, cast at model_image_pose_): a start a little off that pose needs no new
  // raycast (timed in `result`).
  IcpResult AlignFrom(const ObjectPixels& object, const IcpSetup& setup, const Rigid3& start,
                      FusionResult* result) const;
  // Moves `pose` (ICP's from `icp_predicted`) along the free directions ICP found so that the
  // object's colours land on the model's (model_image_; FusionOptions::colour).
  // Skipped for FusionOptions::colour_recheck_frames after a frame without a pattern.
  void AlignColours(const ObjectPixels& object, const Rigid3& icp_predicted, Rigid3* pose,
                    FusionResult* result);
  ColourAlignResult AlignColoursOf(const ObjectPixels& object, const IcpResult& icp,
                                   const Rigid3& icp_predicted, Rigid3* pose) const;
  // ICP and the colours from the previous pose, kept where the colours match better
  // (FusionOptions::colour_weighs_still).
  void WeighStillByColour(const ObjectPixels& object, const IcpSetup& setup,
                          const Rigid3& icp_predicted, Rigid3* pose, FusionResult* result);
  // Why the step from `from` to `to` is implausible (empty when it is not).
  std::string ImplausibleJump(const Rigid3& from, const Rigid3& to) const;
  // Whether an implausible jump to `pose` has now held for FusionOptions::jump_held_frames
  // frames in a row (each within the limits of the last), found by ICP (`icp_found`) where the
  // surface fixes every direction, and agrees with the hand's turn since the last pose.
  bool JumpHolds(const Rigid3& pose, bool icp_found);
  // Updates the running estimate of the contacts' noise from how far `step` leaves them.
  void UpdateContactNoise(const std::vector<PointMatch>& contacts, const Rigid3& step,
                          FusionResult* result);
  // Adds the fingertip contacts found against the model that `contacts` lacks (by id); returns
  // how many pairs.
  int AddModelContacts(const FusionInput& input, std::vector<PointMatch>* contacts) const;
  struct Anchor {
    Eigen::Vector3d object_point;
    int observations = 0;
  };
  // By the pairs' ids.
  using Anchors = std::unordered_map<int, Anchor>;

  // Replaces the previous-frame positions of anchored pairs by their anchors (seen from the
  // previous pose); returns how many.
  int ApplyAnchors(const Anchors& anchors, std::vector<PointMatch>* pairs) const;
  // After registering at `cam_from_object`: the anchors of the pairs still held, updated.
  void UpdateAnchors(const std::vector<PointMatch>& pairs, const Rigid3& cam_from_object,
                     Anchors* anchors) const;
  // The visual sets' anchors after registering at `cam_from_object`.
  void UpdateFeatureAnchors(const PairwiseInput& correspondences, const Rigid3& cam_from_object);
  // Leaves out of `pairs` those `hand_motion` explains better than standing still; returns how
  // many (FusionOptions::drop_features_moving_back).
  int DropPairsMovingWith(const Rigid3& hand_motion, std::vector<PointMatch>* pairs) const;
  // Every anchor (contacts' and features') moved in the object frame by `object_from_moved`.
  void MoveAnchors(const Rigid3& object_from_moved);
  // Where this frame recognised the one-way turn, turns the pose on by what the frames before
  // missed (TurnCarry::TakeCatchUp), the anchors kept where the camera saw them.
  void CatchUpTurn(FusionResult* result);

  const CameraIntrinsics intrinsics_;
  const FusionOptions options_;
  TsdfVolume volume_;
  ViewCoverage coverage_;
  FreeSpace free_space_;
  // Per-frame scratch kept between frames (fresh megabytes every frame cost page faults).
  RaycastImage model_image_;
  // The model seen from a frame's pose over the whole image (ShowsLittleOfModel) or a sample
  // of it (SeeThroughAt).
  RaycastImage hidden_image_;
  // Where model_image_ was raycast from (cam_from_object).
  Rigid3 model_image_pose_;
  std::vector<std::uint16_t> near_depth_;
  // The pixels the see-through check raycasts (SeeThroughPixels).
  std::vector<std::uint16_t> see_through_depth_;
  bool started_ = false;
  Rigid3 cam_from_object_;
  // Frames in a row that saw through the model at their pose (SeeThroughOptions::
  // max_held_frames).
  int see_through_frames_ = 0;
  // The share of its points the last frame's ICP paired (0: none yet).
  double last_paired_ = 0;
  // The object's motion between the last two fused frames (camera frame).
  Rigid3 last_step_;
  // Whether the last frame's ICP left a direction free (FusionOptions::predict_moving).
  bool surface_left_free_ = true;
  // Where the last fused frame whose ICP judged the free directions took its turns about (the
  // turn the hand carries is turned about it), in the object frame.
  Eigen::Vector3d pivot_in_object_ = Eigen::Vector3d::Zero();
  // The running estimate of the contacts' disagreement with the registered motion, mm (starts
  // at the reference: the configured share until contacts have been seen).
  double contact_noise_mm_ = 0;
  Anchors anchors_;
  // The visual features' anchors, by their source's name (FusionOptions::anchor_features).
  std::unordered_map<std::string, Anchors> feature_anchors_;
  // The hand's vertices in the previous frame, when it was registered (else empty).
  std::vector<Eigen::Vector3f> previous_hand_;
  TurnCarry turn_carry_;
  HiddenSpan hidden_;
  // The last implausible jump's pose and how many frames in a row it has held.
  Rigid3 jumped_to_;
  int jump_held_ = 0;
  // The hand's motion (camera frame) since the frame the pose was last taken in, and whether the
  // tracker followed the hand in every frame since (FusionInput::hand_motion).
  Rigid3 hand_turn_since_;
  bool hand_turn_known_ = true;
  KeyframeGraph keyframes_;
  // Frames the colour alignment still skips after one that showed no pattern.
  int colour_skips_left_ = 0;
  // Frames fused so far (the stamp of keyframes and views).
  int fused_frames_ = 0;
};

}  // namespace ihs::fusion
