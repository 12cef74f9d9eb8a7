#include "tracker/grasp_side.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "tracker/hand_pose.h"

namespace ihs::tracker {

void GraspSideOptions::Check() const {
  IHS_CHECK_ARG(weight >= 0, "tracker.grasp_side.weight must be >= 0");
  IHS_CHECK_ARG(min_cosine >= -1 && min_cosine <= 1,
                "tracker.grasp_side.min_cosine must be in [-1, 1]");
  IHS_CHECK_ARG(near_hand_mm > 0, "tracker.grasp_side.near_hand_mm must be positive");
  IHS_CHECK_ARG(min_object_points >= 1, "tracker.grasp_side.min_object_points must be >= 1");
  IHS_CHECK_ARG(opposition_weight >= 0, "tracker.grasp_side.opposition_weight must be >= 0");
  IHS_CHECK_ARG(max_opposition_cosine >= -1 && max_opposition_cosine <= 1,
                "tracker.grasp_side.max_opposition_cosine must be in [-1, 1]");
}

std::optional<GraspSide> GraspSide::Of(const Segmentation& segmentation,
                                       const GraspSideOptions& options) {
  if (options.weight <= 0 || segmentation.hand_points.empty()) return std::nullopt;
  Eigen::Vector3d hand = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& p : segmentation.hand_points) hand += p.cast<double>();
  hand /= static_cast<double>(segmentation.hand_points.size());
  const double near_sq = options.near_hand_mm * options.near_hand_mm;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  int count = 0;
  for (const Eigen::Vector3f& q : segmentation.object_points) {
    const Eigen::Vector3d p = q.cast<double>();
    if ((p - hand).squaredNorm() > near_sq) continue;
    sum += p;
    second += p * p.transpose();
    ++count;
  }
  if (count < options.min_object_points) return std::nullopt;
  const Eigen::Vector3d centroid = sum / count;
  const Eigen::Matrix3d covariance = second / count - centroid * centroid.transpose();
  // The spread across the ray: the covariance's trace less its part along the ray.
  const Eigen::Vector3d ray = centroid.normalized();
  const double across = std::max(0.0, covariance.trace() - ray.dot(covariance * ray));
  return GraspSide(centroid + 0.7 * std::sqrt(across) * ray, options);
}

double GraspSide::Cosine(const PalmAxes& palm, bool right_hand) const {
  const Eigen::Vector3d normal = (right_hand ? 1.0 : -1.0) * palm.Normal();
  const Eigen::Vector3d to_object = centre_ - palm.centre;
  const double length = normal.norm() * to_object.norm();
  return length > 0 ? normal.dot(to_object) / length : 1.0;
}

double GraspSide::Penalty(const PalmAxes& palm, bool right_hand) const {
  return options_.weight * std::max(0.0, options_.min_cosine - Cosine(palm, right_hand));
}

double GraspSide::Opposition(const HandModel& model,
                             const std::vector<Eigen::Vector3d>& joints) const {
  Eigen::Vector3d thumb = Eigen::Vector3d::Zero(), fingers = Eigen::Vector3d::Zero();
  int thumbs = 0, tips = 0;
  for (int end : model.EndEffectors()) {
    const Eigen::Vector3d tip = joints[static_cast<size_t>(end) + 1] - centre_;
    if (model.FingerOf(end) == 4) {
      thumb += tip, ++thumbs;
    } else {
      fingers += tip, ++tips;
    }
  }
  const double length = thumb.norm() * fingers.norm();
  return thumbs > 0 && tips > 0 && length > 0 ? thumb.dot(fingers) / length : 1.0;
}

double GraspSide::Penalty(const HandModel& model, const HandPose& pose, bool right_hand) const {
  const std::vector<Eigen::Vector3d> joints = model.JointPositions(ForwardKinematics(model, pose));
  return Penalty(PalmAxesOf(model, joints), right_hand) +
         options_.opposition_weight *
             std::max(0.0, Opposition(model, joints) - options_.max_opposition_cosine);
}

}  // namespace ihs::tracker
