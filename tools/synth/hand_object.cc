#include "tools/synth/hand_object.h"

#include <algorithm>
#include <limits>

namespace ihs::synth {

int HandObjectContact::TouchingCount() const {
  return static_cast<int>(std::count_if(fingertips.begin(), fingertips.end(),
                                        [](const FingertipContact& f) { return f.touching; }));
}

HandObjectGeometry::HandObjectGeometry(const tracker::HandModel& hand)
    : fingertip_bones_(hand.EndEffectors()), fingertip_vertices_(fingertip_bones_.size()) {
  for (size_t v = 0; v < hand.weights.size(); ++v) {
    int best_bone = -1;
    float best_weight = 0;
    for (const auto& [bone, weight] : hand.weights[v].bones) {
      if (weight > best_weight) best_bone = bone, best_weight = weight;
    }
    const auto it = std::find(fingertip_bones_.begin(), fingertip_bones_.end(), best_bone);
    if (it != fingertip_bones_.end()) {
      fingertip_vertices_[it - fingertip_bones_.begin()].push_back(static_cast<int>(v));
    }
  }
}

double SignedDistanceInCamera(const ObjectShape& object, const Rigid3& object_from_cam,
                              const Eigen::Vector3d& point_in_cam, double far_mm) {
  const Eigen::Vector3d p = object_from_cam * point_in_cam;
  // Distance to the bounding cylinder bounds the distance to the surface from below.
  const double radial = p.head<2>().norm() - object.max_radius_mm();
  const double axial = std::max(-p.z(), p.z() - object.height_mm());
  const double bound = std::max(radial, axial);
  if (bound > far_mm) return bound;
  return object.SignedDistance(p);
}

HandObjectContact HandObjectGeometry::Measure(const TriangleMesh& posed_hand,
                                              const ObjectShape& object,
                                              const Rigid3& cam_from_object,
                                              double touch_mm) const {
  const Rigid3 object_from_cam = cam_from_object.Inverse();
  HandObjectContact contact;
  const double far = std::max(touch_mm, 0.0) + 20.0;
  for (const auto& v : posed_hand.vertices) {
    const double d = SignedDistanceInCamera(object, object_from_cam, v.cast<double>(), 0.0);
    contact.max_penetration_mm = std::max(contact.max_penetration_mm, -d);
  }
  for (const auto& vertices : fingertip_vertices_) {
    FingertipContact tip;
    tip.distance_mm = std::numeric_limits<double>::infinity();
    for (int v : vertices) {
      tip.distance_mm = std::min(
          tip.distance_mm, SignedDistanceInCamera(object, object_from_cam,
                                                  posed_hand.vertices[v].cast<double>(), far));
    }
    tip.touching = tip.distance_mm <= touch_mm;
    contact.fingertips.push_back(tip);
  }
  return contact;
}

}  // namespace ihs::synth
