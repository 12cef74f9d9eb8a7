#include "tracker/contacts.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/point_kd_tree.h"
#include "tracker/local_surface.h"

namespace ihs::tracker {

void ContactOptions::Check() const {
  IHS_CHECK_ARG(start_mm > 0 && step_mm > 0 && max_mm >= start_mm && max_mm <= 100,
                "contacts: start_mm and step_mm must be positive and start_mm <= max_mm <= 100");
  // Detect counts once per threshold: the thresholds between start_mm and max_mm are bounded.
  IHS_CHECK_ARG((max_mm - start_mm) / step_mm <= 1000,
                "contacts.step_mm must be at least (max_mm - start_mm) / 1000");
  IHS_CHECK_ARG(min_vertices >= 1 && reference_fingertip_vertices >= 1,
                "contacts.min_vertices and reference_fingertip_vertices must be >= 1");
  IHS_CHECK_ARG(min_bones >= 1 && min_bones <= 5, "contacts.min_bones must be in [1, 5]");
  IHS_CHECK_ARG(
      surface_mm >= 0 && surface_patch_mm > 0 && surface_min_points >= 4 && surface_max_rms_mm > 0,
      "contacts: surface_mm must be >= 0, surface_patch_mm and surface_max_rms_mm > 0, "
      "surface_min_points >= 4");
}

ContactDetector::ContactDetector(const HandModel& model, ContactOptions options)
    : options_(std::move(options)), end_effectors_(model.EndEffectors()) {
  options_.Check();
  fingertip_vertices_.resize(end_effectors_.size());
  for (size_t v = 0; v < model.weights.size(); ++v) {
    int best = -1;
    float best_weight = -1;
    for (const auto& [bone, weight] : model.weights[v].bones) {
      if (weight > best_weight) best = bone, best_weight = weight;
    }
    const auto it = std::find(end_effectors_.begin(), end_effectors_.end(), best);
    if (it != end_effectors_.end()) {
      fingertip_vertices_[it - end_effectors_.begin()].push_back(static_cast<int>(v));
    }
  }
  for (const auto& vertices : fingertip_vertices_) {
    min_vertices_.push_back(std::max(
        1, static_cast<int>(std::lround(static_cast<double>(options_.min_vertices) *
                                        vertices.size() / options_.reference_fingertip_vertices))));
  }
}

std::vector<float> ContactDetector::SurfaceDistances(
    size_t e, const std::vector<Eigen::Vector3f>& posed_vertices,
    const std::vector<Eigen::Vector3f>& object_points) const {
  const std::vector<int>& tip = fingertip_vertices_[e];
  std::vector<float> distances(tip.size(), 1e9f);
  if (tip.empty()) return distances;
  Eigen::Vector3f centre = Eigen::Vector3f::Zero();
  for (int v : tip) centre += posed_vertices[v];
  centre /= static_cast<float>(tip.size());
  // Points that no sphere or plane explains (an edge, two surfaces) are not continued (with
  // surface_trim, by the surface nearest the fingertip).
  const std::optional<LocalSurface> surface =
      SurfaceAround(centre, object_points, options_.surface_patch_mm, options_.surface_min_points,
                    options_.surface_max_rms_mm, options_.surface_trim);
  if (!surface) return distances;
  for (size_t i = 0; i < tip.size(); ++i) {
    distances[i] = static_cast<float>(surface->Distance(posed_vertices[tip[i]].cast<double>()));
  }
  return distances;
}

std::vector<double> ContactDetector::TipDistances(
    const std::vector<Eigen::Vector3f>& posed_vertices, const PointKdTree& object_points) const {
  // Distance of every fingertip vertex to the object, once.
  std::vector<std::vector<float>> distances(end_effectors_.size());
  for (size_t e = 0; e < end_effectors_.size(); ++e) {
    for (int v : fingertip_vertices_[e]) {
      float d2 = 0;
      distances[e].push_back(object_points.Nearest(posed_vertices[v], &d2) >= 0 ? std::sqrt(d2)
                                                                                : 1e9f);
    }
  }
  // Where the surface continued under a fingertip is nearer than the points seen around it, a
  // vertex counts by that distance, up to surface_mm (beyond it the seen points decide).
  if (options_.surface_mm > 0) {
    for (size_t e = 0; e < end_effectors_.size(); ++e) {
      const std::vector<float> surface =
          SurfaceDistances(e, posed_vertices, object_points.points());
      for (size_t i = 0; i < surface.size(); ++i) {
        if (surface[i] <= options_.surface_mm)
          distances[e][i] = std::min(distances[e][i], surface[i]);
      }
    }
  }
  // A fingertip is a contact bone at a threshold where more than its min_vertices vertices lie
  // within it: from its (min_vertices + 1)-th nearest vertex's distance on.
  std::vector<double> tip_distance_mm(end_effectors_.size(), kNoContactMm);
  for (size_t e = 0; e < end_effectors_.size(); ++e) {
    std::vector<float>& d = distances[e];
    const size_t k = static_cast<size_t>(min_vertices_[e]);
    if (d.size() <= k) continue;
    std::nth_element(d.begin(), d.begin() + k, d.end());
    tip_distance_mm[e] = std::min<double>(d[k], kNoContactMm);
  }
  return tip_distance_mm;
}

Contacts ContactDetector::Detect(const std::vector<Eigen::Vector3f>& posed_vertices,
                                 const PointKdTree& object_points) const {
  return Select(TipDistances(posed_vertices, object_points));
}

Contacts ContactDetector::Select(std::vector<double> tip_distance_mm,
                                 const std::vector<double>* tip_limits_mm) const {
  IHS_CHECK_ARG(tip_distance_mm.size() == end_effectors_.size() &&
                    (!tip_limits_mm || tip_limits_mm->size() == end_effectors_.size()),
                "contacts: one distance (and limit) per end-effector");
  Contacts contacts;
  contacts.tip_distance_mm = std::move(tip_distance_mm);
  auto bones_within = [&](double threshold) {
    std::vector<int> bones;
    for (size_t e = 0; e < end_effectors_.size(); ++e) {
      const double limit = tip_limits_mm ? (*tip_limits_mm)[e] : kNoContactMm;
      if (contacts.tip_distance_mm[e] <= std::min(threshold, limit))
        bones.push_back(end_effectors_[e]);
    }
    return bones;
  };
  contacts.bones = bones_within(options_.start_mm);
  contacts.threshold_mm = options_.start_mm;
  // The threshold grows only to find the grasp's fingertips together; where it does not, a
  // fingertip counts only at the first threshold (a lone fingertip a few millimetres away is
  // a hovering finger as often as a touching one).
  for (double threshold = options_.start_mm + options_.step_mm;
       static_cast<int>(contacts.bones.size()) < options_.min_bones &&
       threshold <= options_.max_mm + 1e-9;
       threshold += options_.step_mm) {
    std::vector<int> bones = bones_within(threshold);
    if (static_cast<int>(bones.size()) >= options_.min_bones) {
      contacts.bones = std::move(bones);
      contacts.threshold_mm = threshold;
    }
  }
  for (size_t e = 0; e < end_effectors_.size(); ++e) {
    if (std::find(contacts.bones.begin(), contacts.bones.end(), end_effectors_[e]) ==
        contacts.bones.end()) {
      continue;
    }
    contacts.vertices.insert(contacts.vertices.end(), fingertip_vertices_[e].begin(),
                             fingertip_vertices_[e].end());
  }
  return contacts;
}

}  // namespace ihs::tracker
