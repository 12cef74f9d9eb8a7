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

#include "app/scan_stages.h"
#include "app/scanner_options.h"
#include "app/sequential_scan.h"
#include "core/allocator.h"
#include "core/atomic_file.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "core/trajectory_io.h"
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

struct Args {
  std::string input, out, gt, template_name = "procedural";
  bool init_from_gt = false, left_hand = false;
  double hand_scale = 0.0;  // The template's scale, or 0 to estimate it over the first frames.
  // `tracker.NAME=VALUE` settings of inhandscan's options (`inhandscan config`).
  std::vector<std::string> assignments;
};

// The scanner's options with the flags and the tracker.* assignments: only the tracker's group
// is registered, other names are unknown here.
ihs::app::ScannerOptions OptionsFrom(const Args& args) {
  ihs::app::ScannerOptions options;
  options.scan.hand_template = args.template_name;
  options.scan.hand_scale = args.hand_scale;
  options.scan.left_hand = args.left_hand;
  ihs::app::OptionRegistry registry;
  ihs::app::AddTrackerOptions(registry, &options.tracker);
  for (const std::string& assignment : args.assignments) registry.SetAssignment(assignment);
  options.Check();
  return options;
}

// The ground truth of a generated sequence, when given.
struct Truth {
  bool given = false;  // --gt
  std::vector<ihs::tracker::HandJointsRow> joints;
  std::vector<ihs::StampedPose> trajectory;
};

Truth ReadTruth(const Args& args) {
  Truth truth;
  if (!args.gt.empty()) {
    truth.given = true;
    truth.joints = ihs::tracker::ReadHandJointsCsv(fs::path(args.gt) / "hand_joints.csv");
    truth.trajectory = ihs::ReadTumTrajectory(fs::path(args.gt) / "trajectory.txt");
  } else if (args.init_from_gt) {
    throw std::invalid_argument("--init-from-gt needs --gt");
  }
  if (args.init_from_gt && truth.joints.empty()) {
    throw ihs::InputError(args.gt + ": no ground-truth joints");
  }
  return truth;
}

// Per frame: the tracker's status, times, fit, contacts and errors against the truth.
class TrackLog {
 public:
  TrackLog(const HandModel& model, const Truth& truth) : model_(model), truth_(truth) {}

  void Add(std::int64_t index, const TrackResult& result) {
    ++counts_[ihs::tracker::ToString(result.status)];
    milliseconds_.push_back(result.milliseconds);
    nlohmann::json entry = {{"frame", index},
                            {"status", ihs::tracker::ToString(result.status)},
                            {"ms", result.milliseconds},
                            {"segmentation_ms", result.segmentation_ms},
                            {"fit_ms", result.fit_ms},
                            {"contacts_ms", result.contacts_ms}};
    stage_ms_[0] += result.segmentation_ms, stage_ms_[1] += result.fit_ms,
        stage_ms_[2] += result.contacts_ms;
    if (!result.reason.empty()) entry["reason"] = result.reason;
    if (result.doubtful) entry["doubtful"] = true, ++doubtful_;
    if (!result.joints_mm.empty()) {
      entry["data_coverage"] = result.fit.data_coverage;
      entry["model_coverage"] = result.fit.model_coverage;
      entry["data_error_mm"] = result.fit.data_error_mm;
      joints_.push_back({index, result.joints_mm});
    }
    AddContacts(index, result);
    AddErrors(index, result, entry);
    frames_.push_back(entry);
  }

  // hand_joints.csv, contacts.csv and stats.json in `out`; the summary on stdout.
  void Write(const fs::path& out, const ihs::app::HandStage& hand, bool scale_estimated) const {
    std::vector<std::string> names;
    for (const auto& bone : model_.bones) names.push_back(bone.name);
    ihs::tracker::WriteHandJointsCsv(out / "hand_joints.csv", names, joints_);
    ihs::WriteFileAtomically(out / "contacts.csv", contacts_csv_);
    const nlohmann::json summary = Summary(hand, scale_estimated);
    ihs::WriteFileAtomically(
        out / "stats.json",
        nlohmann::json{{"summary", summary}, {"frames", frames_}}.dump(1) + "\n");
    Print(summary, hand, scale_estimated);
  }

