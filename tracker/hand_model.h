#pragma once
// A skinned hand model: a skeleton of 20 bones (forearm/palm root; five fingers), a rest-pose
// mesh, linear-blend skinning weights and joint limits. Posing takes each bone's transform
// `cam_from_bone`; the rest pose gives `model_from_bone` (model = the rest mesh's frame).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace ihs::tracker {

/// One bone. Its local +x axis runs along the bone; its end point is bone_from_end = (length, 0,
/// 0).
struct Bone {
  std::string name;
  /// Index of the parent bone, −1 for the root. Parents come before their children.
  int parent = -1;
  /// Length along the bone's x axis, mm.
  double length_mm = 0;
};

/// The rotational degrees of freedom of one joint (the bone's rotation relative to its parent).
struct JointLimits {
  /// Whether the bone may translate freely (the root only).
  bool translation = false;
  /// Which of the three rotation axes are active.
  std::array<bool, 3> active = {false, false, false};
  /// Rotation axes in the bone's rest frame (unit): ≈ twist (x), flexion (y), spread (z).
  std::array<Eigen::Vector3d, 3> axes = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                         Eigen::Vector3d::UnitZ()};
  /// Angle limits per axis, degrees (min, max). Treat as soft: recorded motion exceeds them.
  std::array<std::pair<double, double>, 3> limits_deg = {};
};

/// Skinning weights of one vertex: bone indices and weights summing to 1.
struct VertexWeights {
  std::vector<std::pair<int, float>> bones;
};

/// A skinned hand model. All lengths in mm.
struct HandModel {
  std::vector<Bone> bones;
  /// Rest transform of each bone: bone frame → model (rest mesh) frame.
  std::vector<Rigid3> model_from_bone_rest;
  /// Joint limits per bone.
  std::vector<JointLimits> limits;
  /// The mesh in the rest pose, model frame, outward faces.
  TriangleMesh rest_mesh;
  /// Skinning weights per rest-mesh vertex.
  std::vector<VertexWeights> weights;

  /// Index of the bone named `name`, or −1.
  int BoneIndex(const std::string& name) const;
  /// Indices of the end-effector bones (bones without children: the fingertip segments).
  std::vector<int> EndEffectors() const;
  /// The finger a bone belongs to, by the data's naming "RFing.<f>_…": 0 pinky, 1 ring,
  /// 2 middle, 3 index, 4 thumb; −1 for other bones (the root).
  int FingerOf(int bone) const;
  /// Throws ihs::InputError describing the first inconsistency (sizes, parent order, weights).
  void Check() const;

  /// The model scaled uniformly about the model frame's origin: bone lengths, rest placements and
  /// the mesh (a user's hand of other size than the template's). Limits and weights are kept.
  HandModel Scaled(double scale) const;

  /// The mesh posed by linear blend skinning: each vertex moves by Σ_j w_j·(cam_from_bone_j ·
  /// model_from_bone_rest_j⁻¹). `cam_from_bone` has one transform per bone. Normals recomputed.
  TriangleMesh Pose(const std::vector<Rigid3>& cam_from_bone) const;

  /// 21 joint positions in the camera frame: the root bone's start, then every bone's end point
  /// in skeleton order (the layout of hand_joints.csv).
  std::vector<Eigen::Vector3d> JointPositions(const std::vector<Rigid3>& cam_from_bone) const;
};

}  // namespace ihs::tracker
