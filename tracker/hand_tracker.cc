#include "tracker/hand_tracker.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "core/check.h"
#include "core/parallel_runs.h"
#include "core/point_kd_tree.h"
#include "core/stopwatch.h"

namespace ihs::tracker {
namespace {

// How badly a fit explains the hand (lower is better): the data's mean distance, and the shares
// of data and of visible model points left unexplained (20 mm for none explained).
double FitScore(const HandFitResult& fit) {
  return fit.data_error_mm + 20.0 * (1.0 - fit.data_coverage) + 20.0 * (1.0 - fit.model_coverage);
}

}  // namespace

const char* ToString(TrackStatus status) {
  switch (status) {
    case TrackStatus::kTracked:
      return "tracked";
    case TrackStatus::kInitialised:
      return "initialised";
    case TrackStatus::kDiverged:
      return "diverged";
    case TrackStatus::kNoHand:
      return "no_hand";
    case TrackStatus::kEmptyFrame:
      return "empty_frame";
  }
  return "unknown";
}

void TrackerOptions::Check() const {
  segmentation.Check();
  fit.Check();
  contacts.Check();
  grasp_hold.Check();
  release.Check();
  grasp_side.Check();
  IHS_CHECK_ARG(min_hand_points >= 10, "tracker.min_hand_points must be >= 10");
  IHS_CHECK_ARG(min_data_coverage >= 0 && min_data_coverage <= 1,
                "tracker.min_data_coverage must be in [0, 1]");
  IHS_CHECK_ARG(search_data_coverage >= min_data_coverage && search_data_coverage <= 1,
                "tracker.search_data_coverage must be in [min_data_coverage, 1]");
  IHS_CHECK_ARG(doubtful_frames_to_search >= 1, "tracker.doubtful_frames_to_search must be >= 1");
  IHS_CHECK_ARG(search_when_points_grow == 0 || search_when_points_grow > 1,
                "tracker.search_when_points_grow must be 0 or > 1");
  IHS_CHECK_ARG(search_growth_gain >= 1, "tracker.search_growth_gain must be >= 1");
  IHS_CHECK_ARG(initialisation_iterations >= 1 && initialisation_iterations <= 100,
                "tracker.initialisation_iterations must be in [1, 100]");
  IHS_CHECK_ARG(search_coarse_iterations >= 1 && search_coarse_iterations <= 100,
                "tracker.search_coarse_iterations must be in [1, 100]");
  search.Check();
  IHS_CHECK_ARG(search_candidates >= 1 && search_candidates <= 1000,
                "tracker.search_candidates must be in [1, 1000]");
  IHS_CHECK_ARG(search_refined >= 1 && search_refined <= 100,
                "tracker.search_refined must be in [1, 100]");
  // Each of the first scale_frames frames is fitted at every scale tried (2 range / step + 1).
  IHS_CHECK_ARG(scale_frames >= 0 && scale_frames <= 300,
                "tracker.scale_frames must be in [0, 300]");
  IHS_CHECK_ARG(scale_range >= 0 && scale_range < 0.5, "tracker.scale_range must be in [0, 0.5)");
  IHS_CHECK_ARG(flip_check_frames >= 0 && flip_check_frames <= 100000,
                "tracker.flip_check_frames must be in [0, 100000]");
  IHS_CHECK_ARG(flip_tie_score >= 0 && flip_tie_score <= 100,
                "tracker.flip_tie_score must be in [0, 100]");
  IHS_CHECK_ARG(scale_step > 0 && scale_range <= 50 * scale_step,
                "tracker.scale_step must be positive and at least scale_range / 50 (at most 101 "
                "scales tried)");
}

namespace {
// The fit's options with the segmentation's crop volume.
HandFitOptions FitOptions(const TrackerOptions& options) {
  HandFitOptions fit = options.fit;
  fit.crop_min_mm = options.segmentation.crop_min_mm;
  fit.crop_max_mm = options.segmentation.crop_max_mm;
  return fit;
}

HandFitOptions InitialFitOptions(const TrackerOptions& options, int iterations) {
  HandFitOptions fit = FitOptions(options);
  fit.outer_iterations = iterations;
  fit.prior_weight = 0.5;
  return fit;
}

}  // namespace

// A template scale being tried: the scaled model, its fitter and its summed score.
struct HandTracker::ScaleCandidate {
  double scale = 1.0;
  HandModel model;
  std::unique_ptr<HandFitter> fitter;
  double score = 0;
};

// A search running beside the tracking: its result, and the tracked root when it started (the
// hand's motion since then carries the result on to the frame it is weighed in).
struct HandTracker::PendingSearch {
  std::future<HandFitResult> found;
  Rigid3 cam_from_root;
  std::int64_t frame_index = 0;
  double gain = 1.0;  // How many times better the found pose must score.
};

struct HandTracker::PendingFlipCheck {
  // The fit turned over and its score, on the frame the check began on.
  std::future<std::pair<HandFitResult, double>> turned;
  // The tracked fit's score and root there.
  double kept_score = 0;
  Rigid3 cam_from_root;
  std::int64_t frame_index = 0;
};

HandTracker::HandTracker(HandModel model, const CameraIntrinsics& intrinsics,
                         TrackerOptions options)
    : base_model_(std::move(model)),
      right_hand_(IsRightHand(base_model_)),
      model_(base_model_),
      intrinsics_(intrinsics),
      options_((options.Check(), std::move(options))),
      segmenter_(intrinsics, options_.segmentation) {
  BuildStages();
  if (options_.scale_frames > 0 && options_.scale_range > 0) {
    HandFitOptions fit = FitOptions(options_);
    fit.outer_iterations = std::min(fit.outer_iterations, 3);
    const int steps =
        static_cast<int>(std::floor(options_.scale_range / options_.scale_step + 1e-6));
    for (int k = -steps; k <= steps; ++k) {
      auto candidate = std::make_unique<ScaleCandidate>();
      candidate->scale = 1.0 + k * options_.scale_step;
      candidate->model = base_model_.Scaled(candidate->scale);
      candidate->fitter = std::make_unique<HandFitter>(candidate->model, intrinsics_, fit);
      scale_candidates_.push_back(std::move(candidate));
    }
  }
}

HandTracker::~HandTracker() = default;

void HandTracker::BuildStages() {
  fitter_ = std::make_unique<HandFitter>(model_, intrinsics_, FitOptions(options_));
  search_ = std::make_unique<HandSearch>(model_, intrinsics_, options_.search);
  coarse_fitter_ = std::make_unique<HandFitter>(
      model_, intrinsics_, InitialFitOptions(options_, options_.search_coarse_iterations));
  initial_fitter_ = std::make_unique<HandFitter>(
      model_, intrinsics_, InitialFitOptions(options_, options_.initialisation_iterations));
  contacts_ = std::make_unique<ContactDetector>(model_, options_.contacts);
  grasp_hold_ = std::make_unique<GraspHold>(options_.grasp_hold, options_.contacts.min_bones,
                                            model_.EndEffectors(), contacts_->fingertip_vertices());
  release_watch_ =
      std::make_unique<ReleaseWatch>(options_.release, contacts_->fingertip_vertices().size());
  thumb_vertices_.clear();
  const std::vector<int> ends = model_.EndEffectors();
  for (size_t k = 0; k < ends.size() && k < contacts_->fingertip_vertices().size(); ++k) {
    if (model_.FingerOf(ends[k]) != 4) continue;
    const std::vector<int>& tip = contacts_->fingertip_vertices()[k];
    thumb_vertices_.insert(thumb_vertices_.end(), tip.begin(), tip.end());
  }
  std::sort(thumb_vertices_.begin(), thumb_vertices_.end());
}

HandPose HandTracker::Rescaled(const HandPose& pose, double from, double to) const {
  // The rest joints' centroid in the root's frame, at the base scale; it scales with the model.
  const std::vector<Eigen::Vector3d> joints =
      base_model_.JointPositions(ForwardKinematics(base_model_, HandPose::Rest(base_model_)));
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& joint : joints) centre += joint;
  centre = base_model_.model_from_bone_rest[0].Inverse() * Eigen::Vector3d(centre / joints.size());
  HandPose out = pose;
  out.cam_from_root = Rigid3(
      pose.cam_from_root.rotation(),
      pose.cam_from_root.translation() + pose.cam_from_root.rotation() * ((from - to) * centre));
  return out;
}

