#pragma once
// hand_joints.csv: one row per frame, `frame` then x,y,z (mm, camera frame) of the 21 joints of
// HandModel::JointPositions (the root's start, then every bone's end in skeleton order). The
// generator writes it as ground truth, the tracker as its estimate; the evaluation compares them.

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

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

}  // namespace ihs::tracker
