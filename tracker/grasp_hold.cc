#include "tracker/grasp_hold.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/point_kd_tree.h"

namespace ihs::tracker {

void GraspHoldOptions::Check() const {
  IHS_CHECK_ARG(max_shape_change_mm > 0 && max_shape_change_mm <= 100,
                "tracker.grasp_hold.max_shape_change_mm must be in (0, 100]");
  IHS_CHECK_ARG(max_reach_mm > 0 && max_reach_mm <= 200,
                "tracker.grasp_hold.max_reach_mm must be in (0, 200]");
  IHS_CHECK_ARG(max_frames >= 1 && max_frames <= 10000,
                "tracker.grasp_hold.max_frames must be in [1, 10000]");
}

GraspHold::GraspHold(GraspHoldOptions options, int min_bones, std::vector<int> end_effectors,
                     std::vector<std::vector<int>> fingertip_vertices)
    : options_((options.Check(), options)),
      min_bones_(min_bones),
      end_effectors_(std::move(end_effectors)),
      fingertip_vertices_(std::move(fingertip_vertices)) {
  IHS_CHECK_ARG(end_effectors_.size() == fingertip_vertices_.size(),
                "one fingertip vertex set per end-effector");
}

Eigen::Vector3d GraspHold::TipCentre(size_t index,
                                     const std::vector<Eigen::Vector3f>& vertices) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v : fingertip_vertices_[index]) sum += vertices[v].cast<double>();
  return sum / std::max<size_t>(1, fingertip_vertices_[index].size());
}

void GraspHold::Release() {
  held_.clear();
  root_tips_.clear();
  frames_held_ = 0;
}

Contacts GraspHold::Update(const Contacts& detected, const std::vector<Eigen::Vector3f>& vertices,
                           const Rigid3& cam_from_root, const PointKdTree& object_points) {
  if (!options_.enabled) return detected;
  const Rigid3 root_from_cam = cam_from_root.Inverse();
  if (static_cast<int>(detected.bones.size()) >= min_bones_) {
    Release();
    for (size_t e = 0; e < end_effectors_.size(); ++e) {
      if (std::count(detected.bones.begin(), detected.bones.end(), end_effectors_[e]) == 0) {
        continue;
      }
      held_.push_back(e);
      root_tips_.push_back(root_from_cam * TipCentre(e, vertices));
    }
    grasp_ = detected;
    return detected;
  }
  if (held_.empty() || frames_held_ >= options_.max_frames ||
      !Holds(vertices, root_from_cam, object_points)) {
    Release();
    return detected;
  }
  ++frames_held_;
  Contacts held = grasp_;
  held.held_frames = frames_held_;
  return held;
}

bool GraspHold::Holds(const std::vector<Eigen::Vector3f>& vertices, const Rigid3& root_from_cam,
                      const PointKdTree& object_points) const {
  for (size_t i = 0; i < held_.size(); ++i) {
    const Eigen::Vector3d tip = TipCentre(held_[i], vertices);
    if ((root_from_cam * tip - root_tips_[i]).norm() > options_.max_shape_change_mm) return false;
    float distance_sq = 0;
    if (object_points.Nearest(tip.cast<float>(), &distance_sq) < 0 ||
        std::sqrt(distance_sq) > options_.max_reach_mm) {
      return false;
    }
  }
  return true;
}

}  // namespace ihs::tracker
