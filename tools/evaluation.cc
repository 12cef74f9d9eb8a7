#include "tools/evaluation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "core/data_lines.h"
#include "core/errors.h"
#include "core/mesh_io.h"
#include "core/point_kd_tree.h"
#include "render/offscreen_renderer.h"
#include "tools/synth/objects.h"
#include "tracker/hand_joints_io.h"

namespace ihs::eval {
namespace {

namespace fs = std::filesystem;

// The angle of a rotation, degrees.
double AngleDeg(const Eigen::Matrix3d& rotation) {
  return Eigen::AngleAxisd(rotation).angle() * 180.0 / M_PI;
}

synth::LatheProfile ProfileOf(const std::string& spec) {
  if (spec.rfind("lathe:", 0) == 0) return synth::ReadLatheProfile(spec.substr(6));
  return synth::PaperObjectProfile(spec);  // Throws for an unknown name.
}

// The generator's fingertips, in contacts.csv's column order, and each one's joint in
// hand_joints.csv (the end of its last bone: "RFing.<f>_…" columns, thumb = finger 4).
constexpr const char* kFingers[5] = {"pinky", "ring", "middle", "index", "thumb"};

// One frame of gt/contacts.csv: whether each fingertip touches the object, and how far it is
// from the object's surface (mm).
struct TrueContacts {
  std::array<bool, 5> touch{};
  std::array<double, 5> distance_mm{};
  bool operator[](int finger) const { return touch[finger]; }
};

// The column of `name` in `header`; throws naming `path` when there is none.
int Column(const std::vector<std::string>& header, const std::string& name, const fs::path& path) {
  const auto found = std::find(header.begin(), header.end(), name);
  if (found == header.end()) throw InputError(path.string() + ": no column " + name);
  return static_cast<int>(found - header.begin());
}

// Per frame of gt/contacts.csv: whether each fingertip touches the object, and its distance.
std::map<std::int64_t, TrueContacts> ReadTouches(const fs::path& path) {
  const std::vector<DataLine> lines = ReadDataLines(path);
  if (lines.empty()) throw InputError(path.string() + ": empty");
  const std::vector<std::string> header = SplitFields(lines.front().text);
  std::array<int, 5> column{}, distance_column{};
  for (int f = 0; f < 5; ++f) {
    column[f] = Column(header, std::string(kFingers[f]) + "_touch", path);
    distance_column[f] = Column(header, std::string(kFingers[f]) + "_mm", path);
  }
  std::map<std::int64_t, TrueContacts> touches;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> fields = SplitFields(lines[i].text);
    if (fields.size() != header.size()) {
      throw InputError(path.string() + ": line " + std::to_string(lines[i].number) + " has " +
                       std::to_string(fields.size()) + " fields, the header " +
                       std::to_string(header.size()));
    }
    TrueContacts contacts;
    for (int f = 0; f < 5; ++f) {
      contacts.touch[f] = fields[column[f]] == "1";
      contacts.distance_mm[f] = std::stod(fields[distance_column[f]]);
    }
    touches[std::stoll(fields[0])] = contacts;
  }
  return touches;
}

// The joint index (in a hand_joints.csv row) of each fingertip: the last joint of finger f.
std::array<int, 5> FingertipJoints(const fs::path& joints_csv) {
  const std::vector<DataLine> lines = ReadDataLines(joints_csv);
  if (lines.empty()) throw InputError(joints_csv.string() + ": empty");
  std::array<int, 5> joint;
  joint.fill(-1);
  // Columns: frame, then x,y,z per joint.
  const std::vector<std::string> header = SplitFields(lines.front().text);
  for (size_t column = 1; column < header.size(); ++column) {
    for (int f = 0; f < 5; ++f) {
      const std::string prefix = "RFing." + std::to_string(f) + "_";
      if (header[column].rfind(prefix, 0) == 0) joint[f] = static_cast<int>(column - 1) / 3;
    }
  }
  for (int f = 0; f < 5; ++f) {
    if (joint[f] < 0) {
      throw InputError(joints_csv.string() + ": no joints of finger RFing." + std::to_string(f));
    }
  }
  return joint;
}

}  // namespace

