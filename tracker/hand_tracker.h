#pragma once
// The hand-tracker stage: per frame, segment hand and object, fit the hand model from a
// constant-velocity prediction, search for the hand anew when the fits grow doubtful (without
// stopping), and find the fingertip contacts with the object. One obvious entry point:
// Track(frame).

#include <Eigen/Core>
#include <future>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "tracker/contacts.h"
#include "tracker/grasp_hold.h"
#include "tracker/grasp_side.h"
#include "tracker/hand_fit.h"
#include "tracker/hand_model.h"
#include "tracker/hand_pose.h"
#include "tracker/hand_search.h"
#include "tracker/release_watch.h"
#include "tracker/segmentation.h"

namespace ihs::tracker {

/// Options of the hand tracker.
struct TrackerOptions {
  SegmentationOptions segmentation;
  HandFitOptions fit;
  ContactOptions contacts;
  GraspHoldOptions grasp_hold;
  ReleaseOptions release;
  /// A pose whose palm faces away from the object seen in the hand explains the frame worse
  /// (GraspSide): in the search's ranking, the tracked fit's competition with a search, and the
  /// turned-over check.
  GraspSideOptions grasp_side;
  /// A frame needs this many hand points to be fitted; with fewer it is skipped (no hand).
  int min_hand_points = 150;
  /// A fit with fewer of the hand's points within 10 mm of the model than this has diverged
  /// (the frame's pose is not used).
  double min_data_coverage = 0.75;
  /// A fit with fewer than this is doubtful: a hand fitted in the wrong place or turned the
  /// wrong way round can still explain most of its points (on the generator's scripted turns,
  /// frames with 25–90 mm joint error explained a median 0.92–0.94 of them, while 99 % of the
  /// well tracked frames of the recorded and scripted motions explained 0.95 or more).
  double search_data_coverage = 0.9;
  /// Doubtful (or diverged) frames in a row before the tracker searches for the hand anew
  /// (as on the first frame with a hand) and keeps the best explanation, the tracked fit
  /// included.
  int doubtful_frames_to_search = 2;
  /// A search also runs when a frame shows at least search_when_points_grow times the hand
  /// points of any frame searched before while the hand touches nothing (no contacts in the
  /// previous frame), and its pose replaces the tracked fit only where it scores
  /// search_growth_gain times better (0: never). A hand first seen mostly hidden behind the
  /// object, a few fingertips beside it, is fitted where those fingertips allow, its wrist
  /// 50-100 mm from the truth, and tracked there. Off: on the grasps of tools/bench_hand_init.sh
  /// (seeds 9100, 9200, 9300) the joint error fell (25.4 -> 22.7 mm on 9100, its worst fit 91
  /// -> 54 mm) without a fit more flipped, but on 2 of 47 scripted full turns a pose replaced
  /// early broke the scan that followed (pin 3215 turned 98 -> 51 %; docs/tracker.md).
  double search_when_points_grow = 0.0;
  double search_growth_gain = 1.5;
  /// A search (HandSearch) places the open hand, four curls of it toward a fist (a fifth to
  /// four fifths of each finger's flexion range), the last confident pose's articulation and
  /// the one held now in many orientations onto the hand points; its search_candidates best
  /// are fitted for search_coarse_iterations correspondence updates, the search_refined best
  /// of those for initialisation_iterations more, and the best of these wins. On eight
  /// generated sequences (six scripted turns, two recorded motions; self-initialised) the mean
  /// joint error fell from 27.8 to 13.6 mm against the principal axes alone (docs/tracker.md).
  HandSearchOptions search;
  int search_candidates = 12;
  int search_coarse_iterations = 2;
  int search_refined = 3;
  /// Levenberg–Marquardt iterations (outer) for each refined search hypothesis.
  int initialisation_iterations = 8;
  /// The template's size is estimated over this many frames with a hand (0: the template is
  /// used at the size it comes in): on each, the pose is fitted at every candidate scale in
  /// 1 ± scale_range (steps of scale_step), and the scale that explains the hand points best
  /// over all of them is kept (refined between the steps). The tracker runs at the template's
  /// own size meanwhile.
  int scale_frames = 10;
  double scale_range = 0.15;
  double scale_step = 0.05;
  /// Every flip_check_frames frames with a pose, and on every fit found by a search (0:
  /// never), the fit turned over (TurnedOver: palm for back, thumb for little finger) is fitted
  /// too (initialisation_iterations), and replaces the fit when it explains the hand better;
  /// when it explains it within flip_tie_score as well (FitScore's units: mm of mean distance,
  /// 20 per share of points unexplained), the pose is doubtful. On the 22 generated sequences
  /// of tools/bench_hand_init.sh (seed 1000) it neither won nor tied once (on one of them the
  /// turned-over fit scored 14.6–35 against 3.5–9.7: the wrong fits there are misplaced, not
  /// turned over) and costs about a tenth more fit time at 10 frames (docs/tracker.md); it
  /// guards against the held-out palm-for-back fit.
  int flip_check_frames = 10;
  double flip_tie_score = 0.5;
  /// With each turned-over check, where an object is seen in the hand and the fit's thumb does
  /// not hold it against the fingers (GraspSide::Opposition above max_opposition_cosine), the
  /// thumb is also started elsewhere (ThumbVariants), each fitted for search_coarse_iterations,
  /// the best for initialisation_iterations; it replaces the fit when it scores better. A thumb
  /// hidden behind the object slid to the fingers' side in half the flipped sequences of
  /// tools/bench_hand_init.sh (docs/tracker.md). A frame whose thumb it moved stays tracked
  /// (TrackResult::thumb_moved): the hand's motion across it still carries a held object. Off by
  /// default: with it (and GraspSideOptions::opposition_weight 10) fewer fits flipped on the 72
  /// generated grasps (33 → 17), but on 22 scripted full turns the scans followed 85 → 81 % of
  /// the turn, used contacts in 60 → 51 % of the grasping frames, Chamfer 1.40 → 1.83 mm.
  bool thumb_check = false;
  /// A search that a run of doubtful fits starts runs beside the tracking instead of stalling
  /// it: the tracker goes on fitting each frame from its last pose, and once the search is done
  /// its best pose (found on an older frame, moved on by the tracked root's motion since) is
  /// fitted on the newest frame and replaces the tracked fit where it explains the hand better.
  /// For live input (the pipeline turns it on for a live source): a search stalls the tracker
  /// for 0.3-0.7 s, the frames arriving meanwhile are dropped, and the next frame, far from the
  /// last fit, starts another search. Off, the same frames always give the same hands. The
  /// first search (no pose yet) always runs in place. The periodic check of the fit turned
  /// over (flip_check_frames) runs beside too: the fit turned over on the frame it was due,
  /// weighed there against the tracked fit, and where it won, moved on and fitted on the
  /// newest frame as a search's pose is (a check in place added 20-35 ms to every tenth
  /// frame's latency). A fit found by a search is still checked in place. So do the scale
  /// estimate's fits (scale_frames): each frame's on a copy while the tracker goes on at the
  /// template's size, a frame that comes while they run left out of the estimate, the switch
  /// made on the frame after the last one's fits are done.
  bool search_beside = false;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// What happened to a frame.
enum class TrackStatus {
  kTracked,      ///< Fitted from the previous pose.
  kInitialised,  ///< Fitted from scratch (first frame with a hand, or a search won).
  kDiverged,     ///< Fitted, but the fit does not explain the data; not to be trusted.
  kNoHand,       ///< Skipped: too few hand points.
  kEmptyFrame,   ///< Skipped: no depth at all.
};

/// A short name for stats and logs ("tracked", "initialised", …).
const char* ToString(TrackStatus status);

/// A contact vertex seen in contact in two consecutive frames: where the hand had it in the
/// previous frame and where it has it now (camera frame, mm). Without slip, both are the same
/// point of the object.
struct ContactPair {
  int vertex = 0;
  Eigen::Vector3d previous_mm;
  Eigen::Vector3d current_mm;
};

/// The tracker's result for one frame.
struct TrackResult {
  TrackStatus status = TrackStatus::kNoHand;
  /// Why a frame was skipped or distrusted (empty when tracked).
  std::string reason;
  HandPose pose;
  /// The 21 joints (HandModel::JointPositions), camera frame, mm.
  std::vector<Eigen::Vector3d> joints_mm;
  /// The template posed at `pose` (camera frame, mm) when the pose is usable, for whoever needs
  /// the hand's surface next (the object mask) without posing it again.
  std::shared_ptr<const TriangleMesh> posed_mesh;
  Contacts contacts;
  std::vector<ContactPair> contact_pairs;
  Segmentation segmentation;
  HandFitResult fit;
  /// The pose is given, but its fit explains fewer than TrackerOptions::search_data_coverage of
  /// the hand points: the hand may be in the wrong place or turned the wrong way round (the
  /// tracker searches anew after doubtful_frames_to_search such frames in a row), or its fit
  /// turned over explains them about as well (TrackerOptions::flip_check_frames).
  bool doubtful = false;
  /// The fit turned over explained the hand better than the fit and replaced it this frame.
  bool turned_over = false;
  /// The thumb check (TrackerOptions::thumb_check) moved the thumb this frame: the rest of the
  /// hand is the previous one moved (the frame stays tracked), the thumb's contacts are not
  /// paired across the frame.
  bool thumb_moved = false;
  /// The fit turned over was tried this frame and explained the hand about as well (within
  /// TrackerOptions::flip_tie_score): the pose is doubtful.
  bool flip_tie = false;
  /// The previous frame's grasp was let go this frame (ReleaseWatch): its fingertips do not
  /// count as contacts until they come back.
  bool grasp_let_go = false;
  /// The template's scale in use (1 until an estimate is made; see TrackerOptions).
  double hand_scale = 1.0;
  /// Time spent on this frame, ms: in all, and on segmentation, the pose fit (with any
  /// re-initialisation) and the contacts.
  double milliseconds = 0;
  double segmentation_ms = 0;
  double fit_ms = 0;
  double contacts_ms = 0;

