#include "tracker/hand_tracker.h"

#include <spdlog/spdlog.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <string>

#include "core/check.h"
#include "core/point_kd_tree.h"
#include "core/stopwatch.h"

namespace ihs::tracker {
namespace {

// Principal axes (columns, by decreasing spread) and centroid of points.
void PrincipalAxes(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d* centroid,
                   Eigen::Matrix3d* axes) {
  *centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) *centroid += p;
  *centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& p : points) covariance += (p - *centroid) * (p - *centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigen sorts ascending; reverse to largest first.
  for (int k = 0; k < 3; ++k) axes->col(k) = solver.eigenvectors().col(2 - k);
}

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
  IHS_CHECK_ARG(min_hand_points >= 10, "tracker.min_hand_points must be >= 10");
  IHS_CHECK_ARG(min_data_coverage >= 0 && min_data_coverage <= 1,
                "tracker.min_data_coverage must be in [0, 1]");
  IHS_CHECK_ARG(search_data_coverage >= min_data_coverage && search_data_coverage <= 1,
                "tracker.search_data_coverage must be in [min_data_coverage, 1]");
  IHS_CHECK_ARG(doubtful_frames_to_search >= 1, "tracker.doubtful_frames_to_search must be >= 1");
  IHS_CHECK_ARG(initialisation_iterations >= 1, "tracker.initialisation_iterations must be >= 1");
  IHS_CHECK_ARG(scale_frames >= 0, "tracker.scale_frames must be >= 0");
  IHS_CHECK_ARG(scale_range >= 0 && scale_range < 0.5, "tracker.scale_range must be in [0, 0.5)");
  IHS_CHECK_ARG(scale_step > 0, "tracker.scale_step must be positive");
}

