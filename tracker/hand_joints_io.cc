#include "tracker/hand_joints_io.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/errors.h"
#include "tracker/hand_pose.h"

namespace ihs::tracker {

void WriteHandJointsCsv(const std::filesystem::path& path,
                        const std::vector<std::string>& bone_names,
                        const std::vector<HandJointsRow>& rows) {
  IHS_CHECK_ARG(!bone_names.empty(), "hand_joints.csv needs bone names");
  std::string text = "frame";
  for (size_t j = 0; j <= bone_names.size(); ++j) {
    std::string name = j == 0 ? bone_names[0] + "_start" : bone_names[j - 1] + "_end";
    for (char& c : name) {
      if (c == ' ' || c == ',') c = '_';
    }
    for (const char* axis : {"_x", "_y", "_z"}) text += "," + name + axis;
  }
  text += "\n";
  char number[64];
  for (const HandJointsRow& row : rows) {
    IHS_CHECK_ARG(row.joints_mm.size() == bone_names.size() + 1,
                  "frame " << row.frame << " has " << row.joints_mm.size() << " joints, expected "
                           << bone_names.size() + 1);
    text += std::to_string(row.frame);
    for (const Eigen::Vector3d& joint : row.joints_mm) {
      for (int k = 0; k < 3; ++k) {
        std::snprintf(number, sizeof(number), ",%.4f", joint[k]);
        text += number;
      }
    }
    text += "\n";
  }
  WriteFileAtomically(path, text);
}

std::vector<HandJointsRow> ReadHandJointsCsv(const std::filesystem::path& path) {
  std::istringstream lines(ReadFileToString(path));
  std::string line;
  int number = 0;
  size_t columns = 0;
  std::vector<HandJointsRow> rows;
  auto fail = [&](const std::string& why) -> void {
    throw InputError(path.string() + ": line " + std::to_string(number) + ": " + why);
  };
  while (std::getline(lines, line)) {
    ++number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    std::vector<std::string> fields;
    std::stringstream split(line);
    std::string field;
    while (std::getline(split, field, ',')) fields.push_back(field);
    if (columns == 0) {
      if (fields.empty() || fields[0] != "frame" || (fields.size() - 1) % 3 != 0 ||
          fields.size() < 4) {
        fail("expected a header 'frame,<joint>_x,<joint>_y,<joint>_z,...'");
      }
      columns = fields.size();
      continue;
    }
    if (fields.size() != columns) fail("expected " + std::to_string(columns) + " columns");
    HandJointsRow row;
    try {
      size_t used = 0;
      row.frame = std::stoll(fields[0], &used);
      if (used != fields[0].size()) fail("bad frame number");
      for (size_t c = 1; c < columns; c += 3) {
        Eigen::Vector3d joint;
        for (int k = 0; k < 3; ++k) {
          joint[k] = std::stod(fields[c + k], &used);
          if (used != fields[c + k].size() || !std::isfinite(joint[k])) fail("bad coordinate");
        }
        row.joints_mm.push_back(joint);
      }
    } catch (const std::logic_error&) {
      fail("a field is not a number");
    }
    rows.push_back(std::move(row));
  }
  if (columns == 0) throw InputError(path.string() + ": empty, no header");
  return rows;
}

double MeanJointError(const std::vector<Eigen::Vector3d>& estimate_mm,
                      const std::vector<Eigen::Vector3d>& truth_mm) {
  IHS_CHECK_ARG(!truth_mm.empty() && estimate_mm.size() == truth_mm.size(),
                "joint error of " << estimate_mm.size() << " joints against " << truth_mm.size());
  double sum = 0;
  for (size_t j = 0; j < truth_mm.size(); ++j) sum += (estimate_mm[j] - truth_mm[j]).norm();
  return sum / static_cast<double>(truth_mm.size());
}

HandSides CompareHandSides(const HandModel& model, const std::vector<Eigen::Vector3d>& estimate_mm,
                           const std::vector<Eigen::Vector3d>& truth_mm) {
  const size_t joints = model.bones.size() + 1;
  IHS_CHECK_ARG(estimate_mm.size() == joints && truth_mm.size() == joints,
                "CompareHandSides: " << estimate_mm.size() << " and " << truth_mm.size()
                                     << " joints for a model of " << joints);
  // Fingertips: the ends of the end effectors, by finger (0 little, 4 thumb).
  size_t tips[5] = {0, 0, 0, 0, 0};
  for (int bone : model.EndEffectors()) {
    const int finger = model.FingerOf(bone);
    if (finger >= 0) tips[finger] = static_cast<size_t>(bone + 1);
  }
  const size_t thumb = tips[4], little = tips[0];
  IHS_CHECK_ARG(thumb > 0 && little > 0,
                "CompareHandSides: the model has no thumb or little finger");
  HandSides sides;
  sides.thumb_swapped = (estimate_mm[thumb] - truth_mm[little]).norm() <
                        (estimate_mm[thumb] - truth_mm[thumb]).norm();
  sides.palm_reversed =
      PalmAxesOf(model, estimate_mm).Normal().dot(PalmAxesOf(model, truth_mm).Normal()) < 0;
  return sides;
}

}  // namespace ihs::tracker
