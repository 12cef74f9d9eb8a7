// inhandscan-track: runs the hand tracker (segmentation, pose fit, contacts) over a recording and
// writes the hand's joints, its contacts and per-frame statistics; with --gt (a generator's gt/
// folder) it also measures the joint error and the contact error.

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/scanner_options.h"
#include "core/allocator.h"
#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "core/trajectory_io.h"
#include "sensor/open_input.h"
#include "tracker/hand_data.h"
#include "tracker/hand_joints_io.h"
#include "tracker/hand_tracker.h"

namespace {

namespace fs = std::filesystem;
using ihs::tracker::HandModel;
using ihs::tracker::TrackResult;

double Quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * (values.size() - 1))];
}

// hand_scale: the template's scale, or 0 to estimate it over the first frames.
// assignments: `tracker.NAME=VALUE` settings of inhandscan's options (`inhandscan config`).
int Run(const std::string& input, const fs::path& out, const std::string& gt_dir, bool init_from_gt,
        const std::string& template_name, double hand_scale, bool left_hand,
        const std::vector<std::string>& assignments) {
  HandModel model = ihs::tracker::LoadHandTemplate(template_name, !left_hand);
  ihs::app::ScannerOptions scanner;
  ihs::app::OptionRegistry registry = ihs::app::RegisterScannerOptions(&scanner);
  for (const std::string& assignment : assignments) {
    if (assignment.rfind("tracker.", 0) != 0) {
      throw std::invalid_argument("--set " + assignment +
                                  ": inhandscan-track takes only tracker.* options");
    }
    registry.SetAssignment(assignment);
  }
  ihs::tracker::TrackerOptions options = scanner.tracker;
  // The procedural template's size is estimated unless given; a scanned hand has its owner's.
  if (hand_scale > 0) model = model.Scaled(hand_scale);
  if (hand_scale > 0 || template_name != "procedural") options.scale_frames = 0;
  // Ground truth: joints per frame and the object's trajectory.
  std::vector<ihs::tracker::HandJointsRow> gt_joints;
  std::vector<ihs::StampedPose> gt_trajectory;
  if (!gt_dir.empty()) {
    gt_joints = ihs::tracker::ReadHandJointsCsv(fs::path(gt_dir) / "hand_joints.csv");
    gt_trajectory = ihs::ReadTumTrajectory(fs::path(gt_dir) / "trajectory.txt");
  } else if (init_from_gt) {
    throw std::invalid_argument("--init-from-gt needs --gt");
  }

  auto source = ihs::sensor::OpenInput(input);
  source->Start();
  ihs::tracker::HandTracker tracker(model, source->Intrinsics(), options);
  std::error_code error;
  fs::create_directories(out, error);
  if (error) throw ihs::OutputError(out.string() + ": cannot create (" + error.message() + ")");

  std::vector<ihs::tracker::HandJointsRow> joints;
  std::string contacts_csv = "frame,status,contact_bones,contact_vertices,threshold_mm\n";
  nlohmann::json frames = nlohmann::json::array();
  std::map<std::string, int> counts;
  int doubtful = 0;  // Frames whose pose was doubtful.
  std::vector<double> joint_errors, contact_errors, milliseconds;
  double stage_ms[3] = {0, 0, 0};
  std::int64_t index = 0;
  while (true) {
    const ihs::sensor::SourceRead read = source->Next(std::chrono::seconds(5));
    if (read.status == ihs::sensor::SourceStatus::kTimeout) continue;
    if (read.status != ihs::sensor::SourceStatus::kFrame) break;
    const ihs::Frame& frame = *read.frame;
    if (index == 0 && init_from_gt) {
      if (gt_joints.empty()) throw ihs::InputError(gt_dir + ": no ground-truth joints");
      tracker.Initialise(ihs::tracker::FitPoseToJoints(model, gt_joints.front().joints_mm));
    }
    const TrackResult result = tracker.Track(frame);
    ++counts[ihs::tracker::ToString(result.status)];
    milliseconds.push_back(result.milliseconds);
    nlohmann::json entry = {{"frame", index},
                            {"status", ihs::tracker::ToString(result.status)},
                            {"ms", result.milliseconds},
                            {"segmentation_ms", result.segmentation_ms},
                            {"fit_ms", result.fit_ms},
                            {"contacts_ms", result.contacts_ms}};
    stage_ms[0] += result.segmentation_ms, stage_ms[1] += result.fit_ms,
        stage_ms[2] += result.contacts_ms;
    if (!result.reason.empty()) entry["reason"] = result.reason;
    if (result.doubtful) entry["doubtful"] = true, ++doubtful;
    if (!result.joints_mm.empty()) {
      entry["data_coverage"] = result.fit.data_coverage;
      entry["model_coverage"] = result.fit.model_coverage;
      entry["data_error_mm"] = result.fit.data_error_mm;
      joints.push_back({index, result.joints_mm});
    }
    std::string bones;
    for (int bone : result.contacts.bones)
      bones += (bones.empty() ? "" : " ") + model.bones[bone].name;
    char line[256];
    std::snprintf(line, sizeof line, "%lld,%s,%s,%zu,%.1f\n", static_cast<long long>(index),
                  ihs::tracker::ToString(result.status), bones.c_str(),
                  result.contacts.vertices.size(), result.contacts.threshold_mm);
    contacts_csv += line;
    // Against the ground truth: joints, and contact pairs moved by the object's true motion.
    if (!gt_joints.empty() && index < static_cast<std::int64_t>(gt_joints.size()) &&
        !result.joints_mm.empty()) {
      joint_errors.push_back(
          ihs::tracker::MeanJointError(result.joints_mm, gt_joints[index].joints_mm));
      entry["joint_error_mm"] = joint_errors.back();
    }
    if (index > 0 && index < static_cast<std::int64_t>(gt_trajectory.size())) {
      const ihs::Rigid3 motion =
          gt_trajectory[index].transform * gt_trajectory[index - 1].transform.Inverse();
      std::vector<double> errors;
      for (const auto& pair : result.contact_pairs) {
        errors.push_back((motion * pair.previous_mm - pair.current_mm).norm());
      }
      if (!errors.empty()) entry["contact_error_mm"] = Quantile(errors, 0.5);
      contact_errors.insert(contact_errors.end(), errors.begin(), errors.end());
    }
    frames.push_back(entry);
    ++index;
  }
  if (index == 0) throw ihs::InputError(input + ": no frames");

  std::vector<std::string> names;
  for (const auto& bone : model.bones) names.push_back(bone.name);
  ihs::tracker::WriteHandJointsCsv(out / "hand_joints.csv", names, joints);
  ihs::WriteFileAtomically(out / "contacts.csv", contacts_csv);
  double total_ms = 0;
  for (double ms : milliseconds) total_ms += ms;
  nlohmann::json summary = {{"frames", index},
                            {"hand_scale", tracker.scale() * (hand_scale > 0 ? hand_scale : 1.0)},
                            {"hand_scale_estimated", options.scale_frames > 0},
                            {"hand_scale_at_bound", tracker.scale_at_bound()},
                            {"status_counts", counts},
                            {"doubtful_frames", doubtful},
                            {"ms_mean", total_ms / index},
                            {"ms_p95", Quantile(milliseconds, 0.95)},
                            {"segmentation_ms_mean", stage_ms[0] / index},
                            {"fit_ms_mean", stage_ms[1] / index},
                            {"contacts_ms_mean", stage_ms[2] / index}};
  if (!joint_errors.empty()) {
    double sum = 0;
    for (double e : joint_errors) sum += e;
    summary["joint_error_mm_mean"] = sum / joint_errors.size();
    summary["joint_error_mm_p95"] = Quantile(joint_errors, 0.95);
  }
  if (!contact_errors.empty()) {
    summary["contact_error_mm_median"] = Quantile(contact_errors, 0.5);
    summary["contact_pairs"] = contact_errors.size();
  }
  ihs::WriteFileAtomically(out / "stats.json",
                           nlohmann::json{{"summary", summary}, {"frames", frames}}.dump(1) + "\n");
  std::printf(
      "frames %lld: tracked %d, initialised %d, diverged %d, no hand %d, empty %d; doubtful %d\n",
      static_cast<long long>(index), counts["tracked"], counts["initialised"], counts["diverged"],
      counts["no_hand"], counts["empty_frame"], doubtful);
  std::printf("hand scale: %.3f (%s)\n", summary["hand_scale"].get<double>(),
              options.scale_frames == 0    ? "given"
              : tracker.scale_at_bound() ? "estimated over the first frames, on a bound of its range"
                                         : "estimated over the first frames");
  std::printf(
      "time per frame: %.1f ms mean, %.1f ms p95 (one core); segmentation %.1f, fit %.1f, "
      "contacts %.1f ms\n",
      total_ms / index, Quantile(milliseconds, 0.95), stage_ms[0] / index, stage_ms[1] / index,
      stage_ms[2] / index);
  if (!joint_errors.empty()) {
    std::printf("joint error: %.2f mm mean, %.2f mm p95 over %zu frames\n",
                summary["joint_error_mm_mean"].get<double>(), Quantile(joint_errors, 0.95),
                joint_errors.size());
  }
  if (!contact_errors.empty()) {
    std::printf("contact error: %.2f mm median over %zu contact pairs\n",
                Quantile(contact_errors, 0.5), contact_errors.size());
  } else if (!gt_dir.empty()) {
    std::printf("contact error: no contact pairs\n");
  }
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  ihs::KeepFreedMemoryForReuse();
  CLI::App app{"Track the hand through a recording: joints, contacts, statistics.",
               "inhandscan-track"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-track ") + IHS_VERSION);
  std::string input, out, gt, template_name = "procedural", log_level = "info";
  bool init_from_gt = false, left_hand = false, quiet = false;
  double hand_scale = 0.0;
  app.add_option("input", input, ".oni file or TUM folder")->required();
  app.add_option("--out", out, "output folder")->required();
  app.add_option("--gt", gt, "a generator's gt/ folder: measure joint and contact errors");
  app.add_flag("--init-from-gt", init_from_gt, "start from the ground truth's first pose");
  app.add_option("--template", template_name, "procedural, or the real hand data folder")
      ->capture_default_str();
  app.add_option("--hand-scale", hand_scale,
                 "scale of the template (default: the procedural one estimated over the first "
                 "frames, a scanned one 1)")
      ->check(CLI::Range(0.5, 2.0));
  app.add_flag("--left-hand", left_hand,
               "the hand is a left one (the procedural template is mirrored; a scanned one must "
               "be a left hand)");
  std::vector<std::string> assignments;
  app.add_option("--set", assignments,
                 "set one of the tracker's options: tracker.NAME=VALUE (repeatable; `inhandscan "
                 "config` lists them)");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-track", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return Run(input, out, gt, init_from_gt, template_name, hand_scale, left_hand, assignments);
  });
}
