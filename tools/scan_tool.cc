// inhandscan-scan: the scanner's stages one after the other, no threads: source → hand tracker →
// object mask without the hand → SIFT matches and fingertip contacts → fusion (registration,
// ICP, TSDF) → meshes, with the application's stage objects (app/scan_stages.h). Writes the
// watertight mesh, the TSDF's own mesh, the object's trajectory, the hand's joints and per-frame
// statistics; with --gt (a generator's gt/ folder) it also prints the paper's Table 1 and Table 2
// measures and the surface's Chamfer distance. The application (inhandscan) runs the same stage
// objects threaded; this is the reference and the baselines' harness (--gamma-t 0, --contacts-only,
// --no-icp), and starts the hand from the ground truth when asked (--init-from-gt).

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "app/run_record.h"
#include "app/scan_export.h"
#include "app/scan_record.h"
#include "app/scan_stages.h"
#include "app/scanner_options.h"
#include "app/sequential_scan.h"
#include "core/allocator.h"
#include "core/command_line.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "core/stopwatch.h"
#include "tools/evaluation.h"
#include "tracker/hand_joints_io.h"

namespace {

namespace fs = std::filesystem;
struct Args {
  std::string input, out, gt, object, template_name = "procedural";
  bool init_from_gt = false, no_icp = false, contacts_only = false, no_color = false;
  bool no_anchors = false, features_3d = false, left_hand = false;
  double hand_scale = 0, gamma_t = 15.0;
  int hand_dilation_px = 4;
  std::int64_t max_frames = 0;
  std::vector<std::string> assignments;  // --set NAME=VALUE, applied after the flags above.
};

// The scanner's options from the flags, then the --set assignments.
ihs::app::ScannerOptions OptionsFrom(const Args& args) {
  ihs::app::ScannerOptions options;
  options.scan.hand_template = args.template_name;
  options.scan.hand_scale = args.hand_scale;
  options.scan.left_hand = args.left_hand;
  options.scan.hand_dilation_px = args.hand_dilation_px;
  options.scan.features_2d = !args.contacts_only;
  options.scan.features_3d = args.features_3d && !args.contacts_only;
  options.fusion.pairwise.contact_weight = args.gamma_t;
  if (args.contacts_only) options.fusion.pairwise.visual_weight = 0;
  options.fusion.use_icp = !args.no_icp;
  options.fusion.anchor_contacts = !args.no_anchors;
  options.fusion.tsdf.color = !args.no_color;
  options.meshing.color = !args.no_color;
  ihs::app::OptionRegistry registry = ihs::app::RegisterScannerOptions(&options);
  for (const std::string& assignment : args.assignments) registry.SetAssignment(assignment);
  options.Check();
  return options;
}

// The sequential run's options: --frames, and the hand's first pose from the ground truth.
ihs::app::SequentialOptions RunOptionsFrom(const Args& args) {
  ihs::app::SequentialOptions run;
  run.max_frames = args.max_frames;
  if (args.init_from_gt) {
    if (args.gt.empty()) throw std::invalid_argument("--init-from-gt needs --gt");
    const auto gt_joints = ihs::tracker::ReadHandJointsCsv(fs::path(args.gt) / "hand_joints.csv");
    if (gt_joints.empty()) throw ihs::InputError(args.gt + ": no ground-truth joints");
    run.first_joints_mm = gt_joints.front().joints_mm;
  }
  return run;
}

// What was scanned: --object, or the ground truth manifest's object.
std::string ObjectFrom(const Args& args) {
  if (!args.object.empty() || args.gt.empty()) return args.object;
  std::ifstream manifest(fs::path(args.gt) / "manifest.json");
  if (!manifest) throw ihs::InputError(args.gt + "/manifest.json: cannot read");
  return nlohmann::json::parse(manifest, nullptr, false)
      .value("object", nlohmann::json::object())
      .value("spec", "");
}

// The output folder, created, without an earlier scan's files.
void PrepareOutput(const fs::path& out) {
  std::error_code error;
  fs::create_directories(out, error);
  if (error) throw ihs::OutputError(out.string() + ": cannot create (" + error.message() + ")");
  if (const int removed = ihs::app::RemovePreviousScan(out)) {
    spdlog::info("{}: removed {} files of an earlier scan", out.string(), removed);
  }
}

// The meshes' export times and measures for stats.json.
nlohmann::json MeshSummary(const ihs::fusion::MeshingResult& meshes, double export_ms,
                           double marching_cubes_ms) {
  return {{"export_ms",
           {{"total", export_ms},
            {"marching_cubes", marching_cubes_ms},
            {"cleanup", meshes.cleanup_ms},
            {"smoothing", meshes.smoothing_ms},
            {"poisson", meshes.poisson_ms},
            {"bound", meshes.bound_ms},
            {"repair", meshes.repair_ms}}},
          {"mesh",
           {{"faces", meshes.watertight.faces.size()},
            {"watertight", meshes.IsWatertight()},
            {"self_intersections", meshes.self_intersections},
            {"self_intersections_repaired", meshes.repaired_intersections},
            {"unseen_share", meshes.unseen_share},
            {"cut_share", meshes.cut_share},
            {"hull_cut_share", meshes.hull_cut_share},
            {"hull_revolved", meshes.hull_shape == ihs::fusion::HullShape::kRevolved},
            {"hull_box", meshes.hull_shape == ihs::fusion::HullShape::kBox},
            {"volume_mm3", meshes.watertight.IsWatertight() ? meshes.watertight.Volume() : 0.0}}}};
}

// The run's lines on stdout: frames, time per stage, export, mesh and coverage.
void PrintSummary(std::int64_t frames, const ihs::app::ScanRecord& record,
                  const nlohmann::json& summary, const ihs::fusion::MeshingResult& meshes,
                  double export_ms, double marching_cubes_ms, const fs::path& out) {
  auto count = [](const nlohmann::json& counts, const char* key) {
    return counts.contains(key) ? counts[key].get<int>() : 0;
  };
  const auto& fusion_counts = summary["fusion_status_counts"];
  std::printf("frames %lld: registered %lld (started %d, fused %d, skipped %d)\n",
              static_cast<long long>(frames), static_cast<long long>(record.registered()),
              count(fusion_counts, "started"), count(fusion_counts, "fused"),
              count(fusion_counts, "skipped"));
  for (const auto& [reason, n] : record.skip_reasons())
    std::printf("  skipped: %s × %lld\n", reason.c_str(), static_cast<long long>(n));
  if (const int slid = count(summary, "icp_slid_frames"); slid > 0)
    std::printf("  ICP slid off what it started on in %d frames: its best-paired iterate kept\n",
                slid);
  if (const int loops = count(summary, "loops"); loops > 0) {
    std::printf(
        "  loop closure: %d keyframes, %d loops with earlier ones, the drift corrected %d "
        "times\n",
        count(summary, "keyframes"), loops, count(summary, "loop_corrections"));
  }
  if (const double alias = summary.value("keypoint_alias_deg", 0.0); alias > 0) {
    std::printf(
        "  registrations by keypoints were seen %.0f° off (a pattern that repeats, or a drift "
        "past the gate): loops by keypoints kept within half of that\n",
        alias);
  }
  if (const int carried = count(summary, "hand_carried_frames"),
      back = count(summary, "hand_back_frames"),
      undecided = count(summary, "hand_undecided_frames");
      carried + back + undecided > 0) {
    std::printf(
        "  the object turned one way: the hand carried its free turn in %d frames, turned back "
        "without it in %d, left it to the contacts in %d; %.0f° missed before the turn was "
        "recognised caught up\n",
        carried, back, undecided,
        summary.contains("hand_caught_up_deg") ? summary["hand_caught_up_deg"].get<double>() : 0.0);
  }
  if (const int aligned = count(summary, "colour_aligned_frames"); aligned > 0) {
    std::printf(
        "  the colours aligned %d frames along the turns the surface leaves free; in %d they "
        "kept the object standing still against the turn the registration gave it\n",
        aligned, count(summary, "colour_still_frames"));
  }
  if (const int hidden = count(summary, "hidden_frames"); hidden > 0) {
    std::printf("  %d frames showed the object mostly hidden behind the hand: tracked, not fused\n",
                hidden);
  }
  if (const int moved = count(summary, "see_through_moved_frames"),
      held = count(summary, "see_through_held_frames");
      moved + held > 0) {
    std::printf(
        "  %d frames saw through the model at their registered pose and were moved onto the "
        "object's points; %d still did: tracked, not fused\n",
        moved, held);
  }
  if (const int jumps = count(summary, "jumps_taken"); jumps > 0) {
    std::printf(
        "  %d times the object was found far from where it was, frames in a row: taken as "
        "having moved there unseen\n",
        jumps);
  }
  const auto& ms = summary["ms_per_frame"];
  auto mean = [&](const char* key) { return ms.contains(key) ? ms[key].get<double>() : 0.0; };
  std::printf(
      "ms per frame (one thread; a hand search on every core): track %.1f, mask %.1f, features "
      "%.1f, fusion %.1f (pairwise %.2f, "
      "raycast %.1f, ICP %.1f, integrate %.1f)\n",
      mean("track"), mean("mask"), mean("features"), mean("fusion"), mean("pairwise"),
      mean("raycast"), mean("icp"), mean("integrate"));
  std::printf(
      "export: %.0f ms (marching cubes %.0f, cleanup %.0f, smoothing %.0f, Poisson %.0f, bound "
      "%.0f)\n",
      export_ms, marching_cubes_ms, meshes.cleanup_ms, meshes.smoothing_ms, meshes.poisson_ms,
      meshes.bound_ms);
  std::printf("mesh: %s (%zu faces, %s)\n", (out / "mesh.ply").c_str(),
              meshes.watertight.faces.size(),
              meshes.IsWatertight()              ? "watertight"
              : meshes.watertight.IsWatertight() ? "closed but crossing itself: NOT watertight"
                                                 : "NOT watertight");
  if (meshes.repaired_intersections > 0) {
    std::printf(
        "repaired: Poisson's mesh crossed itself (%lld pairs of faces); re-made from its "
        "signed distance without them (%.0f ms)\n",
        static_cast<long long>(meshes.repaired_intersections), meshes.repair_ms);
  }
  std::printf(
      "coverage: seen from %.1f %% of the directions around it, %.1f %% of the "
      "watertight mesh never seen\n",
      100 * record.coverage(), 100 * meshes.unseen_share);
  if (meshes.cut_share > 0) {
    std::printf(
        "closure: %.1f %% of Poisson's volume cut away where the views saw empty space "
        "(%.1f %%) or beyond the seen surface's convex hull%s (%.1f %%)\n",
        100 * meshes.cut_share, 100 * (meshes.cut_share - meshes.hull_cut_share),
        meshes.hull_shape == ihs::fusion::HullShape::kRevolved ? " (turned all round its axis)"
        : meshes.hull_shape == ihs::fusion::HullShape::kBox    ? " (the box along its faces)"
                                                               : "",
        100 * meshes.hull_cut_share);
  }
}

// The fingers of the tracker's contact bones in this frame (what the evaluation judges the
// frame's contacts by).
std::vector<int> ContactFingers(const ihs::tracker::HandModel& model,
                                const ihs::tracker::Contacts& contacts) {
  std::vector<int> fingers;
  for (int bone : contacts.bones) {
    if (const int finger = model.FingerOf(bone); finger >= 0) fingers.push_back(finger);
  }
  return fingers;
}

// The scan against the ground truth (printed; returned for stats.json): the paper's measures
// and the surface's distances, what the recording showed, and how the contacts were used where
// the truth grasps.
nlohmann::json Evaluate(const Args& args, const std::string& object,
                        const ihs::app::ScanRecord& record,
                        const ihs::fusion::MeshingResult& meshes,
                        const std::vector<ihs::eval::FrameContactUse>& contact_use,
                        const ihs::eval::ShownSurface& shown) {
  // Dimensions and distances on the surface that was seen (the TSDF's, smoothed); Poisson's
  // closing of what was never seen (a base under the hand) is guesswork that would add to a
  // bottle's height. The volume needs the watertight mesh.
  nlohmann::json evaluation =
      ihs::eval::ReportScan(object, meshes.smoothed, meshes.watertight, args.gt,
                            record.trajectory(), meshes.unseen_share);
  // The completeness perfect registration would reach: what the frames showed at all.
  const double shown_share = shown.Share(evaluation.value("completeness_within_mm", 2.0));
  std::printf(
      "the recording showed %.1f %% of the true surface (the completeness a scan can reach)\n",
      100 * shown_share);
  evaluation["shown_share"] = shown_share;
  const ihs::eval::ContactUse use = ihs::eval::CompareContactUse(args.gt, contact_use);
  std::printf(
      "contacts used in %d of %d frames where the truth grasps (%.0f %%); %d of %d frames with "
      "contacts used had no fingertip within 3 mm (%.0f %%)\n",
      use.used_in_grasp, use.grasp_frames, 100 * use.recall, use.false_frames, use.used_frames,
      100 * use.false_share);
  // Contacts are found only where the fitted fingertips are near the object: how near they were.
  const ihs::eval::GraspTips tips =
      ihs::eval::CompareGraspTips(args.gt, fs::path(args.out) / "hand_joints.csv");
  std::printf(
      "fitted fingertips where the truth grasps: two touching ones within 6 / 10 / 15 mm of the "
      "true ones in %.0f / %.0f / %.0f %% of those %d frames\n",
      100 * tips.share[0], 100 * tips.share[1], 100 * tips.share[2], tips.grasp_frames);
  evaluation["grasp_tips"] = {
      {"grasp_frames", tips.grasp_frames}, {"within_mm", tips.within_mm}, {"share", tips.share}};
  evaluation["contacts"] = {{"grasp_frames", use.grasp_frames},
                            {"used_in_grasp", use.used_in_grasp},
                            {"recall", use.recall},
                            {"used_frames", use.used_frames},
                            {"false_frames", use.false_frames},
                            {"false_share", use.false_share}};
  return evaluation;
}

int Run(const Args& args) {
  const ihs::app::ScannerOptions options = OptionsFrom(args);
  const std::string object = ObjectFrom(args);
  ihs::app::SequentialScan scan(args.input, RunOptionsFrom(args));
  ihs::app::HandStage hand(options, scan.intrinsics());
  ihs::app::ObjectStage object_stage(options, scan.intrinsics());
  ihs::app::ScanRecord record(hand.BoneNames(), hand.AngleNames());
  const fs::path out = args.out;
  PrepareOutput(out);

  std::vector<ihs::eval::FrameContactUse> contact_use;
  std::optional<ihs::eval::ShownSurface> shown;
  if (!args.gt.empty()) shown.emplace(args.gt, scan.intrinsics());
  const auto run_start = ihs::SteadyClock::now();
  const std::int64_t frames = scan.Run(hand, [&](ihs::app::FramePacket& packet) {
    ihs::app::ScanObject(object_stage, record, packet);
    contact_use.push_back({packet.frame->depth_timestamp_us * 1e-6, packet.fusion.ContactsUsed(),
                           ContactFingers(hand.model(), packet.track.contacts)});
    if (shown && packet.frame) shown->Add(*packet.frame);
  });
  const double run_s = ihs::MillisecondsSince(run_start) / 1000.0;

  // Meshes.
  auto start = ihs::SteadyClock::now();
  const ihs::fusion::ModelSnapshot model = object_stage.Snapshot();
  const double marching_cubes_ms = ihs::MillisecondsSince(start);
  const ihs::app::ExportedMeshes exported = ihs::app::ExportMeshes(model, options.meshing, out);
  const double export_ms = ihs::MillisecondsSince(start);
  if (exported.files.empty()) {
    // As `inhandscan replay` ends it: code 5 and the skip reasons.
    std::fprintf(stderr, "inhandscan-scan: error: %s: %s\n", args.input.c_str(),
                 record.NothingScanned().c_str());
    return ihs::kExitStageFailed;
  }
  record.WriteTables(out);

  const nlohmann::json summary = record.Summary();
  // The options in effect (the flags and --set together), not the flags alone.
  const ihs::app::RunRecord run = ihs::app::RunRecord::Of(args.input, options);
  run.Write(out, scan.intrinsics());
  const bool visual = (options.scan.features_2d || options.scan.features_3d) &&
                      options.fusion.pairwise.visual_weight > 0;
  nlohmann::json extra = {{"hand_scale", hand.scale()},
                          {"hand_scale_at_bound", hand.scale_at_bound()},
                          {"gamma_t", options.fusion.pairwise.contact_weight},
                          {"icp", options.fusion.use_icp},
                          {"visual", visual},
                          {"seconds", run_s},
                          {"run", run.Json(scan.intrinsics())}};
  extra.update(MeshSummary(exported.meshes, export_ms, marching_cubes_ms));
  PrintSummary(frames, record, summary, exported.meshes, export_ms, marching_cubes_ms, out);
  if (!args.gt.empty()) {
    extra["evaluation"] = Evaluate(args, object, record, exported.meshes, contact_use, *shown);
  }
  record.WriteStats(out / "stats.json", extra);
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  ihs::KeepFreedMemoryForReuse();
  CLI::App app{
      "Scan an object from a recording, stage after stage (no threads): mesh, object "
      "trajectory, hand joints, statistics; with --gt the paper's measures.",
      "inhandscan-scan"};
  app.footer(ihs::ExitCodesHelp());
  app.set_version_flag("--version", std::string("inhandscan-scan ") + IHS_VERSION);
  Args args;
  std::string log_level = "info";
  bool quiet = false;
  app.add_option("input", args.input, ".oni file or TUM folder")->required();
  app.add_option("--out", args.out, "output folder")->required();
  app.add_option("--gt", args.gt, "a generator's gt/ folder: measure the scan against it");
  app.add_option("--object", args.object,
                 "what was scanned, for its dimensions (a paper object or lathe:FILE; default: "
                 "the ground truth's)")
      ->check(ihs::eval::NotABodyOfRevolution);
  app.add_flag("--init-from-gt", args.init_from_gt, "start the hand from the ground truth's pose");
  app.add_option("--template", args.template_name, "procedural, or the real hand data folder")
      ->capture_default_str();
  app.add_option("--hand-scale", args.hand_scale,
                 "scale of the template (default: the procedural one estimated over the first "
                 "frames, a scanned one 1)")
      ->check(CLI::Range(0.5, 2.0));
  app.add_flag("--left-hand", args.left_hand,
               "the hand is a left one (the procedural template is mirrored; a scanned one must "
               "be a left hand)");
  app.add_option("--gamma-t", args.gamma_t,
                 "weight of the fingertip contacts (paper: 15; 0: "
                 "visual features only)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0));
  app.add_flag("--contacts-only", args.contacts_only, "no visual features: contacts (and ICP)");
  app.add_flag("--no-icp", args.no_icp, "no ICP against the model");
  app.add_flag("--3d-features", args.features_3d,
               "add ISS3D + CSHOT matches (the paper's E_feat3d; off by default: about 200 ms per "
               "frame, and on symmetric objects their matches mislead more than they help)");
  app.add_flag("--no-anchors", args.no_anchors,
               "contacts registered frame to frame only, as the paper does (no anchors)");
  app.add_flag("--no-color", args.no_color, "meshes without colour");
  app.add_option("--hand-dilation", args.hand_dilation_px,
                 "pixels around the posed hand model kept out of the object")
      ->capture_default_str()
      ->check(CLI::Range(0, 50));
  app.add_option("--frames", args.max_frames, "stop after this many frames (0: all)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--set", args.assignments,
                 "set one of inhandscan's options: NAME=VALUE (repeatable; `inhandscan config` "
                 "lists them)");
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  if (const auto done = ihs::ParseCommandLine(app, argc, argv)) return *done;
  if (args.contacts_only && args.gamma_t <= 0) {
    std::fprintf(stderr, "inhandscan-scan: error: --contacts-only needs --gamma-t > 0\n");
    return ihs::kExitUsage;
  }
  return ihs::RunReportingErrors("inhandscan-scan", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return Run(args);
  });
}