const StampedPose* FindPose(const std::vector<StampedPose>& trajectory, double time_s) {
  const auto found =
      std::lower_bound(trajectory.begin(), trajectory.end(), time_s - 5e-4,
                       [](const StampedPose& pose, double t) { return pose.time_s < t; });
  if (found == trajectory.end() || std::abs(found->time_s - time_s) > 5e-4) return nullptr;
  return &*found;
}

fusion::RevolutionMeasures TrueMeasures(const std::string& object_spec) {
  // Rings every 0.5 mm, as dense as a scan's mesh, so the same measuring code applies.
  return fusion::MeasureRevolution(
      synth::MakeLatheMesh(synth::ResampleProfile(ProfileOf(object_spec), 0.5), 256));
}

double TrueVolume(const std::string& object_spec) {
  const synth::LatheProfile profile = ProfileOf(object_spec);
  double volume = 0;
  for (size_t i = 1; i < profile.size(); ++i) {
    const auto [z0, r0] = profile[i - 1];
    const auto [z1, r1] = profile[i];
    volume += M_PI * (z1 - z0) * (r0 * r0 + r0 * r1 + r1 * r1) / 3;
  }
  return volume;
}

std::vector<DimensionRow> PaperDimensions(const std::string& object_spec,
                                          const TriangleMesh& scan) {
  const fusion::RevolutionMeasures truth = TrueMeasures(object_spec);
  const fusion::RevolutionMeasures captured = fusion::MeasureRevolution(scan);
  if (object_spec == "sphere") {
    return {{"diameter", truth.widest_diameter_mm, captured.widest_diameter_mm}};
  }
  std::vector<DimensionRow> rows = {{"height", truth.height_mm, captured.height_mm}};
  if (object_spec == "bowling-pin") {
    rows.push_back({"body diameter", truth.widest_diameter_mm, captured.widest_diameter_mm});
    rows.push_back({"head diameter", truth.head_diameter_mm, captured.head_diameter_mm});
  } else {
    rows.push_back({"diameter", truth.widest_diameter_mm, captured.widest_diameter_mm});
  }
  return rows;
}

bool IsBox(const TriangleMesh& mesh) { return fusion::MeasureBox(mesh).face_share >= 0.9; }

std::vector<DimensionRow> BoxDimensions(const TriangleMesh& truth, const TriangleMesh& scan) {
  auto sides = [](const TriangleMesh& mesh) {
    const Eigen::Vector3d size =
        fusion::MeasureExtent(mesh.vertices, fusion::MeasureBox(mesh).axes).Size();
    std::array<double, 3> sorted = {size.x(), size.y(), size.z()};
    std::sort(sorted.begin(), sorted.end(), std::greater<double>());
    return sorted;
  };
  const std::array<double, 3> true_sides = sides(truth), scan_sides = sides(scan);
  const char* names[3] = {"longest side", "middle side", "shortest side"};
  std::vector<DimensionRow> rows;
  for (int k = 0; k < 3; ++k) rows.push_back({names[k], true_sides[k], scan_sides[k]});
  return rows;
}