 private:
  void AddContacts(std::int64_t index, const TrackResult& result) {
    std::string bones;
    for (int bone : result.contacts.bones)
      bones += (bones.empty() ? "" : " ") + model_.bones[bone].name;
    char line[256];
    std::snprintf(line, sizeof line, "%lld,%s,%s,%zu,%.1f\n", static_cast<long long>(index),
                  ihs::tracker::ToString(result.status), bones.c_str(),
                  result.contacts.vertices.size(), result.contacts.threshold_mm);
    contacts_csv_ += line;
  }

  // Against the ground truth: joints, and contact pairs moved by the object's true motion.
  void AddErrors(std::int64_t index, const TrackResult& result, nlohmann::json& entry) {
    if (!truth_.joints.empty() && index < static_cast<std::int64_t>(truth_.joints.size()) &&
        !result.joints_mm.empty()) {
      const auto& truth = truth_.joints[index].joints_mm;
      joint_errors_.push_back(ihs::tracker::MeanJointError(result.joints_mm, truth));
      entry["joint_error_mm"] = joint_errors_.back();
      const ihs::tracker::HandSides sides =
          ihs::tracker::CompareHandSides(model_, result.joints_mm, truth);
      if (sides.turned_over()) entry["turned_over"] = true, ++turned_over_;
      if (sides.palm_reversed) entry["palm_reversed"] = true, ++palm_reversed_;
    }
    if (index > 0 && index < static_cast<std::int64_t>(truth_.trajectory.size())) {
      const ihs::Rigid3 motion =
          truth_.trajectory[index].transform * truth_.trajectory[index - 1].transform.Inverse();
      std::vector<double> errors;
      for (const auto& pair : result.contact_pairs) {
        errors.push_back((motion * pair.previous_mm - pair.current_mm).norm());
      }
      if (!errors.empty()) entry["contact_error_mm"] = Quantile(errors, 0.5);
      contact_errors_.insert(contact_errors_.end(), errors.begin(), errors.end());
    }
  }

  nlohmann::json Summary(const ihs::app::HandStage& hand, bool scale_estimated) const {
    const auto frames = static_cast<double>(frames_.size());
    double total_ms = 0;
    for (double ms : milliseconds_) total_ms += ms;
    nlohmann::json summary = {{"frames", frames_.size()},
                              {"hand_scale", hand.scale()},
                              {"hand_scale_estimated", scale_estimated},
                              {"hand_scale_at_bound", hand.scale_at_bound()},
                              {"status_counts", counts_},
                              {"doubtful_frames", doubtful_},
                              {"ms_mean", total_ms / frames},
                              {"ms_p95", Quantile(milliseconds_, 0.95)},
                              {"segmentation_ms_mean", stage_ms_[0] / frames},
                              {"fit_ms_mean", stage_ms_[1] / frames},
                              {"contacts_ms_mean", stage_ms_[2] / frames}};
    if (!joint_errors_.empty()) {
      double sum = 0;
      for (double e : joint_errors_) sum += e;
      summary["joint_error_mm_mean"] = sum / joint_errors_.size();
      summary["joint_error_mm_p95"] = Quantile(joint_errors_, 0.95);
      summary["turned_over_frames"] = turned_over_;
      summary["palm_reversed_frames"] = palm_reversed_;
    }
    if (!contact_errors_.empty()) {
      summary["contact_error_mm_median"] = Quantile(contact_errors_, 0.5);
      summary["contact_pairs"] = contact_errors_.size();
    }
    return summary;
  }

