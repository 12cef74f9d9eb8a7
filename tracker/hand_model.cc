#include "tracker/hand_model.h"

#include <cmath>
#include <stdexcept>

#include "core/errors.h"

namespace ihs::tracker {

int HandModel::BoneIndex(const std::string& name) const {
  for (size_t i = 0; i < bones.size(); ++i) {
    if (bones[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<int> HandModel::EndEffectors() const {
  std::vector<bool> has_child(bones.size(), false);
  for (const Bone& bone : bones) {
    if (bone.parent >= 0) has_child[bone.parent] = true;
  }
  std::vector<int> ends;
  for (size_t i = 0; i < bones.size(); ++i) {
    if (!has_child[i]) ends.push_back(static_cast<int>(i));
  }
  return ends;
}

int HandModel::FingerOf(int bone) const {
  const std::string& name = bones.at(bone).name;
  if (name.rfind("RFing.", 0) != 0 || name.size() < 7 || name[6] < '0' || name[6] > '4') return -1;
  return name[6] - '0';
}

HandModel HandModel::Scaled(double scale) const {
  if (!(scale > 0)) throw std::invalid_argument("hand model scale must be positive");
  HandModel scaled = *this;
  for (Bone& bone : scaled.bones) bone.length_mm *= scale;
  for (Rigid3& rest : scaled.model_from_bone_rest)
    rest = Rigid3(rest.rotation(), scale * rest.translation());
  for (Eigen::Vector3f& vertex : scaled.rest_mesh.vertices) vertex *= static_cast<float>(scale);
  return scaled;
}

void HandModel::Check() const {
  const size_t n = bones.size();
  if (n == 0) throw InputError("hand model has no bones");
  if (model_from_bone_rest.size() != n || limits.size() != n) {
    throw InputError("hand model: rest transforms or limits do not match the " + std::to_string(n) +
                     " bones");
  }
  for (size_t i = 0; i < n; ++i) {
    if (bones[i].parent >= static_cast<int>(i) || (i > 0 && bones[i].parent < 0) ||
        (i == 0 && bones[i].parent != -1)) {
      throw InputError("hand model: bone " + bones[i].name + " is not after its parent");
    }
  }
  rest_mesh.Check();
  if (weights.size() != rest_mesh.vertices.size()) {
    throw InputError("hand model: " + std::to_string(weights.size()) + " weight rows for " +
                     std::to_string(rest_mesh.vertices.size()) + " vertices");
  }
  for (size_t v = 0; v < weights.size(); ++v) {
    double sum = 0;
    for (const auto& [bone, weight] : weights[v].bones) {
      if (bone < 0 || bone >= static_cast<int>(n) || !(weight >= 0)) {
        throw InputError("hand model: vertex " + std::to_string(v) + " has an invalid weight");
      }
      sum += weight;
    }
    if (std::abs(sum - 1.0) > 1e-3) {
      throw InputError("hand model: weights of vertex " + std::to_string(v) + " sum to " +
                       std::to_string(sum));
    }
  }
}

TriangleMesh HandModel::Pose(const std::vector<Rigid3>& cam_from_bone) const {
  std::vector<Eigen::Matrix<double, 3, 4>> skinning(bones.size());
  for (size_t j = 0; j < bones.size(); ++j) {
    skinning[j] = (cam_from_bone[j] * model_from_bone_rest[j].Inverse()).ToMatrix().topRows<3>();
  }
  TriangleMesh posed;
  posed.faces = rest_mesh.faces;
  posed.colors = rest_mesh.colors;
  posed.vertices.resize(rest_mesh.vertices.size());
  for (size_t v = 0; v < rest_mesh.vertices.size(); ++v) {
    Eigen::Matrix<double, 3, 4> blended = Eigen::Matrix<double, 3, 4>::Zero();
    for (const auto& [bone, weight] : weights[v].bones) blended += weight * skinning[bone];
    posed.vertices[v] =
        (blended * rest_mesh.vertices[v].cast<double>().homogeneous()).cast<float>();
  }
  posed.ComputeVertexNormals();
  return posed;
}

std::vector<Eigen::Vector3d> HandModel::JointPositions(
    const std::vector<Rigid3>& cam_from_bone) const {
  std::vector<Eigen::Vector3d> joints;
  joints.reserve(bones.size() + 1);
  joints.push_back(cam_from_bone[0].translation());
  for (size_t j = 0; j < bones.size(); ++j) {
    joints.push_back(cam_from_bone[j] * Eigen::Vector3d(bones[j].length_mm, 0, 0));
  }
  return joints;
}

}  // namespace ihs::tracker