std::vector<HandPose> HandTracker::ScaleStarts() const {
  std::vector<HandPose> starts;
  for (const auto& candidate : scale_candidates_)
    starts.push_back(Rescaled(pose_, scale_, candidate->scale));
  return starts;
}

void HandTracker::EstimateScale(const Segmentation& segmentation, const Frame& frame) {
  FitScaleCandidates(segmentation, frame, ScaleStarts());
  if (++scale_frames_done_ >= options_.scale_frames) FinishScaleEstimate();
}

void HandTracker::EstimateScaleBeside(const Segmentation& segmentation, const Frame& frame) {
  if (pending_scale_.valid()) {
    if (pending_scale_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return;
    pending_scale_.get();
    if (++scale_frames_done_ >= options_.scale_frames) {
      FinishScaleEstimate();
      return;
    }
  }
  pending_scale_ = std::async(std::launch::async, [this, segmentation = segmentation, frame = frame,
                                                   starts = ScaleStarts()]() {
    FitScaleCandidates(segmentation, frame, starts);
  });
}

void HandTracker::FitScaleCandidates(const Segmentation& segmentation, const Frame& frame,
                                     const std::vector<HandPose>& starts) {
  // Each scale's fit is its own (on the search's threads: the first frames cost several fits).
  ParallelRuns(scale_candidates_.size(), options_.search.threads, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      ScaleCandidate& candidate = *scale_candidates_[k];
      const HandFitResult fit =
          candidate.fitter->Fit(segmentation.hand_points, &frame, starts[k], &segmentation);
      // How far the hand points are from the model, and the model's visible points from them.
      candidate.score += fit.data_error_mm + fit.model_error_mm;
    }
  });
}

