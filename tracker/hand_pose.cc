#include "tracker/hand_pose.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "core/check.h"

namespace ihs::tracker {
namespace {

// parent_from_bone in the rest pose.
Rigid3 RestOnParent(const HandModel& model, int bone) {
  return model.model_from_bone_rest[model.bones[bone].parent].Inverse() *
         model.model_from_bone_rest[bone];
}

// Angle of rotation `rotation` about unit `axis` (its twist component, swing removed).
double TwistAngle(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& axis) {
  const Eigen::Quaterniond q(rotation);
  const double along = q.vec().dot(axis);
  return 2.0 * std::atan2(along, q.w());
}

}  // namespace

std::vector<DegreeOfFreedom> JointDegreesOfFreedom(const HandModel& model) {
  std::vector<DegreeOfFreedom> dofs;
  for (int bone = 1; bone < static_cast<int>(model.bones.size()); ++bone) {
    for (int axis = 0; axis < 3; ++axis) {
      if (model.limits[bone].active[axis]) dofs.push_back({bone, axis});
    }
  }
  return dofs;
}

HandPose HandPose::Rest(const HandModel& model, const Rigid3& cam_from_model) {
  HandPose pose;
  pose.cam_from_root = cam_from_model * model.model_from_bone_rest[0];
  pose.angles_rad.assign(JointDegreesOfFreedom(model).size(), 0.0);
  return pose;
}

std::vector<Rigid3> ForwardKinematics(const HandModel& model, const HandPose& pose) {
  const std::vector<DegreeOfFreedom> dofs = JointDegreesOfFreedom(model);
  IHS_CHECK_ARG(pose.angles_rad.size() == dofs.size(),
                "hand pose has " << pose.angles_rad.size() << " angles, the model " << dofs.size()
                                 << " degrees of freedom");
  std::vector<Eigen::Matrix3d> local(model.bones.size(), Eigen::Matrix3d::Identity());
  for (size_t k = 0; k < dofs.size(); ++k) {
    const auto& [bone, axis] = dofs[k];
    local[bone] =
        local[bone] *
        Eigen::AngleAxisd(pose.angles_rad[k], model.limits[bone].axes[axis]).toRotationMatrix();
  }
  std::vector<Rigid3> cam_from_bone(model.bones.size());
  cam_from_bone[0] = pose.cam_from_root;
  for (size_t bone = 1; bone < model.bones.size(); ++bone) {
    cam_from_bone[bone] = cam_from_bone[model.bones[bone].parent] *
                          RestOnParent(model, static_cast<int>(bone)) *
                          Rigid3(local[bone], Eigen::Vector3d::Zero());
  }
  return cam_from_bone;
}

HandPose PoseFromBoneTransforms(const HandModel& model, const std::vector<Rigid3>& cam_from_bone) {
  IHS_CHECK_ARG(cam_from_bone.size() == model.bones.size(),
                "need one transform per bone, got " << cam_from_bone.size());
  HandPose pose;
  pose.cam_from_root = cam_from_bone[0];
  const std::vector<DegreeOfFreedom> dofs = JointDegreesOfFreedom(model);
  pose.angles_rad.assign(dofs.size(), 0.0);
  size_t k = 0;
  for (size_t bone = 1; bone < model.bones.size(); ++bone) {
    const Rigid3 rest_in_cam =
        cam_from_bone[model.bones[bone].parent] * RestOnParent(model, static_cast<int>(bone));
    // Peels the axes off in order (R = R0·R1·R2): what remains after the earlier ones.
    Eigen::Matrix3d remaining = (rest_in_cam.Inverse() * cam_from_bone[bone]).rotation();
    for (; k < dofs.size() && dofs[k].bone == static_cast<int>(bone); ++k) {
      const Eigen::Vector3d& axis = model.limits[bone].axes[dofs[k].axis];
      const double angle = TwistAngle(remaining, axis);
      pose.angles_rad[k] = angle;
      remaining = Eigen::AngleAxisd(-angle, axis).toRotationMatrix() * remaining;
    }
  }
  return pose;
}

PalmAxes PalmAxesOf(const HandModel& model, const std::vector<Eigen::Vector3d>& joints) {
  IHS_CHECK_ARG(joints.size() == model.bones.size() + 1,
                joints.size() << " joints for a model of " << model.bones.size() + 1);
  auto knuckle = [&](int finger) {
    const std::string bone = "RFing." + std::to_string(finger) + "_Hand";
    const int index = model.BoneIndex(bone);
    IHS_CHECK_ARG(index >= 0, "the hand model has no bone " << bone);
    return joints[static_cast<size_t>(index + 1)];
  };
  PalmAxes axes;
  axes.across = knuckle(3) - knuckle(0);
  axes.along = knuckle(2) - joints[0];
  axes.centre = joints[0];
  for (int finger = 0; finger < 4; ++finger) axes.centre += knuckle(finger);
  axes.centre /= 5.0;
  return axes;
}

bool IsRightHand(const HandModel& model) {
  const auto dofs = JointDegreesOfFreedom(model);
  const HandPose rest = HandPose::Rest(model);
  HandPose flexed = rest;
  for (size_t k = 0; k < dofs.size(); ++k) {
    if (dofs[k].axis == 1) flexed.angles_rad[k] = -0.6;
  }
  const auto joints = model.JointPositions(ForwardKinematics(model, rest));
  const auto bent = model.JointPositions(ForwardKinematics(model, flexed));
  const int middle_tip = model.BoneIndex("RFing.2_2");
  IHS_CHECK_ARG(middle_tip >= 0, "IsRightHand: the model has no bone RFing.2_2");
  const size_t tip = static_cast<size_t>(middle_tip + 1);
  return PalmAxesOf(model, joints).Normal().dot(bent[tip] - joints[tip]) > 0;
}

}  // namespace ihs::tracker
