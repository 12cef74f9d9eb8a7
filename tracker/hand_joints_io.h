#pragma once
// hand_joints.csv: one row per frame, `frame` then x,y,z (mm, camera frame) of the 21 joints of
// HandModel::JointPositions (the root's start, then every bone's end in skeleton order). The
// generator writes it as ground truth, the tracker as its estimate; the evaluation compares them.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "tracker/hand_model.h"

namespace ihs::tracker {

/// The joints of one frame.
struct HandJointsRow {
  std::int64_t frame = 0;
  std::vector<Eigen::Vector3d> joints_mm;
};

/// Writes rows atomically with a header naming each column after `bone_names` (joint 0 is
/// "<root>_start", joint k > 0 is "<bone k-1>_end"). All rows must have bone_names.size() + 1
/// joints. Throws ihs::OutputError when the file cannot be written.
void WriteHandJointsCsv(const std::filesystem::path& path,
                        const std::vector<std::string>& bone_names,
                        const std::vector<HandJointsRow>& rows);

/// Reads a hand_joints.csv. Throws ihs::InputError naming the file and line when malformed.
std::vector<HandJointsRow> ReadHandJointsCsv(const std::filesystem::path& path);

/// The joint error of an estimate against the truth: the mean distance between corresponding
/// joints, mm. Throws std::invalid_argument unless both have the same, non-zero count.
double MeanJointError(const std::vector<Eigen::Vector3d>& estimate_mm,
                      const std::vector<Eigen::Vector3d>& truth_mm);

/// An estimate of the hand against the truth by issue 32's per-frame tests.
struct HandSides {
  /// The estimate's thumb tip is nearer the true little fingertip than the true thumb tip.
  bool thumb_swapped = false;
  /// The estimate's palm normal (little to index knuckle × first joint to middle knuckle) is
  /// more than 90° from the truth's: palm for back.
  bool palm_reversed = false;
  /// Either: the hand is fitted turned over (a flip, where it lasts more than 10 frames).
  bool turned_over() const { return thumb_swapped || palm_reversed; }
};

/// Compares an estimate's sides with the truth's. `model` gives the joints' layout
/// (HandModel::JointPositions; the bones named "RFing.<finger>_Hand", and the fingers' end
/// effectors). Throws std::invalid_argument for other layouts.
HandSides CompareHandSides(const HandModel& model, const std::vector<Eigen::Vector3d>& estimate_mm,
                           const std::vector<Eigen::Vector3d>& truth_mm);

}  // namespace ihs::tracker