PairwiseError ContactPairwiseError(const fs::path& gt_dir,
                                   const std::vector<StampedPose>& trajectory) {
  const std::vector<StampedPose> truth = ReadTumTrajectory(gt_dir / "trajectory.txt");
  const auto touches = ReadTouches(gt_dir / "contacts.csv");
  const std::array<int, 5> tip = FingertipJoints(gt_dir / "hand_joints.csv");
  const std::vector<tracker::HandJointsRow> joints =
      tracker::ReadHandJointsCsv(gt_dir / "hand_joints.csv");
  const TriangleMesh object = ReadMesh(gt_dir / "object.ply");
  const PointKdTree surface(fusion::SampleSurface(object, 0.3));

  std::vector<double> errors;
  for (size_t k = 1; k < truth.size() && k < joints.size(); ++k) {
    const StampedPose* before = FindPose(trajectory, truth[k - 1].time_s);
    const StampedPose* after = FindPose(trajectory, truth[k].time_s);
    const auto touch_before = touches.find(static_cast<std::int64_t>(k - 1));
    const auto touch_after = touches.find(static_cast<std::int64_t>(k));
    if (!before || !after || touch_before == touches.end() || touch_after == touches.end()) {
      continue;
    }
    const Rigid3 estimated = after->transform * before->transform.Inverse();
    const Rigid3 object_from_cam = truth[k - 1].transform.Inverse();
    for (int f = 0; f < 5; ++f) {
      if (!touch_before->second[f] || !touch_after->second[f]) continue;
      // The object's surface point under the fingertip, in the object frame.
      float distance_sq = 0;
      const Eigen::Vector3f tip_in_object =
          (object_from_cam * joints[k - 1].joints_mm[tip[f]]).cast<float>();
      const Eigen::Vector3d point =
          surface.points()[surface.Nearest(tip_in_object, &distance_sq)].cast<double>();
      const Eigen::Vector3d seen_before = truth[k - 1].transform * point;
      errors.push_back((estimated * seen_before - truth[k].transform * point).norm());
    }
  }
  PairwiseError result;
  result.samples = static_cast<int>(errors.size());
  if (errors.empty()) return result;
  double sum = 0, sum_sq = 0;
  for (double e : errors) sum += e, sum_sq += e * e;
  result.mean_mm = sum / errors.size();
  result.std_mm =
      std::sqrt(std::max(0.0, sum_sq / errors.size() - result.mean_mm * result.mean_mm));
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  result.median_mm = errors[errors.size() / 2];
  return result;
}

// A true step turning less than this stands still (0.05°: the generator's scripted turns turn
// 0.17° or more a frame while held; rounding leaves 1e-6).
constexpr double kStillRad = 0.05 * M_PI / 180.0;

TrajectoryError CompareTrajectory(const fs::path& gt_dir,
                                  const std::vector<StampedPose>& trajectory) {
  const std::vector<StampedPose> truth = ReadTumTrajectory(gt_dir / "trajectory.txt");
  const TriangleMesh object = ReadMesh(gt_dir / "object.ply");
  TrajectoryError result;
  if (trajectory.empty()) return result;
  const StampedPose* first = FindPose(truth, trajectory.front().time_s);
  if (!first) return result;
  // Scan object frame ← true object frame, fixed by the first registered frame.
  const Rigid3 scan_from_truth = trajectory.front().transform.Inverse() * first->transform;
  double sum = 0, rotation_sum = 0;
  const StampedPose* last_true = nullptr;
  Rigid3 last_estimated;
  // The scan's steps where the truth stood still (rotation vectors, object frame), and the
  // truth's steps summed (its turn axis).
  std::vector<Eigen::Vector3d> still_steps;
  Eigen::Vector3d truth_turn = Eigen::Vector3d::Zero();
  for (const StampedPose& pose : trajectory) {
    const StampedPose* true_pose = FindPose(truth, pose.time_s);
    if (!true_pose) continue;
    const Rigid3 estimated = pose.transform * scan_from_truth;
    double error = 0;
    for (const auto& v : object.vertices) {
      const Eigen::Vector3d p = v.cast<double>();
      error += (estimated * p - true_pose->transform * p).norm();
    }
    error /= std::max<size_t>(1, object.vertices.size());
    sum += error;
    result.max_mm = std::max(result.max_mm, error);
    result.final_mm = error;
    const double turned_off =
        AngleDeg(estimated.rotation().transpose() * true_pose->transform.rotation());
    rotation_sum += turned_off;
    result.rotation_max_deg = std::max(result.rotation_max_deg, turned_off);
    result.rotation_final_deg = turned_off;
    if (last_true) {
      // The steps in the object's frame (a turn of the object about its own axis).
      const Eigen::AngleAxisd true_step(last_true->transform.rotation().transpose() *
                                        true_pose->transform.rotation());
      const Eigen::AngleAxisd scan_step(last_estimated.rotation().transpose() *
                                        estimated.rotation());
      result.truth_turned_deg += true_step.angle() * 180.0 / M_PI;
      result.scan_turned_deg +=
          scan_step.angle() * scan_step.axis().dot(true_step.axis()) * 180.0 / M_PI;
      truth_turn += true_step.angle() * true_step.axis();
      if (true_step.angle() < kStillRad)
        still_steps.push_back(scan_step.angle() * scan_step.axis());
    }
    last_true = true_pose;
    last_estimated = estimated;
    result.times_s.push_back(pose.time_s);
    result.errors_mm.push_back(error);
    ++result.frames;
  }
  result.mean_mm = result.frames ? sum / result.frames : 0;
  result.rotation_mean_deg = result.frames ? rotation_sum / result.frames : 0;
  result.still_steps = static_cast<int>(still_steps.size());
  const Eigen::Vector3d axis =
      truth_turn.norm() > 0 ? Eigen::Vector3d(truth_turn.normalized()) : Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& step : still_steps) {
    result.scan_turned_still_deg += step.dot(axis) * 180.0 / M_PI;
    result.scan_wandered_still_deg += step.norm() * 180.0 / M_PI;
  }
  return result;
}