void HandTracker::FinishScaleEstimate() {
  size_t best = 0;
  for (size_t k = 1; k < scale_candidates_.size(); ++k) {
    if (scale_candidates_[k]->score < scale_candidates_[best]->score) best = k;
  }
  double scale = scale_candidates_[best]->scale;
  scale_at_bound_ = best == 0 || best + 1 == scale_candidates_.size();
  if (scale_at_bound_) {
    // Searching anew and estimating again did not help (docs/tracker.md): said, not retried.
    spdlog::warn(
        "hand scale estimate {:.2f} is on a bound of its range: the hand may be that "
        "size or beyond, or its first fits were wrong (scan.hand_scale sets it)",
        scale);
  }
  if (best > 0 && best + 1 < scale_candidates_.size()) {
    // The minimum of the parabola through the best score and its neighbours.
    const double a = scale_candidates_[best - 1]->score, b = scale_candidates_[best]->score,
                 c = scale_candidates_[best + 1]->score;
    const double curvature = a - 2 * b + c;
    if (curvature > 1e-9) scale += 0.5 * options_.scale_step * (a - c) / curvature;
  }
  std::string scores;
  for (const auto& candidate : scale_candidates_) {
    scores +=
        fmt::format(" {:.2f}: {:.2f}", candidate->scale, candidate->score / options_.scale_frames);
  }
  spdlog::debug("hand scale {:.3f} from mean scores{}", scale, scores);
  scale_candidates_.clear();
  // A search beside the tracking uses the stages rebuilt below: it is waited for and dropped
  // (its pose is at the old scale).
  FinishSearch();
  pending_.reset();
  pending_flip_.reset();
  pose_ = Rescaled(pose_, scale_, scale);
  has_previous_ = false;
  previous_vertices_.clear();
  previous_contact_vertices_.clear();
  scale_ = scale;
  model_ = base_model_.Scaled(scale_);
  BuildStages();
}

void HandTracker::Initialise(const HandPose& pose) {
  pose_ = pose;
  has_pose_ = true;
  has_previous_ = false;
  doubtful_in_a_row_ = 0;
  has_confident_pose_ = false;
}

