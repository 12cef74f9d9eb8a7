#include "core/trajectory_io.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "core/data_lines.h"
#include "core/errors.h"

namespace ihs {

void WriteTumTrajectory(const std::filesystem::path& path, const std::vector<StampedPose>& poses,
                        const std::vector<std::string>& comments) {
  std::string text;
  for (const std::string& comment : comments) text += "# " + comment + "\n";
  text += "# timestamp tx ty tz qx qy qz qw\n";
  char line[256];
  for (const StampedPose& pose : poses) {
    const Eigen::Vector3d& t = pose.transform.translation();
    Eigen::Quaterniond q = pose.transform.quaternion();
    if (q.w() < 0) q.coeffs() = -q.coeffs();  // One of the two equal quaternions, w ≥ 0.
    std::snprintf(line, sizeof(line), "%.6f %.6f %.6f %.6f %.9f %.9f %.9f %.9f\n", pose.time_s,
                  t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
    text += line;
  }
  WriteFileAtomically(path, text);
}

std::vector<StampedPose> ReadTumTrajectory(const std::filesystem::path& path) {
  std::vector<StampedPose> poses;
  for (const DataLine& line : ReadDataLines(path)) {
    const int number = line.number;
    std::istringstream fields(line.text);
    double v[8];
    for (double& value : v) {
      if (!(fields >> value) || !std::isfinite(value)) {
        throw InputError(path.string() + ": line " + std::to_string(number) +
                         " is not 't tx ty tz qx qy qz qw'");
      }
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      throw InputError(path.string() + ": line " + std::to_string(number) +
                       ": quaternion is not of unit length");
    }
    poses.push_back({v[0], Rigid3(q, Eigen::Vector3d(v[1], v[2], v[3]))});
  }
  return poses;
}

}  // namespace ihs
