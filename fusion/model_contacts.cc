#include "fusion/model_contacts.h"

#include "core/check.h"

namespace ihs::fusion {

void ModelContactOptions::Check() const {
  IHS_CHECK_ARG(distance_mm > 0, "fusion.model_contacts.distance_mm must be positive");
  IHS_CHECK_ARG(min_vertex_share >= 0 && min_vertex_share < 1,
                "fusion.model_contacts.min_vertex_share must be in [0, 1)");
  IHS_CHECK_ARG(min_fingertips >= 1 && min_fingertips <= 5,
                "fusion.model_contacts.min_fingertips must be in [1, 5]");
}

std::vector<ModelContact> FindModelContacts(const TsdfVolume& model,
                                            const Rigid3& object_from_previous_cam,
                                            const std::vector<Eigen::Vector3f>& previous_vertices,
                                            const std::vector<Eigen::Vector3f>& current_vertices,
                                            const std::vector<std::vector<int>>& fingertips,
                                            const ModelContactOptions& options) {
  options.Check();
  std::vector<ModelContact> contacts;
  if (!options.enabled || previous_vertices.size() != current_vertices.size()) return contacts;
  const Eigen::Matrix3f rotation = object_from_previous_cam.rotation().cast<float>();
  const Eigen::Vector3f translation = object_from_previous_cam.translation().cast<float>();
  const float limit = static_cast<float>(options.distance_mm);
  int touching = 0;
  for (const std::vector<int>& fingertip : fingertips) {
    int on_surface = 0;
    for (int v : fingertip) {
      if (v < 0 || static_cast<size_t>(v) >= previous_vertices.size()) continue;
      float distance = 0;
      if (model.SignedDistance(rotation * previous_vertices[v] + translation, &distance) &&
          distance <= limit) {
        ++on_surface;
      }
    }
    if (fingertip.empty() || on_surface <= options.min_vertex_share * fingertip.size()) continue;
    ++touching;
    for (int v : fingertip) {
      if (v < 0 || static_cast<size_t>(v) >= previous_vertices.size()) continue;
      contacts.push_back(
          {v, previous_vertices[v].cast<double>(), current_vertices[v].cast<double>()});
    }
  }
  if (touching < options.min_fingertips) contacts.clear();
  return contacts;
}

}  // namespace ihs::fusion