double HandTracker::Score(const HandFitResult& fit, const GraspSide* side) const {
  return FitScore(fit) + (side != nullptr ? side->Penalty(model_, fit.pose, right_hand_) : 0.0);
}

HandTracker::SearchStarts HandTracker::StartsOfSearch() const {
  // Articulations to place: the open hand and four curls toward a fist, the last confident
  // pose's and the one held now (a grasping hand is far from the open one: from the open hand
  // alone a search after a jump mid-grasp settled 122 mm off with 88 % of the points
  // explained); those two also from where they were.
  SearchStarts starts;
  for (double curl : {0.0, 0.2, 0.4, 0.6, 0.8})
    starts.articulations.push_back(CurledHand(model_, curl));
  if (has_confident_pose_) starts.tracked.push_back(confident_pose_);
  if (has_pose_ && (!has_confident_pose_ || pose_.angles_rad != confident_pose_.angles_rad))
    starts.tracked.push_back(pose_);
  return starts;
}

HandFitResult HandTracker::Search(const SearchStarts& search_starts,
                                  const std::vector<Eigen::Vector3f>& hand_points,
                                  const Frame& frame, const Segmentation* segmentation,
                                  const GraspSide* side) const {
  // The best placed hypotheses fitted briefly (with their scores); the best few fitted on. The
  // fits are independent: on the search's threads, each result in its hypothesis's place.
  const std::vector<SearchHypothesis> hypotheses =
      search_->Best(hand_points, frame, search_starts.articulations, search_starts.tracked,
                    options_.search_candidates, side, right_hand_);
  auto fit_all = [&](const HandFitter& fitter, const std::vector<const HandPose*>& starts) {
    std::vector<std::pair<double, HandFitResult>> fits(starts.size());
    ParallelRuns(starts.size(), options_.search.threads, [&](size_t begin, size_t end) {
      for (size_t k = begin; k < end; ++k) {
        fits[k].second = fitter.Fit(hand_points, &frame, *starts[k], segmentation);
        fits[k].first = Score(fits[k].second, side);
      }
    });
    return fits;
  };
  std::vector<const HandPose*> starts;
  for (const SearchHypothesis& hypothesis : hypotheses) starts.push_back(&hypothesis.pose);
  std::vector<std::pair<double, HandFitResult>> coarse = fit_all(*coarse_fitter_, starts);
  const size_t kept = std::min<size_t>(coarse.size(), options_.search_refined);
  std::partial_sort(coarse.begin(), coarse.begin() + kept, coarse.end(),
                    [](const auto& a, const auto& b) { return a.first < b.first; });
  starts.clear();
  for (size_t k = 0; k < kept; ++k) starts.push_back(&coarse[k].second.pose);
  std::vector<std::pair<double, HandFitResult>> refined = fit_all(*initial_fitter_, starts);
  HandFitResult best;
  double best_score = std::numeric_limits<double>::infinity();
  for (size_t k = 0; k < refined.size(); ++k) {
    if (k == 0 || refined[k].first < best_score) {
      best_score = refined[k].first, best = std::move(refined[k].second);
    }
  }
  return best;
}

void HandTracker::StartSearchBeside(const Frame& frame, const TrackResult& result,
                                    const std::optional<GraspSide>& side, double gain) {
  auto pending = std::make_unique<PendingSearch>();
  pending->gain = gain;
  pending->cam_from_root = result.fit.pose.cam_from_root;
  pending->frame_index = frame.index;
  // Copies: the frame and its segmentation outlive this call only here.
  pending->found = std::async(std::launch::async, [this, starts = StartsOfSearch(), frame = frame,
                                                   segmentation = result.segmentation,
                                                   side = side]() {
    return Search(starts, segmentation.hand_points, frame, &segmentation, side ? &*side : nullptr);
  });
  pending_ = std::move(pending);
}

