#include "tracker/hand_data.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "tracker/hand_pose.h"
#include "tracker/procedural_hand.h"

namespace ihs::tracker {
namespace fs = std::filesystem;
namespace {

// Lines of a text file without line ends (LF or CRLF), with numbers for error messages.
class Lines {
 public:
  explicit Lines(const fs::path& path) : path_(path), text_(ReadFileToString(path)) {}
  bool Next(std::string& line) {
    if (position_ >= text_.size()) return false;
    size_t end = text_.find('\n', position_);
    if (end == std::string::npos) end = text_.size();
    line.assign(text_, position_, end - position_);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    position_ = end + 1;
    ++number_;
    return true;
  }
  // Next line that is not blank; throws at the end of the file.
  std::string Required(const char* what) {
    std::string line;
    while (Next(line)) {
      if (line.find_first_not_of(" \t") != std::string::npos) return line;
    }
    Fail(std::string("ends before ") + what);
  }
  [[noreturn]] void Fail(const std::string& message) const {
    throw InputError(path_.string() + ": line " + std::to_string(number_) + ": " + message);
  }
  // Parses exactly `count` numbers from `line`.
  std::vector<double> Numbers(const std::string& line, size_t count) const {
    std::vector<double> values;
    const char* p = line.data();
    const char* end = p + line.size();
    while (p < end) {
      while (p < end && (*p == ' ' || *p == '\t')) ++p;
      if (p == end) break;
      double value = 0;
      const auto result = std::from_chars(p, end, value);
      if (result.ec != std::errc() || !std::isfinite(value)) Fail("expected a number");
      values.push_back(value);
      p = result.ptr;
    }
    if (values.size() != count) {
      Fail("expected " + std::to_string(count) + " numbers, found " +
           std::to_string(values.size()));
    }
    return values;
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  std::string text_;
  size_t position_ = 0;
  int number_ = 0;
};

bool StartsWithNumber(const std::string& line) {
  const size_t first = line.find_first_not_of(" \t");
  if (first == std::string::npos) return false;
  const char c = line[first];
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

std::string Trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  const size_t last = text.find_last_not_of(" \t");
  return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

Rigid3 TransformFromRow(const std::vector<double>& v) {
  Eigen::Matrix3d rotation;
  rotation << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
  return Rigid3(rotation, Eigen::Vector3d(v[9], v[10], v[11]));  // Re-orthonormalised.
}

}  // namespace

TriangleMesh ReadOffMesh(const fs::path& path) {
  Lines lines(path);
  if (Trim(lines.Required("the OFF header")) != "OFF") lines.Fail("not an OFF file");
  std::istringstream counts(lines.Required("the counts"));
  long vertices = -1, faces = -1;
  if (!(counts >> vertices >> faces) || vertices <= 0 || faces < 0 || vertices > 10'000'000 ||
      faces > 20'000'000) {
    lines.Fail("bad vertex/face counts");
  }
  TriangleMesh mesh;
  mesh.vertices.reserve(vertices);
  for (long i = 0; i < vertices; ++i) {
    const auto xyz = lines.Numbers(lines.Required("all vertices"), 3);
    mesh.vertices.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  for (long f = 0; f < faces; ++f) {
    std::istringstream face(lines.Required("all faces"));
    long count = 0;
    if (!(face >> count) || count < 3) lines.Fail("bad face");
    std::vector<long> polygon(count);
    for (long& index : polygon) {
      if (!(face >> index) || index < 0 || index >= vertices) lines.Fail("bad face index");
    }
    for (long k = 1; k + 1 < count; ++k) {
      mesh.faces.push_back({static_cast<std::int32_t>(polygon[0]),
                            static_cast<std::int32_t>(polygon[k]),
                            static_cast<std::int32_t>(polygon[k + 1])});
    }
  }
  return mesh;
}

RecordedHand LoadRecordedHand(const fs::path& data_dir, const fs::path& sequence_dir) {
  RecordedHand hand;
  HandModel& model = hand.model;

  // Skeleton: rows per bone, then (parent, name, length) triples.
  Lines skel(sequence_dir / "Model_Hand_R.SKEL");
  const long rows = std::lround(skel.Numbers(skel.Required("the row count"), 1)[0]);
  if (rows < 1 || rows > 1'000'000) skel.Fail("bad row count");
  std::string line;
  while (true) {
    std::string parent;
    while (skel.Next(parent) && Trim(parent).empty()) {
    }
    if (Trim(parent).empty()) break;
    Bone bone;
    bone.name = Trim(skel.Required("a bone name"));
    bone.length_mm = skel.Numbers(skel.Required("a bone length"), 1)[0];
    const std::string parent_name = Trim(parent);
    bone.parent = model.BoneIndex(parent_name);
    if (bone.parent < 0 && !model.bones.empty()) skel.Fail("parent '" + parent_name + "' unknown");
    if (model.BoneIndex(bone.name) >= 0) skel.Fail("bone '" + bone.name + "' repeated");
    model.bones.push_back(bone);
  }
  const size_t bone_count = model.bones.size();
  if (bone_count == 0) skel.Fail("no bones");

  // Motion: per bone a name line and `rows` rows of 12 numbers (global cam_from_bone).
  Lines motion(sequence_dir / "Model_Hand_R.MOTION");
  std::vector<std::vector<Rigid3>> per_bone(bone_count);
  for (size_t j = 0; j < bone_count; ++j) {
    const std::string name = Trim(motion.Required("a bone block"));
    if (StartsWithNumber(name) || name != model.bones[j].name) {
      motion.Fail("expected the block of bone '" + model.bones[j].name + "'");
    }
    per_bone[j].reserve(rows);
    for (long r = 0; r < rows; ++r) {
      per_bone[j].push_back(TransformFromRow(motion.Numbers(motion.Required("all rows"), 12)));
    }
  }
  for (size_t j = 0; j < bone_count; ++j) model.model_from_bone_rest.push_back(per_bone[j][0]);
  hand.cam_from_bone.resize(rows - 1);
  for (long r = 1; r < rows; ++r) {
    hand.cam_from_bone[r - 1].reserve(bone_count);
    for (size_t j = 0; j < bone_count; ++j) hand.cam_from_bone[r - 1].push_back(per_bone[j][r]);
  }

  model.rest_mesh = ReadOffMesh(data_dir / "model" / "Model_Hand_R.OFF");

  // Skinning weights: K, K bone names (which may contain spaces), one row of K per vertex.
  Lines skin(data_dir / "model" / "Model_Hand_R.SKIN");
  const long columns = std::lround(skin.Numbers(skin.Required("the bone count"), 1)[0]);
  std::vector<int> column_bone;
  std::istringstream names(skin.Required("the bone names"));
  std::string token, pending;
  while (names >> token) {
    pending = pending.empty() ? token : pending + " " + token;
    if (const int bone = model.BoneIndex(pending); bone >= 0) {
      column_bone.push_back(bone);
      pending.clear();
    }
  }
  if (!pending.empty() || static_cast<long>(column_bone.size()) != columns) {
    skin.Fail("bone names do not match the skeleton");
  }
  model.weights.resize(model.rest_mesh.vertices.size());
  for (VertexWeights& vertex : model.weights) {
    const auto row = skin.Numbers(skin.Required("all weight rows"), columns);
    double sum = 0;
    for (long c = 0; c < columns; ++c) {
      if (row[c] < 0) skin.Fail("negative weight");
      sum += row[c];
    }
    if (sum <= 0) skin.Fail("a vertex has no weight");
    for (long c = 0; c < columns; ++c) {
      if (row[c] > 0) vertex.bones.emplace_back(column_bone[c], static_cast<float>(row[c] / sum));
    }
  }

  // Limits: per bone a name, flags "T Rx Ry Rz", three axes, three "min max" rows.
  Lines limits(data_dir / "model" / "Model_Hand_R.LIMITS");
  model.limits.resize(bone_count);
  while (limits.Next(line)) {
    const std::string name = Trim(line);
    if (name.empty()) continue;
    const int bone = model.BoneIndex(name);
    if (bone < 0) limits.Fail("unknown bone '" + name + "'");
    JointLimits& joint = model.limits[bone];
    const auto flags = limits.Numbers(limits.Required("the flags"), 4);
    joint.translation = flags[0] != 0;
    std::array<Eigen::Vector3d, 3> axes;
    for (auto& axis : axes) {
      const auto v = limits.Numbers(limits.Required("an axis"), 3);
      axis = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    for (int k = 0; k < 3; ++k) {
      const auto range = limits.Numbers(limits.Required("a limit"), 2);
      joint.limits_deg[k] = {range[0], range[1]};
      const bool bounded = range[0] != 0 || range[1] != 0;
      joint.active[k] = flags[1 + k] != 0 && bounded;
      if (joint.active[k] && bone != 0) {
        if (axes[k].norm() < 1e-6) limits.Fail("zero rotation axis");
        joint.axes[k] = axes[k].normalized();
      }
    }
  }
  model.Check();
  return hand;
}

HandModel LoadHandModel(const fs::path& data_dir) {
  std::vector<fs::path> sessions;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(data_dir / "sequences", error)) {
    if (fs::exists(entry.path() / "Model_Hand_R.MOTION")) sessions.push_back(entry.path());
  }
  if (sessions.empty()) {
    throw InputError(data_dir.string() +
                     ": not a hand data folder (no sequences/*/Model_Hand_R.MOTION)");
  }
  std::sort(sessions.begin(), sessions.end());
  return LoadRecordedHand(data_dir, sessions.front()).model;
}

HandModel LoadHandTemplate(const std::string& name, bool right_hand) {
  if (name == "procedural") {
    ProceduralHandOptions options;
    options.right_hand = right_hand;
    return MakeProceduralHand(options);
  }
  HandModel model = LoadHandModel(name);
  if (IsRightHand(model) != right_hand) {
    throw InputError("the hand template in " + name + " is a " + (right_hand ? "left" : "right") +
                     " hand, the scan asks for a " + (right_hand ? "right" : "left") + " one");
  }
  return model;
}

}  // namespace ihs::tracker