  /// Whether the pose is usable (tracked or initialised).
  bool HasPose() const {
    return status == TrackStatus::kTracked || status == TrackStatus::kInitialised;
  }
  /// The status for a person: ToString(status), with " (doubtful)" after a doubtful pose.
  std::string State() const {
    return std::string(ToString(status)) + (doubtful ? " (doubtful)" : "");
  }
};

/// Tracks one hand through a sequence of frames. Not thread-safe; one per thread.
class HandTracker {
 public:
  HandTracker(HandModel model, const CameraIntrinsics& intrinsics, TrackerOptions options = {});
  ~HandTracker();

  /// Starts (or restarts) from a known pose (benchmark mode: the ground truth); otherwise the
  /// first frame with a hand initialises from the hand cloud (the user shows an open hand).
  void Initialise(const HandPose& pose);

  /// Processes the next frame (depth in mm with registered colour).
  TrackResult Track(const Frame& frame);

  /// Whether a search runs beside the tracking (TrackerOptions::search_beside).
  bool searching() const { return pending_ != nullptr; }
  /// Whether a check of the fit turned over runs beside the tracking (search_beside).
  bool checking_flip() const { return pending_flip_ != nullptr; }
  /// Waits until a search (and a check of the fit turned over, and a frame of the scale
  /// estimate) running beside the tracking is done; the next Track weighs its pose.
  void FinishSearch();