void HandTracker::WeighSearchBeside(const Frame& frame, TrackResult& result,
                                    const GraspSide* side) {
  const std::unique_ptr<PendingSearch> pending = std::move(pending_);
  HandFitResult found = pending->found.get();
  if (found.data_points == 0) return;  // No hand points: nothing was found.
  TakeMovedOn("the search", found.pose, pending->cam_from_root, pending->frame_index, frame, result,
              side, pending->gain);
}

bool HandTracker::TakeMovedOn(const char* what, const HandPose& found, const Rigid3& then_root,
                              std::int64_t then_frame, const Frame& frame, TrackResult& result,
                              const GraspSide* side, double gain) const {
  // Moved on as the tracked root moved since.
  HandPose start = found;
  start.cam_from_root = result.fit.pose.cam_from_root * then_root.Inverse() * found.cam_from_root;
  HandFitResult fit =
      initial_fitter_->Fit(result.segmentation.hand_points, &frame, start, &result.segmentation);
  spdlog::debug("frame {}: {} begun at frame {} scores {:.2f}, the tracked fit {:.2f}", frame.index,
                what, then_frame, Score(fit, side), Score(result.fit, side));
  if (!(gain * Score(fit, side) < Score(result.fit, side))) return false;
  result.fit = std::move(fit);
  result.status = TrackStatus::kInitialised;
  return true;
}

void HandTracker::FinishSearch() {
  if (pending_) pending_->found.wait();
  if (pending_flip_) pending_flip_->turned.wait();
  if (pending_scale_.valid()) pending_scale_.wait();
}

void HandTracker::StartFlipCheckBeside(const Frame& frame, const TrackResult& result,
                                       const std::optional<GraspSide>& side) {
  auto pending = std::make_unique<PendingFlipCheck>();
  pending->kept_score = Score(result.fit, side ? &*side : nullptr);
  pending->cam_from_root = result.fit.pose.cam_from_root;
  pending->frame_index = frame.index;
  pending->turned = std::async(
      std::launch::async, [this, start = TurnedOver(model_, result.fit.pose), frame = frame,
                           segmentation = result.segmentation, side = side]() {
        HandFitResult turned =
            initial_fitter_->Fit(segmentation.hand_points, &frame, start, &segmentation);
        const double score = Score(turned, side ? &*side : nullptr);
        return std::make_pair(std::move(turned), score);
      });
  pending_flip_ = std::move(pending);
}

void HandTracker::WeighFlipCheckBeside(const Frame& frame, TrackResult& result,
                                       const GraspSide* side) {
  const std::unique_ptr<PendingFlipCheck> pending = std::move(pending_flip_);
  auto [turned, other] = pending->turned.get();
  spdlog::debug("frame {}: on frame {} the fit scored {:.2f}, turned over {:.2f}", frame.index,
                pending->frame_index, pending->kept_score, other);
  result.flip_tie = std::abs(other - pending->kept_score) < options_.flip_tie_score;
  if (!(other < pending->kept_score)) return;
  result.turned_over = TakeMovedOn("the fit turned over", turned.pose, pending->cam_from_root,
                                   pending->frame_index, frame, result, side);
}

bool HandTracker::CheckTurnedOver(const std::vector<Eigen::Vector3f>& hand_points,
                                  const Frame& frame, TrackResult& result,
                                  const GraspSide* side) const {
  HandFitResult turned = initial_fitter_->Fit(
      hand_points, &frame, TurnedOver(model_, result.fit.pose), &result.segmentation);
  const double kept = Score(result.fit, side), other = Score(turned, side);
  spdlog::debug("frame {}: fit scores {:.2f}, turned over {:.2f}", frame.index, kept, other);
  if (other < kept) {
    result.fit = std::move(turned);
    result.status = TrackStatus::kInitialised;
    result.turned_over = true;
  }
  return std::abs(other - kept) < options_.flip_tie_score;
}

