#pragma once
// Trajectories in the TUM RGB-D format: one pose per line, "t tx ty tz qx qy qz qw" (t in
// seconds, translation in the file's unit — millimetres in this project — unit quaternion).

#include <filesystem>
#include <vector>

#include "core/rigid3.h"

namespace ihs {

/// One timestamped pose of a trajectory; the transform's direction (e.g. cam_from_object) is
/// the caller's convention and is written in the file header.
struct StampedPose {
  double time_s = 0;
  Rigid3 transform;
};

/// Writes `poses` atomically as a TUM trajectory, with `# comment` lines first (e.g. which
/// transform and unit). Throws ihs::OutputError when the file cannot be written.
void WriteTumTrajectory(const std::filesystem::path& path, const std::vector<StampedPose>& poses,
                        const std::vector<std::string>& comments = {});

/// Reads a TUM trajectory ('#' comments and blank lines skipped). Throws ihs::InputError naming
/// the file and line when a line is malformed or a quaternion is not close to unit length.
std::vector<StampedPose> ReadTumTrajectory(const std::filesystem::path& path);

}  // namespace ihs