ContactUse CompareContactUse(const fs::path& gt_dir, const std::vector<FrameContactUse>& frames,
                             double false_mm) {
  const std::vector<StampedPose> truth = ReadTumTrajectory(gt_dir / "trajectory.txt");
  const auto touches = ReadTouches(gt_dir / "contacts.csv");
  ContactUse use;
  for (const FrameContactUse& frame : frames) {
    // The truth's frame index: its row in the trajectory with this time stamp.
    const StampedPose* pose = FindPose(truth, frame.time_s);
    if (!pose) continue;
    const auto touch = touches.find(static_cast<std::int64_t>(pose - truth.data()));
    if (touch == touches.end()) continue;
    const TrueContacts& contacts = touch->second;
    const int touching =
        static_cast<int>(std::count(contacts.touch.begin(), contacts.touch.end(), true));
    double nearest = 1e9;
    for (int finger = 0; finger < static_cast<int>(contacts.distance_mm.size()); ++finger) {
      if (frame.fingers.empty() ||
          std::count(frame.fingers.begin(), frame.fingers.end(), finger) > 0) {
        nearest = std::min(nearest, contacts.distance_mm[finger]);
      }
    }
    if (touching >= 2) {
      ++use.grasp_frames;
      use.used_in_grasp += frame.used;
    }
    if (frame.used) {
      ++use.used_frames;
      use.false_frames += nearest > false_mm;
    }
  }
  use.recall = use.grasp_frames ? static_cast<double>(use.used_in_grasp) / use.grasp_frames : 0;
  use.false_share = use.used_frames ? static_cast<double>(use.false_frames) / use.used_frames : 0;
  return use;
}

GraspTips CompareGraspTips(const fs::path& gt_dir, const fs::path& tracked_csv,
                           const std::vector<double>& within_mm) {
  const auto touches = ReadTouches(gt_dir / "contacts.csv");
  const std::array<int, 5> true_tip = FingertipJoints(gt_dir / "hand_joints.csv");
  const std::array<int, 5> tracked_tip = FingertipJoints(tracked_csv);
  std::map<std::int64_t, std::vector<Eigen::Vector3d>> truth, tracked;
  for (auto& row : tracker::ReadHandJointsCsv(gt_dir / "hand_joints.csv"))
    truth[row.frame] = std::move(row.joints_mm);
  for (auto& row : tracker::ReadHandJointsCsv(tracked_csv))
    tracked[row.frame] = std::move(row.joints_mm);
  GraspTips tips{0, within_mm, std::vector<double>(within_mm.size(), 0.0)};
  for (const auto& [frame, contacts] : touches) {
    const int touching =
        static_cast<int>(std::count(contacts.touch.begin(), contacts.touch.end(), true));
    const auto true_joints = truth.find(frame);
    if (touching < 2 || true_joints == truth.end()) continue;
    ++tips.grasp_frames;
    const auto fitted = tracked.find(frame);
    if (fitted == tracked.end()) continue;
    // Two touching fingers are within any distance at or above the second smallest error.
    std::vector<double> errors;
    for (int f = 0; f < 5; ++f) {
      if (!contacts.touch[f]) continue;
      errors.push_back(
          (fitted->second.at(tracked_tip[f]) - true_joints->second.at(true_tip[f])).norm());
    }
    std::sort(errors.begin(), errors.end());
    for (size_t k = 0; k < within_mm.size(); ++k) tips.share[k] += errors[1] <= within_mm[k];
  }
  for (double& share : tips.share) share /= std::max(1, tips.grasp_frames);
  return tips;
}