bool HandTracker::CheckThumb(const std::vector<Eigen::Vector3f>& hand_points, const Frame& frame,
                             TrackResult& result, const GraspSide* side) const {
  // Only a thumb that does not hold the object against the fingers is tried elsewhere.
  if (side == nullptr ||
      side->Opposition(model_, model_.JointPositions(ForwardKinematics(model_, result.fit.pose))) <=
          options_.grasp_side.max_opposition_cosine) {
    return false;
  }
  // Every variant fitted briefly (on the search's threads), the best of them fitted on.
  const std::vector<HandPose> variants = ThumbVariants(model_, result.fit.pose);
  if (variants.empty()) return false;
  std::vector<HandFitResult> fits(variants.size());
  std::vector<double> scores(variants.size());
  ParallelRuns(variants.size(), options_.search.threads, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      fits[k] = coarse_fitter_->Fit(hand_points, &frame, variants[k], &result.segmentation);
      scores[k] = Score(fits[k], side);
    }
  });
  const size_t best =
      static_cast<size_t>(std::min_element(scores.begin(), scores.end()) - scores.begin());
  HandFitResult refined =
      initial_fitter_->Fit(hand_points, &frame, fits[best].pose, &result.segmentation);
  const double kept = Score(result.fit, side), other = Score(refined, side);
  spdlog::debug("frame {}: fit scores {:.2f}, the thumb elsewhere {:.2f}", frame.index, kept,
                other);
  if (other < kept) {
    result.fit = std::move(refined);
    return true;
  }
  return false;
}

std::vector<SurfaceContact> HandTracker::HeldContacts(const HandPose& predicted,
                                                      const Segmentation& segmentation) const {
  std::vector<SurfaceContact> held;
  if (options_.fit.contact_surface_weight <= 0 || !has_previous_ || previous_vertices_.empty())
    return held;
  // Each fingertip touching in the previous frame, moved as the hand is predicted to move, and
  // the object's surface seen around it.
  const Rigid3 moved = predicted.cam_from_root * pose_.cam_from_root.Inverse();
  const std::vector<int> ends = model_.EndEffectors();
  const ContactOptions& c = options_.contacts;
  for (size_t k = 0; k < ends.size() && k < contacts_->fingertip_vertices().size(); ++k) {
    if (std::find(previous_contact_bones_.begin(), previous_contact_bones_.end(), ends[k]) ==
        previous_contact_bones_.end()) {
      continue;
    }
    const std::vector<int>& tip = contacts_->fingertip_vertices()[k];
    if (tip.empty()) continue;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int v : tip) centre += previous_vertices_[v].cast<double>();
    centre = moved * Eigen::Vector3d(centre / static_cast<double>(tip.size()));
    const std::optional<LocalSurface> surface =
        SurfaceAround(centre.cast<float>(), segmentation.object_points, c.surface_patch_mm,
                      c.surface_min_points, c.surface_max_rms_mm);
    if (surface) held.push_back({tip, contacts_->min_vertices()[k], *surface});
  }
  return held;
}