namespace {
// The fit's options with the segmentation's crop volume.
HandFitOptions FitOptions(const TrackerOptions& options) {
  HandFitOptions fit = options.fit;
  fit.crop_min_mm = options.segmentation.crop_min_mm;
  fit.crop_max_mm = options.segmentation.crop_max_mm;
  return fit;
}

HandFitOptions InitialFitOptions(const TrackerOptions& options) {
  HandFitOptions fit = FitOptions(options);
  fit.outer_iterations = options.initialisation_iterations;
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

HandTracker::HandTracker(HandModel model, const CameraIntrinsics& intrinsics,
                         TrackerOptions options)
    : base_model_(std::move(model)),
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
  initial_fitter_ = std::make_unique<HandFitter>(model_, intrinsics_, InitialFitOptions(options_));
  contacts_ = std::make_unique<ContactDetector>(model_, options_.contacts);
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

void HandTracker::EstimateScale(const Segmentation& segmentation, const Frame& frame) {
  for (auto& candidate : scale_candidates_) {
    const HandFitResult fit = candidate->fitter->Fit(
        segmentation.hand_points, &frame, Rescaled(pose_, scale_, candidate->scale), &segmentation);
    // How far the hand points are from the model, and the model's visible points from them.
    candidate->score += fit.data_error_mm + fit.model_error_mm;
  }
  if (++scale_frames_done_ < options_.scale_frames) return;
  size_t best = 0;
  for (size_t k = 1; k < scale_candidates_.size(); ++k) {
    if (scale_candidates_[k]->score < scale_candidates_[best]->score) best = k;
  }
  double scale = scale_candidates_[best]->scale;
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

std::vector<HandPose> HandTracker::CloudHypotheses(const std::vector<Eigen::Vector3f>& hand_points,
                                                   const HandPose& articulation,
                                                   bool also_unturned) const {
  // The posed model's principal axes onto the hand cloud's, each way round: the articulation
  // kept, the whole hand turned and moved onto the cloud.
  std::vector<Eigen::Vector3d> data, model;
  for (const auto& p : hand_points) data.push_back(p.cast<double>());
  for (const auto& v : model_.Pose(ForwardKinematics(model_, articulation)).vertices)
    model.push_back(v.cast<double>());
  Eigen::Vector3d data_centre, model_centre;
  Eigen::Matrix3d data_axes, model_axes;
  PrincipalAxes(data, &data_centre, &data_axes);
  PrincipalAxes(model, &model_centre, &model_axes);
  if (model_axes.determinant() < 0) model_axes.col(2) *= -1;
  // The cloud is the visible surface: the hand's middle lies a little farther along the ray.
  const Eigen::Vector3d centre = data_centre + 8.0 * data_centre.normalized();
  std::vector<HandPose> hypotheses;
  for (int s1 : {1, -1}) {
    for (int s2 : {1, -1}) {
      Eigen::Matrix3d axes;
      axes.col(0) = s1 * data_axes.col(0);
      axes.col(1) = s2 * data_axes.col(1);
      axes.col(2) = axes.col(0).cross(axes.col(1));
      const Eigen::Matrix3d rotation = axes * model_axes.transpose();
      HandPose pose = articulation;
      pose.cam_from_root = Rigid3(rotation, centre - rotation * model_centre) * pose.cam_from_root;
      hypotheses.push_back(std::move(pose));
    }
  }
  if (also_unturned) {
    // Only moved onto the cloud: a hand that moved fast but did not turn much.
    HandPose moved = articulation;
    moved.cam_from_root =
        Rigid3(Eigen::Matrix3d::Identity(), centre - model_centre) * moved.cam_from_root;
    hypotheses.push_back(std::move(moved));
  }
  return hypotheses;
}

HandFitResult HandTracker::Search(const std::vector<Eigen::Vector3f>& hand_points,
                                  const Frame& frame) const {
  std::vector<HandPose> hypotheses =
      CloudHypotheses(hand_points, HandPose::Rest(model_), /*also_unturned=*/false);
  if (has_confident_pose_) {
    for (HandPose& pose : CloudHypotheses(hand_points, confident_pose_, /*also_unturned=*/true))
      hypotheses.push_back(std::move(pose));
  }
  // The articulation the tracker holds now, if it is another (one given to Initialise: a
  // grasping hand is far from the rest pose's open one, and from the rest articulation alone a
  // search after a jump mid-grasp settled 122 mm off with 88 % of the points explained).
  if (has_pose_ && (!has_confident_pose_ || pose_.angles_rad != confident_pose_.angles_rad)) {
    for (HandPose& pose : CloudHypotheses(hand_points, pose_, /*also_unturned=*/true))
      hypotheses.push_back(std::move(pose));
  }
  HandFitResult best = initial_fitter_->Fit(hand_points, &frame, hypotheses.front());
  for (size_t k = 1; k < hypotheses.size(); ++k) {
    HandFitResult fit = initial_fitter_->Fit(hand_points, &frame, hypotheses[k]);
    if (FitScore(fit) < FitScore(best)) best = std::move(fit);
  }
  return best;
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
    return finish();
  }

  if (!has_pose_) {
    result.fit = Search(points, frame);
    result.status = TrackStatus::kInitialised;
  } else {
    HandPose predicted = pose_;
    if (has_previous_) {
      predicted.cam_from_root =
          pose_.cam_from_root * previous_pose_.cam_from_root.Inverse() * pose_.cam_from_root;
    }
    result.fit = fitter_->Fit(points, &frame, predicted, &result.segmentation);
    result.status = TrackStatus::kTracked;
  }
  // A run of doubtful fits: search for the hand anew, the tracked fit competing.
  doubtful_in_a_row_ =
      result.fit.data_coverage < options_.search_data_coverage ? doubtful_in_a_row_ + 1 : 0;
  if (result.status == TrackStatus::kTracked &&
      doubtful_in_a_row_ >= options_.doubtful_frames_to_search) {
    doubtful_in_a_row_ = 0;
    HandFitResult found = Search(points, frame);
    if (FitScore(found) < FitScore(result.fit)) {
      result.fit = std::move(found);
      result.status = TrackStatus::kInitialised;
    }
  }
  if (result.fit.data_coverage >= options_.search_data_coverage) {
    confident_pose_ = result.fit.pose;
    has_confident_pose_ = true;
  }
  if (result.fit.data_coverage < options_.min_data_coverage) {
    result.status = TrackStatus::kDiverged;
    result.reason = "fit explains " +
                    std::to_string(static_cast<int>(100 * result.fit.data_coverage)) +
                    " % of the hand points";
  }

  previous_pose_ = pose_;
  has_previous_ = has_pose_ && result.status == TrackStatus::kTracked;
  pose_ = result.fit.pose;
  has_pose_ = true;
  if (estimating_scale() && result.HasPose()) EstimateScale(result.segmentation, frame);
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
    result.contacts = contacts_->Detect(vertices, object);
    if (!previous_vertices_.empty()) {
      for (int v : result.contacts.vertices) {
        if (std::binary_search(previous_contact_vertices_.begin(), previous_contact_vertices_.end(),
                               v)) {
          result.contact_pairs.push_back(
              {v, previous_vertices_[v].cast<double>(), vertices[v].cast<double>()});
        }
      }
    }
  }
  result.contacts_ms = MillisecondsSince(stage);
  previous_vertices_ = vertices;
  previous_contact_vertices_ = result.contacts.vertices;
  std::sort(previous_contact_vertices_.begin(), previous_contact_vertices_.end());
  return finish();
}

}  // namespace ihs::tracker