fusion::SurfaceComparison CompareWithTruth(const fs::path& gt_dir, const TriangleMesh& scan,
                                           const std::vector<StampedPose>& trajectory) {
  if (trajectory.empty()) throw InputError("no registered frame to align the scan by");
  const std::vector<StampedPose> truth = ReadTumTrajectory(gt_dir / "trajectory.txt");
  const StampedPose* true_pose = FindPose(truth, trajectory.front().time_s);
  if (!true_pose) {
    throw InputError((gt_dir / "trajectory.txt").string() +
                     ": no pose at t = " + std::to_string(trajectory.front().time_s) + " s");
  }
  // Scan object frame → camera (first registered frame) → true object frame.
  const Rigid3 truth_from_scan = true_pose->transform.Inverse() * trajectory.front().transform;
  TriangleMesh placed = scan;
  for (auto& v : placed.vertices)
    v = (truth_from_scan * Eigen::Vector3d(v.cast<double>())).cast<float>();
  return fusion::CompareSurfaces(placed, ReadMesh(gt_dir / "object.ply"));
}

// The paper's dimensions of `object` measured on `mesh`, printed by `print` as a table, as JSON
// "dimensions" + `suffix` and "dimension_error_mm_mean" + `suffix`.
template <typename Print>
nlohmann::json DimensionReport(const std::vector<DimensionRow>& rows, const std::string& suffix,
                               Print& print) {
  nlohmann::json report = nlohmann::json::object();
  print("%-16s %10s %10s %10s\n", "measure", "truth mm", "scan mm", "error mm");
  double sum = 0;
  nlohmann::json& table = report["dimensions" + suffix] = nlohmann::json::array();
  for (const DimensionRow& row : rows) {
    print("%-16s %10.2f %10.2f %+10.2f\n", row.measure.c_str(), row.truth_mm, row.captured_mm,
          row.Error());
    table.push_back(
        {{"measure", row.measure}, {"truth_mm", row.truth_mm}, {"scan_mm", row.captured_mm}});
    sum += std::abs(row.Error());
  }
  report["dimension_error_mm_mean" + suffix] = sum / rows.size();
  print("mean absolute error: %.2f mm over %zu measures\n", sum / rows.size(), rows.size());
  return report;
}

void ReportVolume(double truth_mm3, const TriangleMesh& watertight,
                  std::optional<double> unseen_share, std::FILE* out, nlohmann::json* report) {
  const double volume = watertight.Volume();
  if (out) {
    std::fprintf(out, "volume: truth %.0f mm³, scan %.0f mm³, %+.2f %%", truth_mm3, volume,
                 100 * (volume / truth_mm3 - 1));
  }
  (*report)["volume_mm3"] = {{"truth", truth_mm3}, {"scan", volume}};
  (*report)["volume_error"] = volume / truth_mm3 - 1;
  if (unseen_share) {
    // What no frame saw, Poisson closed: the volume is a guess over that part.
    if (out) std::fprintf(out, " (%.0f %% of its surface never seen)", 100 * *unseen_share);
    (*report)["volume_unseen_share"] = *unseen_share;
  }
  if (out) std::fprintf(out, "\n");
}