  /// The template at its current scale (it changes once, when the scale estimate is made).
  const HandModel& model() const { return model_; }
  double scale() const { return scale_; }
  /// Whether the template's scale is still being estimated.
  bool estimating_scale() const { return !scale_candidates_.empty(); }
  /// Whether the estimate lies on a bound of its range (the hand may be that size or beyond, or
  /// its first fits were wrong).
  bool scale_at_bound() const { return scale_at_bound_; }
  const TrackerOptions& options() const { return options_; }

 private:
  struct ScaleCandidate;
  struct PendingSearch;
  struct PendingFlipCheck;
  // What a search places: the open hand and its curls, and the poses the tracker holds.
  struct SearchStarts {
    std::vector<HandPose> articulations, tracked;
  };
  SearchStarts StartsOfSearch() const;
  // The fit from the search's hypotheses that explains the hand best. Reads only what no frame
  // changes (the model, the fitters, the options) besides its arguments: it may run on another
  // thread while the tracker goes on (search_beside), until the scale estimate rebuilds them.
  HandFitResult Search(const SearchStarts& starts, const std::vector<Eigen::Vector3f>& hand_points,
                       const Frame& frame, const Segmentation* segmentation,
                       const GraspSide* side) const;
  // Starts a search beside the tracking on copies of this frame's data.
  // `gain`: how many times better the search's pose must score to replace the tracked fit.
  void StartSearchBeside(const Frame& frame, const TrackResult& result,
                         const std::optional<GraspSide>& side, double gain);
  // A finished search's pose, moved on and fitted on this frame, replaces `result`'s fit where
  // it explains the hand better (by the search's gain).
  void WeighSearchBeside(const Frame& frame, TrackResult& result, const GraspSide* side);
  // Starts the check of the fit turned over (CheckTurnedOver) beside the tracking, on copies
  // of this frame's data.
  void StartFlipCheckBeside(const Frame& frame, const TrackResult& result,
                            const std::optional<GraspSide>& side);
  // A finished check beside: where the fit turned over explained its frame better, it is moved
  // on, fitted on this frame and replaces `result`'s fit where it explains the hand better;
  // a tie on its frame makes this one doubtful.
  void WeighFlipCheckBeside(const Frame& frame, TrackResult& result, const GraspSide* side);
  // `found` (`what` found it on frame `then_frame`, where the tracked root was `then_root`),
  // moved on as the tracked root moved since and fitted on this frame: replaces `result`'s fit
  // where it scores `gain` times better (returns whether it did).
  bool TakeMovedOn(const char* what, const HandPose& found, const Rigid3& then_root,
                   std::int64_t then_frame, const Frame& frame, TrackResult& result,
                   const GraspSide* side, double gain = 1.0) const;
  // How badly `fit` explains the frame (lower is better): FitScore, and the grasp side's
  // penalty where an object is seen in the hand.
  double Score(const HandFitResult& fit, const GraspSide* side) const;
  // The fit turned over (TurnedOver), fitted: replaces `result`'s fit when it explains the hand
  // better; returns whether the two tie (within flip_tie_score).
  bool CheckTurnedOver(const std::vector<Eigen::Vector3f>& hand_points, const Frame& frame,
                       TrackResult& result, const GraspSide* side) const;
  // The fit with its thumb started elsewhere (ThumbVariants), fitted: the best replaces
  // `result`'s fit when it explains the hand better (returns whether it did).
  bool CheckThumb(const std::vector<Eigen::Vector3f>& hand_points, const Frame& frame,
                  TrackResult& result, const GraspSide* side) const;
  // The fingertips touching in the previous frame (tracked), each with the object's surface
  // seen around where `predicted` moves it (HandFitOptions::contact_surface_weight).
  std::vector<SurfaceContact> HeldContacts(const HandPose& predicted,
                                           const Segmentation& segmentation) const;
  // Builds the fitters and the contact detector for model_.
  void BuildStages();
  // `pose` of the template at scale `from` carried over to scale `to`: same angles, the hand's
  // middle where it was.
  HandPose Rescaled(const HandPose& pose, double from, double to) const;
  // One frame of the scale estimate; switches to the estimated scale after the last frame.
  void EstimateScale(const Segmentation& segmentation, const Frame& frame);
  // The same beside the tracking (search_beside): weighs the last frame's fits when they are
  // done, then starts this frame's (or leaves this frame out while they run).
  void EstimateScaleBeside(const Segmentation& segmentation, const Frame& frame);
  // The pose to fit each candidate scale from: the current one, carried over to its scale.
  std::vector<HandPose> ScaleStarts() const;
  // Each candidate scale fitted on a frame, its score added to the candidate's.
  void FitScaleCandidates(const Segmentation& segmentation, const Frame& frame,
                          const std::vector<HandPose>& starts);
  // The scale the candidates' scores give; the stages rebuilt for it.
  void FinishScaleEstimate();