TrackResult HandTracker::Track(const Frame& frame) {
  const auto started = SteadyClock::now();
  TrackResult result;
  auto finish = [&]() {
    result.milliseconds = MillisecondsSince(started);
    return std::move(result);
  };
  if (std::all_of(frame.depth_mm.begin(), frame.depth_mm.end(),
                  [](std::uint16_t z) { return z == 0; })) {
    result.status = TrackStatus::kEmptyFrame;
    result.reason = "empty depth image";
    has_previous_ = false;
    return finish();
  }
  auto stage = SteadyClock::now();
  result.segmentation = segmenter_.Segment(frame);
  result.segmentation_ms = MillisecondsSince(stage);
  stage = SteadyClock::now();
  const auto& points = result.segmentation.hand_points;
  if (static_cast<int>(points.size()) < options_.min_hand_points) {
    result.status = TrackStatus::kNoHand;
    result.reason = "no hand: " + std::to_string(points.size()) +
                    " skin points in the crop volume (need " +
                    std::to_string(options_.min_hand_points) + ")";
    has_previous_ = false;
    previous_contact_vertices_.clear();
    previous_contact_bones_.clear();
    release_watch_->Reset();
    return finish();
  }

  // The object in the hand, found only when a search or the turned-over check compares poses.
  std::optional<GraspSide> held;
  bool held_found = false;
  auto side = [&]() -> const GraspSide* {
    if (!held_found) held = GraspSide::Of(result.segmentation, options_.grasp_side);
    held_found = true;
    return held ? &*held : nullptr;
  };
  if (!has_pose_) {
    result.fit = Search(StartsOfSearch(), points, frame, &result.segmentation, side());
    result.status = TrackStatus::kInitialised;
    points_at_search_ = points.size();
  } else {
    HandPose predicted = pose_;
    if (has_previous_) {
      predicted.cam_from_root =
          pose_.cam_from_root * previous_pose_.cam_from_root.Inverse() * pose_.cam_from_root;
    }
    result.fit = fitter_->Fit(points, &frame, predicted, &result.segmentation,
                              HeldContacts(predicted, result.segmentation));
    result.status = TrackStatus::kTracked;
    // A search that ran beside the tracking and is done competes with the tracked fit.
    if (pending_ &&
        pending_->found.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      WeighSearchBeside(frame, result, side());
    }
    if (pending_flip_ &&
        pending_flip_->turned.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      WeighFlipCheckBeside(frame, result, side());
    }
  }
  // A run of doubtful fits: search for the hand anew, the tracked fit competing (here, or beside
  // the tracking from the next frames on).
  doubtful_in_a_row_ =
      result.fit.data_coverage < options_.search_data_coverage ? doubtful_in_a_row_ + 1 : 0;
  // Or, touching nothing, the hand shows much more of itself than on any frame searched.
  if (points_at_search_ == 0) points_at_search_ = points.size();
  const bool grown = options_.search_when_points_grow > 0 && previous_contact_bones_.empty() &&
                     static_cast<double>(points.size()) >=
                         options_.search_when_points_grow * static_cast<double>(points_at_search_);
  const bool doubted = doubtful_in_a_row_ >= options_.doubtful_frames_to_search;
  if (result.status == TrackStatus::kTracked && (doubted || grown)) {
    doubtful_in_a_row_ = 0;
    points_at_search_ = std::max(points_at_search_, points.size());
    // A doubtful fit gives way to any better pose, a trusted one only to a much better one.
    const double gain = doubted ? 1.0 : options_.search_growth_gain;
    if (options_.search_beside) {
      side();  // Finds the held object (`held`) once.
      if (!pending_) StartSearchBeside(frame, result, held, gain);
    } else {
      HandFitResult found = Search(StartsOfSearch(), points, frame, &result.segmentation, side());
      spdlog::debug("frame {}: the search scores {:.2f}, the tracked fit {:.2f}", frame.index,
                    Score(found, side()), Score(result.fit, side()));
      if (gain * Score(found, side()) < Score(result.fit, side())) {
        result.fit = std::move(found);
        result.status = TrackStatus::kInitialised;
      }
    }
  }
  // Palm for back: the fit turned over, now and then, and always on a fit found from scratch.
  bool& tie = result.flip_tie;
  // The thumb check moved the thumb alone: the rest of the hand is the previous one moved.
  bool& thumb_moved = result.thumb_moved;
  if (options_.flip_check_frames > 0 && result.fit.data_coverage >= options_.min_data_coverage &&
      (result.status == TrackStatus::kInitialised ||
       ++frames_since_flip_check_ >= options_.flip_check_frames)) {
    frames_since_flip_check_ = 0;
    if (options_.search_beside && result.status == TrackStatus::kTracked) {
      side();  // Finds the held object (`held`) once.
      if (!pending_flip_) StartFlipCheckBeside(frame, result, held);
    } else {
      tie = CheckTurnedOver(points, frame, result, side());
    }
    thumb_moved = options_.thumb_check && CheckThumb(points, frame, result, side());
  }
  if (result.fit.data_coverage >= options_.search_data_coverage && !tie) {
    confident_pose_ = result.fit.pose;
    has_confident_pose_ = true;
  }
  result.doubtful = result.fit.data_coverage < options_.search_data_coverage || tie;
  if (result.fit.data_coverage < options_.min_data_coverage) {
    result.status = TrackStatus::kDiverged;
    result.doubtful = false;  // Not doubtful: diverged.
    result.reason = "fit explains " +
                    std::to_string(static_cast<int>(100 * result.fit.data_coverage)) +
                    " % of the hand points";
  }

  previous_pose_ = pose_;
  has_previous_ = has_pose_ && result.status == TrackStatus::kTracked;
  pose_ = result.fit.pose;
  has_pose_ = true;
  if (estimating_scale() && result.HasPose()) {
    if (options_.search_beside) {
      EstimateScaleBeside(result.segmentation, frame);
    } else {
      EstimateScale(result.segmentation, frame);
    }
  }
  result.fit_ms = MillisecondsSince(stage);
  stage = SteadyClock::now();
  result.hand_scale = scale_;
  result.pose = pose_;
  const std::vector<Rigid3> cam_from_bone = ForwardKinematics(model_, pose_);
  result.joints_mm = model_.JointPositions(cam_from_bone);

  // Contacts with the object's points, and those held since the previous frame.
  auto posed = std::make_shared<const TriangleMesh>(model_.Pose(cam_from_bone));
  const std::vector<Eigen::Vector3f>& vertices = posed->vertices;
  if (result.HasPose()) result.posed_mesh = posed;
  if (!result.segmentation.object_points.empty() && result.HasPose()) {
    // Only object points near the fingertips can touch them: those in the box around the
    // distal phalanges' bones, grown by a finger's radius and the largest contact threshold.
    Eigen::Vector3f low = Eigen::Vector3f::Constant(1e9f), high = -low;
    for (int end : model_.EndEffectors()) {
      for (int joint : {end + 1, model_.bones[end].parent + 1}) {
        const Eigen::Vector3f p = result.joints_mm[joint].cast<float>();
        low = low.cwiseMin(p), high = high.cwiseMax(p);
      }
    }
    const float margin = 20.0f + static_cast<float>(options_.contacts.max_mm);
    low.array() -= margin, high.array() += margin;
    std::vector<Eigen::Vector3f> near;
    for (const Eigen::Vector3f& p : result.segmentation.object_points) {
      if ((p.array() >= low.array()).all() && (p.array() <= high.array()).all()) near.push_back(p);
    }
    const PointKdTree object(std::move(near));
    // The previous frame's contact fingertips rising off together let go of the object.
    std::vector<double> distances = contacts_->TipDistances(vertices, object);
    std::vector<size_t> grasp;
    const std::vector<int> ends = model_.EndEffectors();
    for (size_t k = 0; k < ends.size(); ++k) {
      if (std::count(previous_contact_bones_.begin(), previous_contact_bones_.end(), ends[k]))
        grasp.push_back(k);
    }
    result.grasp_let_go = release_watch_->Observe(distances, grasp);
    if (result.grasp_let_go) grasp_hold_->Release();
    const std::vector<double> limits = release_watch_->Limits();
    const Contacts detected = contacts_->Select(std::move(distances), &limits);
    result.contacts = grasp_hold_->Update(detected, vertices, pose_.cam_from_root, object);
    // A pose found anew (a search) is not the previous one moved: no pairs across it; nor
    // across a thumb the thumb check moved.
    if (!previous_vertices_.empty() && result.status == TrackStatus::kTracked) {
      for (int v : result.contacts.vertices) {
        if (thumb_moved && std::binary_search(thumb_vertices_.begin(), thumb_vertices_.end(), v))
          continue;
        if (std::binary_search(previous_contact_vertices_.begin(), previous_contact_vertices_.end(),
                               v)) {
          result.contact_pairs.push_back(
              {v, previous_vertices_[v].cast<double>(), vertices[v].cast<double>()});
        }
      }
    }
  }
  if (result.contacts.bones.empty() || result.status != TrackStatus::kTracked) {
    grasp_hold_->Release();
  }
  if (!result.HasPose()) release_watch_->Reset();
  result.contacts_ms = MillisecondsSince(stage);
  previous_vertices_ = vertices;
  previous_contact_vertices_ = result.contacts.vertices;
  previous_contact_bones_ = result.contacts.bones;
  std::sort(previous_contact_vertices_.begin(), previous_contact_vertices_.end());
  return finish();
}

}  // namespace ihs::tracker