ShownSurface::ShownSurface(const fs::path& gt_dir, const CameraIntrinsics& intrinsics)
    : gt_dir_(gt_dir),
      intrinsics_(intrinsics),
      truth_(ReadTumTrajectory(gt_dir / "trajectory.txt")) {
  for (const char* needed : {"labels", "object.ply"}) {
    if (!fs::exists(gt_dir / needed)) throw InputError((gt_dir / needed).string() + ": missing");
  }
}

std::vector<std::uint8_t> TruthObjectPixels(const fs::path& gt_dir, std::int64_t index, int width,
                                            int height) {
  char name[32];
  std::snprintf(name, sizeof name, "%06lld.png", static_cast<long long>(index));
  const cv::Mat labels = cv::imread((gt_dir / "labels" / name).string(), cv::IMREAD_GRAYSCALE);
  if (labels.cols != width || labels.rows != height || !labels.isContinuous()) return {};
  std::vector<std::uint8_t> object(labels.total());
  for (size_t i = 0; i < object.size(); ++i) object[i] = labels.data[i] == render::kObject;
  return object;
}

void ShownSurface::Add(const Frame& frame) {
  const StampedPose* pose = FindPose(truth_, frame.depth_timestamp_us * 1e-6);
  if (!pose) return;
  const std::int64_t index = pose - truth_.data();
  const std::vector<std::uint8_t> object =
      TruthObjectPixels(gt_dir_, index, frame.width, frame.height);
  if (object.empty()) {
    throw InputError((gt_dir_ / "labels").string() + ": frame " + std::to_string(index) +
                     "'s labels are missing or not the frame's size");
  }
  Add(frame, object);
}

void ShownSurface::Add(const Frame& frame, const std::vector<std::uint8_t>& object_pixels) {
  const StampedPose* pose = FindPose(truth_, frame.depth_timestamp_us * 1e-6);
  if (!pose || object_pixels.size() != frame.depth_mm.size()) return;
  const Rigid3 object_from_cam = pose->transform.Inverse();
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const size_t pixel = static_cast<size_t>(v) * frame.width + u;
      const std::uint16_t depth = frame.depth_mm[pixel];
      if (depth == 0 || !object_pixels[pixel]) continue;
      const Eigen::Vector3d p = object_from_cam * intrinsics_.BackProject(u, v, depth);
      // A millimetre cube's key (the object lies within ±1 m of its origin).
      const Eigen::Array3i cell = (p.array().floor() + 1024).cast<int>().min(2047).max(0);
      points_.try_emplace((std::int64_t{cell.x()} << 22) | (cell.y() << 11) | cell.z(),
                          p.cast<float>());
    }
  }
}

double ShownSurface::Share(double within_mm) const {
  std::vector<Eigen::Vector3f> shown;
  shown.reserve(points_.size());
  for (const auto& entry : points_) shown.push_back(entry.second);
  const PointKdTree tree(std::move(shown));
  const std::vector<Eigen::Vector3f> truth =
      fusion::SampleSurface(ReadMesh(gt_dir_ / "object.ply"), 1.0);
  if (truth.empty()) return 0;
  int near = 0;
  for (const Eigen::Vector3f& p : truth) {
    float distance_sq = 0;
    near += tree.Nearest(p, &distance_sq) >= 0 && distance_sq <= within_mm * within_mm;
  }
  return static_cast<double>(near) / truth.size();
}

bool IsBodyOfRevolution(const std::string& object) {
  const std::vector<std::string> names = synth::PaperObjectNames();
  return object.rfind("lathe:", 0) == 0 ||
         std::find(names.begin(), names.end(), object) != names.end();
}

std::string NotABodyOfRevolution(const std::string& object) {
  return IsBodyOfRevolution(object) ? std::string()
                                    : "unknown object '" + object +
                                          "' (sphere, water-bottle, bowling-pin, small-bottle, "
                                          "lathe:FILE)";
}