  const HandModel base_model_;
  const bool right_hand_;
  HandModel model_;
  double scale_ = 1.0;
  const CameraIntrinsics intrinsics_;
  const TrackerOptions options_;
  Segmenter segmenter_;
  std::unique_ptr<HandFitter> fitter_;
  std::unique_ptr<HandSearch> search_;
  std::unique_ptr<HandFitter> coarse_fitter_;
  std::unique_ptr<HandFitter> initial_fitter_;
  std::unique_ptr<ContactDetector> contacts_;
  std::unique_ptr<GraspHold> grasp_hold_;
  std::unique_ptr<ReleaseWatch> release_watch_;
  // The thumb's fingertip vertices (ContactDetector::fingertip_vertices), sorted.
  std::vector<int> thumb_vertices_;
  std::vector<std::unique_ptr<ScaleCandidate>> scale_candidates_;
  int scale_frames_done_ = 0;
  bool scale_at_bound_ = false;
  bool has_pose_ = false;
  HandPose pose_;
  HandPose previous_pose_;
  bool has_previous_ = false;
  int doubtful_in_a_row_ = 0;
  int frames_since_flip_check_ = 0;
  // The most hand points a frame that a search ran on had (0: none ran yet).
  size_t points_at_search_ = 0;
  // The last pose whose fit explained at least search_data_coverage of the hand points.
  HandPose confident_pose_;
  bool has_confident_pose_ = false;
  std::vector<Eigen::Vector3f> previous_vertices_;
  std::vector<int> previous_contact_vertices_;
  std::vector<int> previous_contact_bones_;
  // A search and a check of the fit turned over running beside the tracking; last, so that
  // they are waited for before the stages they use go.
  std::unique_ptr<PendingSearch> pending_;
  std::unique_ptr<PendingFlipCheck> pending_flip_;
  // A frame's scale candidates being fitted beside the tracking.
  std::future<void> pending_scale_;
};

}  // namespace ihs::tracker