  void Print(const nlohmann::json& summary, const ihs::app::HandStage& hand,
             bool scale_estimated) const {
    auto count = [&](const char* status) {
      const auto found = counts_.find(status);
      return found == counts_.end() ? 0 : found->second;
    };
    std::printf(
        "frames %zu: tracked %d, initialised %d, diverged %d, no hand %d, empty %d; doubtful %d\n",
        frames_.size(), count("tracked"), count("initialised"), count("diverged"), count("no_hand"),
        count("empty_frame"), doubtful_);
    std::printf("hand scale: %.3f (%s)\n", summary["hand_scale"].get<double>(),
                !scale_estimated        ? "given"
                : hand.scale_at_bound() ? "estimated over the first frames, on a bound of its range"
                                        : "estimated over the first frames");
    std::printf(
        "time per frame: %.1f ms mean, %.1f ms p95 (one thread; a search on every core); "
        "segmentation %.1f, fit %.1f, "
        "contacts %.1f ms\n",
        summary["ms_mean"].get<double>(), summary["ms_p95"].get<double>(),
        summary["segmentation_ms_mean"].get<double>(), summary["fit_ms_mean"].get<double>(),
        summary["contacts_ms_mean"].get<double>());
    if (!joint_errors_.empty()) {
      std::printf(
          "joint error: %.2f mm mean, %.2f mm p95 over %zu frames; turned over in %d (palm for "
          "back in %d, the others' thumb tip nearer the true little fingertip)\n",
          summary["joint_error_mm_mean"].get<double>(), Quantile(joint_errors_, 0.95),
          joint_errors_.size(), turned_over_, palm_reversed_);
    }
    if (!contact_errors_.empty()) {
      std::printf("contact error: %.2f mm median over %zu contact pairs\n",
                  Quantile(contact_errors_, 0.5), contact_errors_.size());
    } else if (truth_.given) {
      std::printf("contact error: no contact pairs\n");
    }
  }

  const HandModel& model_;
  const Truth& truth_;
  std::vector<ihs::tracker::HandJointsRow> joints_;
  std::string contacts_csv_ = "frame,status,contact_bones,contact_vertices,threshold_mm\n";
  nlohmann::json frames_ = nlohmann::json::array();
  std::map<std::string, int> counts_;
  int doubtful_ = 0;  // Frames whose pose was doubtful.
  // Frames fitted turned over against the truth (CompareHandSides), and palm for back.
  int turned_over_ = 0, palm_reversed_ = 0;
  std::vector<double> joint_errors_, contact_errors_, milliseconds_;
  double stage_ms_[3] = {0, 0, 0};
};

int Run(const Args& args) {
  const ihs::app::ScannerOptions options = OptionsFrom(args);
  const Truth truth = ReadTruth(args);
  ihs::app::SequentialOptions run;
  if (args.init_from_gt) run.first_joints_mm = truth.joints.front().joints_mm;
  ihs::app::SequentialScan scan(args.input, run);
  ihs::app::HandStage hand(options, scan.intrinsics());
  const fs::path out = args.out;
  std::error_code error;
  fs::create_directories(out, error);
  if (error) throw ihs::OutputError(out.string() + ": cannot create (" + error.message() + ")");

  TrackLog log(hand.model(), truth);
  std::int64_t index = 0;
  scan.Run(hand, [&](ihs::app::FramePacket& packet) { log.Add(index++, packet.track); });
  // The procedural template's size is estimated unless given; a scanned hand has its owner's.
  log.Write(out, hand, ihs::app::TrackerOptionsFor(options).scale_frames > 0);
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  ihs::KeepFreedMemoryForReuse();
  CLI::App app{"Track the hand through a recording: joints, contacts, statistics.",
               "inhandscan-track"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-track ") + IHS_VERSION);
  Args args;
  std::string log_level = "info";
  bool quiet = false;
  app.add_option("input", args.input, ".oni file or TUM folder")->required();
  app.add_option("--out", args.out, "output folder")->required();
  app.add_option("--gt", args.gt, "a generator's gt/ folder: measure joint and contact errors");
  app.add_flag("--init-from-gt", args.init_from_gt, "start from the ground truth's first pose");
  app.add_option("--template", args.template_name, "procedural, or the real hand data folder")
      ->capture_default_str();
  app.add_option("--hand-scale", args.hand_scale,
                 "scale of the template (default: the procedural one estimated over the first "
                 "frames, a scanned one 1)")
      ->check(CLI::Range(0.5, 2.0));
  app.add_flag("--left-hand", args.left_hand,
               "the hand is a left one (the procedural template is mirrored; a scanned one must "
               "be a left hand)");
  app.add_option("--set", args.assignments,
                 "set one of the tracker's options: tracker.NAME=VALUE (repeatable; `inhandscan "
                 "config` lists them)");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  return ihs::RunReportingErrors("inhandscan-track", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return Run(args);
  });
}