nlohmann::json ReportScan(const std::string& object, const TriangleMesh& seen,
                          const TriangleMesh& watertight, const fs::path& gt_dir,
                          const std::vector<StampedPose>& trajectory,
                          std::optional<double> unseen_share, std::FILE* out) {
  // Prints to `out` unless it is null.
  auto print = [out](const char* format, auto... values) {
    if (out) std::fprintf(out, format, values...);
  };
  nlohmann::json report = nlohmann::json::object();
  // The dimensions on the seen surface and, what the user takes away, on the closed mesh where
  // it is another.
  auto dimensions = [&](const auto& measure) {
    report.update(DimensionReport(measure(seen), "", print));
    if (&watertight != &seen && !watertight.faces.empty()) {
      print("on the watertight mesh (mesh.ply):\n");
      report.update(DimensionReport(measure(watertight), "_watertight", print));
    }
  };
  if (!IsBodyOfRevolution(object)) {
    if (!gt_dir.empty() && fs::exists(gt_dir / "object.ply")) {
      const TriangleMesh truth = ReadMesh(gt_dir / "object.ply");
      // A box's sides (the generator's boxes and cubes).
      if (IsBox(truth) && !seen.faces.empty()) {
        dimensions([&](const TriangleMesh& mesh) { return BoxDimensions(truth, mesh); });
      }
      if (watertight.IsWatertight()) {
        ReportVolume(truth.Volume(), watertight, unseen_share, out, &report);
      }
    }
  } else {
    dimensions([&](const TriangleMesh& mesh) { return PaperDimensions(object, mesh); });
    if (watertight.IsWatertight()) {
      ReportVolume(TrueVolume(object), watertight, unseen_share, out, &report);
    }
  }
  if (!gt_dir.empty()) {
    const PairwiseError pairwise = ContactPairwiseError(gt_dir, trajectory);
    print("pairwise registration error at the fingertips: %.2f ± %.2f mm (median %.2f, %d)\n",
          pairwise.mean_mm, pairwise.std_mm, pairwise.median_mm, pairwise.samples);
    report["pairwise_error_mm"] = {{"mean", pairwise.mean_mm},
                                   {"std", pairwise.std_mm},
                                   {"median", pairwise.median_mm},
                                   {"samples", pairwise.samples}};
    const TrajectoryError drift = CompareTrajectory(gt_dir, trajectory);
    print("object trajectory error: %.2f mm mean, %.2f mm max, %.2f mm at the end\n", drift.mean_mm,
          drift.max_mm, drift.final_mm);
    print(
        "object rotation error: %.2f° mean, %.2f° max, %.2f° at the end; turned %.1f° of the "
        "truth's %.1f°\n",
        drift.rotation_mean_deg, drift.rotation_max_deg, drift.rotation_final_deg,
        drift.scan_turned_deg, drift.truth_turned_deg);
    print(
        "while the truth stood still (%d steps): turned %.1f° about the truth's turn axis (back "
        "where negative), %.1f° in all\n",
        drift.still_steps, drift.scan_turned_still_deg, drift.scan_wandered_still_deg);
    report["trajectory_error_mm"] = {
        {"mean", drift.mean_mm}, {"max", drift.max_mm}, {"final", drift.final_mm}};
    report["rotation_error_deg"] = {{"mean", drift.rotation_mean_deg},
                                    {"max", drift.rotation_max_deg},
                                    {"final", drift.rotation_final_deg}};
    report["turned_deg"] = {{"truth", drift.truth_turned_deg},
                            {"scan", drift.scan_turned_deg},
                            {"still_steps", drift.still_steps},
                            {"scan_while_still", drift.scan_turned_still_deg},
                            {"scan_wandered_while_still", drift.scan_wandered_still_deg}};
    const fusion::SurfaceComparison surface = CompareWithTruth(gt_dir, seen, trajectory);
    print(
        "surface: Chamfer %.2f mm (scan→truth %.2f, truth→scan %.2f), completeness %.1f %% "
        "(within %.1f mm)\n",
        surface.chamfer_mm, surface.scan_to_truth_mm, surface.truth_to_scan_mm,
        100 * surface.completeness, surface.within_mm);
    report["chamfer_mm"] = surface.chamfer_mm;
    report["completeness"] = surface.completeness;
    report["completeness_within_mm"] = surface.within_mm;
  }
  return report;
}

}  // namespace ihs::eval
