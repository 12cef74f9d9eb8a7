#pragma once
// The pose parameters of a hand model — a rigid root transform plus one angle per active joint
// degree of freedom — and forward kinematics from them to every bone's cam_from_bone.

#include <vector>

#include "core/rigid3.h"
#include "tracker/hand_model.h"

namespace ihs::tracker {

/// One rotational degree of freedom: bone `bone` rotates about its `axis`-th limit axis.
struct DegreeOfFreedom {
  int bone = 0;
  int axis = 0;
};

/// The active joint degrees of freedom of `model` (root excluded), in bone order then axis order
/// (x, y, z): the layout of HandPose::angles_rad.
std::vector<DegreeOfFreedom> JointDegreesOfFreedom(const HandModel& model);

/// A hand pose: the root bone's transform and the joint angles (radians, zero = rest pose).
struct HandPose {
  /// cam_from_bone of the root bone (forearm/palm).
  Rigid3 cam_from_root;
  /// One angle per JointDegreesOfFreedom entry, radians.
  std::vector<double> angles_rad;

  /// The rest pose of `model` placed by `cam_from_model`.
  static HandPose Rest(const HandModel& model, const Rigid3& cam_from_model = Rigid3());
};

/// Forward kinematics: cam_from_bone for every bone. A bone's rotation relative to its rest
/// placement on its parent is R = Rx(θx)·Ry(θy)·Rz(θz) about its (active) limit axes.
std::vector<Rigid3> ForwardKinematics(const HandModel& model, const HandPose& pose);

/// Joint angles that explain given bone transforms: each bone's rotation relative to its rest
/// placement is decomposed onto its active axes in order, taking each axis's twist component
/// (exact for single-axis joints and for rotations about the axes alone; an approximation for
/// general multi-axis rotations, and rotation about inactive axes is dropped). Angles are not
/// clamped to the limits. Used to initialise a fit from recorded motion.
HandPose PoseFromBoneTransforms(const HandModel& model, const std::vector<Rigid3>& cam_from_bone);

/// The palm's axes from joints in HandModel::JointPositions' layout (the bones
/// "RFing.<finger>_Hand" end at the knuckles): `across` from the little finger's knuckle to the
/// index finger's, `along` from the first joint (the root's start) to the middle finger's
/// knuckle, `centre` the mean of the first joint and the four knuckles. Throws
/// std::invalid_argument for a model without those bones or joints of another count.
struct PalmAxes {
  Eigen::Vector3d across, along, centre;
  /// across × along: toward the palm for a right hand, toward its back for a left one.
  Eigen::Vector3d Normal() const { return across.cross(along); }
};
PalmAxes PalmAxesOf(const HandModel& model, const std::vector<Eigen::Vector3d>& joints);

/// Whether `model` is a right hand: the direction across its knuckles from the little finger
/// (RFing.0) to the index (RFing.3), crossed with the direction from the wrist to the middle
/// knuckle, points to its palm (the side to which flexion takes the middle fingertip). A left
/// hand is the mirror image; the paper's scanned hand is a right one.
bool IsRightHand(const HandModel& model);

}  // namespace ihs::tracker
