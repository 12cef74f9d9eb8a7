// inhandscan-scan: the scanner's stages one after the other, no threads: source → hand tracker →
// object mask without the hand → SIFT matches and fingertip contacts → fusion (registration,
// ICP, TSDF) → meshes. Writes the watertight mesh, the TSDF's own mesh, the object's trajectory,
// the hand's joints and per-frame statistics; with --gt (a generator's gt/ folder) it also
// prints the paper's Table 1 and Table 2 measures and the surface's Chamfer distance. The
// application runs the same stage objects threaded; this is the reference and the baselines'
// harness (--gamma-t 0, --contacts-only, --no-icp).

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/exit_codes.h"
#include "core/logging.h"
#include "core/mesh_io.h"
#include "core/stopwatch.h"
#include "core/trajectory_io.h"
#include "fusion/object_fusion.h"
#include "fusion/object_mask.h"
#include "fusion/shot_matcher.h"
#include "fusion/sift_matcher.h"
#include "fusion/surface_mesh.h"
#include "sensor/open_input.h"
#include "tools/evaluation.h"
#include "tracker/hand_data.h"
#include "tracker/hand_joints_io.h"
#include "tracker/hand_tracker.h"
#include "tracker/procedural_hand.h"

namespace {

namespace fs = std::filesystem;
struct Args {
  std::string input, out, gt, object, template_name = "procedural";
  bool init_from_gt = false, no_icp = false, contacts_only = false, no_color = false;
  bool no_anchors = false, features_3d = false;
  double hand_scale = 0, gamma_t = 15.0;
  int hand_dilation_px = 4;
  std::int64_t max_frames = 0;
};

// Mean of the per-frame values of `key` over `frames` that have it.
double MeanOf(const nlohmann::json& frames, const char* key) {
  double sum = 0;
  int count = 0;
  for (const auto& frame : frames) {
    if (frame.contains(key)) sum += frame[key].get<double>(), ++count;
  }
  return count ? sum / count : 0.0;
}

int Run(const Args& args) {
  namespace tracker = ihs::tracker;
  namespace fusion = ihs::fusion;
  tracker::HandModel model = args.template_name == "procedural"
                                 ? tracker::MakeProceduralHand()
                                 : tracker::LoadHandModel(args.template_name);
  tracker::TrackerOptions tracker_options;
  if (args.hand_scale > 0) model = model.Scaled(args.hand_scale);
  if (args.hand_scale > 0 || args.template_name != "procedural") tracker_options.scale_frames = 0;
  fusion::FusionOptions fusion_options;
  fusion_options.pairwise.contact_weight = args.gamma_t;
  if (args.contacts_only) fusion_options.pairwise.visual_weight = 0;
  fusion_options.use_icp = !args.no_icp;
  fusion_options.anchor_contacts = !args.no_anchors;
  fusion_options.tsdf.color = !args.no_color;
  fusion::MeshingOptions meshing_options;
  meshing_options.color = !args.no_color;

  std::vector<tracker::HandJointsRow> gt_joints;
  std::string object = args.object;
  if (!args.gt.empty()) {
    gt_joints = tracker::ReadHandJointsCsv(fs::path(args.gt) / "hand_joints.csv");
    if (object.empty()) {
      std::ifstream manifest(fs::path(args.gt) / "manifest.json");
      if (!manifest) throw ihs::InputError(args.gt + "/manifest.json: cannot read");
      object = nlohmann::json::parse(manifest, nullptr, false)
                   .value("object", nlohmann::json::object())
                   .value("spec", "");
    }
  } else if (args.init_from_gt) {
    throw std::invalid_argument("--init-from-gt needs --gt");
  }

  auto source = ihs::sensor::OpenInput(args.input);
  source->Start();
  const ihs::CameraIntrinsics intrinsics = source->Intrinsics();
  tracker::HandTracker hand_tracker(model, intrinsics, tracker_options);
  fusion::SiftMatcher sift(intrinsics);
  fusion::ShotMatcher shot(intrinsics);
  fusion::ObjectFusion object_fusion(intrinsics, fusion_options);
  const fs::path out = args.out;
  std::error_code error;
  fs::create_directories(out, error);
  if (error) throw ihs::OutputError(out.string() + ": cannot create (" + error.message() + ")");

  std::vector<tracker::HandJointsRow> joints;
  std::vector<ihs::StampedPose> trajectory;
  nlohmann::json frames = nlohmann::json::array();
  std::map<std::string, int> track_counts, fusion_counts;
  std::map<std::string, int> skip_reasons;
  std::int64_t index = 0;
  const auto run_start = ihs::SteadyClock::now();
  while (args.max_frames <= 0 || index < args.max_frames) {
    const ihs::sensor::SourceRead read = source->Next(std::chrono::seconds(5));
    if (read.status == ihs::sensor::SourceStatus::kTimeout) continue;
    if (read.status != ihs::sensor::SourceStatus::kFrame) break;
    const ihs::Frame& frame = *read.frame;
    if (index == 0 && args.init_from_gt) {
      if (gt_joints.empty()) throw ihs::InputError(args.gt + ": no ground-truth joints");
      hand_tracker.Initialise(tracker::FitPoseToJoints(model, gt_joints.front().joints_mm));
    }
    const tracker::TrackResult tracked = hand_tracker.Track(frame);
    ++track_counts[tracker::ToString(tracked.status)];
    nlohmann::json entry = {{"frame", index},
                            {"track", tracker::ToString(tracked.status)},
                            {"track_ms", tracked.milliseconds}};
    if (!tracked.reason.empty()) entry["track_reason"] = tracked.reason;
    if (!tracked.joints_mm.empty()) joints.push_back({index, tracked.joints_mm});

    // The object's pixels, without the hand model's (grown a little).
    auto start = ihs::SteadyClock::now();
    std::vector<std::uint8_t> mask = tracked.segmentation.object_mask;
    if (mask.size() != frame.depth_mm.size()) mask.assign(frame.depth_mm.size(), 0);
    if (tracked.HasPose()) {
      const ihs::TriangleMesh hand =
          hand_tracker.model().Pose(tracker::ForwardKinematics(hand_tracker.model(), tracked.pose));
      entry["hand_pixels_removed"] =
          fusion::RemoveMeshPixels(hand, frame, intrinsics, args.hand_dilation_px, 10.0, &mask);
    }
    entry["mask_ms"] = ihs::MillisecondsSince(start);

    fusion::FusionInput input;
    input.frame = &frame;
    input.object_mask = &mask;
    start = ihs::SteadyClock::now();
    if (!args.contacts_only) {
      input.correspondences.features_2d = sift.Match(frame, mask);
      if (args.features_3d) input.correspondences.features_3d = shot.Match(frame, mask);
    }
    entry["features_ms"] = ihs::MillisecondsSince(start);
    for (const auto& pair : tracked.contact_pairs) {
      input.correspondences.contacts.push_back({pair.previous_mm, pair.current_mm});
      input.contact_ids.push_back(pair.vertex);
    }
    const fusion::FusionResult fused = object_fusion.Fuse(input);
    ++fusion_counts[fusion::ToString(fused.status)];
    entry["fusion"] = fusion::ToString(fused.status);
    entry["fusion_ms"] = fused.milliseconds;
    entry["pairwise_ms"] = fused.pairwise_ms;
    entry["raycast_ms"] = fused.raycast_ms;
    entry["icp_ms"] = fused.icp_ms;
    entry["integrate_ms"] = fused.integrate_ms;
    entry["sift_matches"] = input.correspondences.features_2d.size();
    entry["shot_matches"] = input.correspondences.features_3d.size();
    entry["contact_pairs"] = input.correspondences.contacts.size();
    entry["anchored_contacts"] = fused.anchored_contacts;
    entry["contact_spread_mm"] = fused.pairwise.contact_spread_mm;
    if (fused.pairwise.ok) {
      // The correspondences' motion before ICP: tx ty tz qx qy qz qw (mm), for diagnosis.
      const Eigen::Quaterniond q = fused.pairwise.current_from_previous.quaternion();
      const Eigen::Vector3d t = fused.pairwise.current_from_previous.translation();
      entry["pairwise_motion"] = {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()};
      entry["pairwise_rms_mm"] = fused.pairwise.rms_mm;
    }
    if (fused.icp_from_previous) entry["icp_from_previous"] = true;
    if (fused.icp.iterations > 0) {
      entry["icp_inliers"] = fused.icp.inliers;
      entry["icp_rms_mm"] = fused.icp.rms_mm;
    }
    if (fused.status == fusion::FusionStatus::kSkipped) {
      entry["fusion_reason"] = fused.reason;
      // Counted by the reason's kind (the text before any numbers).
      ++skip_reasons[fused.reason.substr(0, fused.reason.find(':'))];
    } else {
      trajectory.push_back({frame.depth_timestamp_us * 1e-6, fused.cam_from_object});
    }
    frames.push_back(entry);
    ++index;
  }
  if (index == 0) throw ihs::InputError(args.input + ": no frames");
  const double run_s = ihs::MillisecondsSince(run_start) / 1000.0;

  // Meshes.
  auto start = ihs::SteadyClock::now();
  const ihs::TriangleMesh raw = object_fusion.ExtractMesh();
  const double marching_cubes_ms = ihs::MillisecondsSince(start);
  const fusion::MeshingResult meshes = fusion::MakeMeshes(raw, meshing_options);
  const double export_ms = ihs::MillisecondsSince(start);
  if (meshes.smoothed.Empty()) throw ihs::InputError(args.input + ": nothing was scanned");
  ihs::WriteMesh(out / "mesh_tsdf.ply", meshes.smoothed);
  if (!meshes.watertight.Empty()) ihs::WriteMesh(out / "mesh.ply", meshes.watertight);
  ihs::WriteTumTrajectory(out / "trajectory.txt", trajectory,
                          {"cam_from_object of the scanned object (mm), registered frames only",
                           "timestamp tx ty tz qx qy qz qw"});
  std::vector<std::string> names;
  for (const auto& bone : model.bones) names.push_back(bone.name);
  tracker::WriteHandJointsCsv(out / "hand_joints.csv", names, joints);

  nlohmann::json summary = {
      {"frames", index},
      {"registered_frames", trajectory.size()},
      {"track_status_counts", track_counts},
      {"fusion_status_counts", fusion_counts},
      {"skip_reasons", skip_reasons},
      {"hand_scale", hand_tracker.scale() * (args.hand_scale > 0 ? args.hand_scale : 1.0)},
      {"gamma_t", args.gamma_t},
      {"icp", !args.no_icp},
      {"visual", !args.contacts_only},
      {"seconds", run_s},
      {"ms_per_frame",
       {{"track", MeanOf(frames, "track_ms")},
        {"mask", MeanOf(frames, "mask_ms")},
        {"features", MeanOf(frames, "features_ms")},
        {"fusion", MeanOf(frames, "fusion_ms")},
        {"pairwise", MeanOf(frames, "pairwise_ms")},
        {"raycast", MeanOf(frames, "raycast_ms")},
        {"icp", MeanOf(frames, "icp_ms")},
        {"integrate", MeanOf(frames, "integrate_ms")}}},
      {"export_ms",
       {{"total", export_ms},
        {"marching_cubes", marching_cubes_ms},
        {"cleanup", meshes.cleanup_ms},
        {"smoothing", meshes.smoothing_ms},
        {"poisson", meshes.poisson_ms}}},
      {"mesh",
       {{"faces", meshes.watertight.faces.size()},
        {"watertight", meshes.watertight.IsWatertight()},
        {"volume_mm3", meshes.watertight.IsWatertight() ? meshes.watertight.Volume() : 0.0}}}};

  std::printf("frames %lld: registered %zu (started %d, fused %d, skipped %d)\n",
              static_cast<long long>(index), trajectory.size(), fusion_counts["started"],
              fusion_counts["fused"], fusion_counts["skipped"]);
  for (const auto& [reason, count] : skip_reasons)
    std::printf("  skipped: %s × %d\n", reason.c_str(), count);
  const auto& ms = summary["ms_per_frame"];
  std::printf(
      "ms per frame (one core): track %.1f, mask %.1f, features %.1f, fusion %.1f (pairwise %.2f, "
      "raycast %.1f, ICP %.1f, integrate %.1f)\n",
      ms["track"].get<double>(), ms["mask"].get<double>(), ms["features"].get<double>(),
      ms["fusion"].get<double>(), ms["pairwise"].get<double>(), ms["raycast"].get<double>(),
      ms["icp"].get<double>(), ms["integrate"].get<double>());
  std::printf("export: %.0f ms (marching cubes %.0f, cleanup %.0f, smoothing %.0f, Poisson %.0f)\n",
              export_ms, marching_cubes_ms, meshes.cleanup_ms, meshes.smoothing_ms,
              meshes.poisson_ms);
  std::printf("mesh: %s (%zu faces, %s)\n", (out / "mesh.ply").c_str(),
              meshes.watertight.faces.size(),
              meshes.watertight.IsWatertight() ? "watertight" : "NOT watertight");

  if (!args.gt.empty()) {
    // Dimensions and distances on the surface that was seen (the TSDF's, smoothed); Poisson's
    // closing of what was never seen (a base under the hand) is guesswork that would add to a
    // bottle's height. The volume needs the watertight mesh.
    summary["evaluation"] = ihs::eval::ReportScan(object == "box" ? "" : object, meshes.smoothed,
                                                  meshes.watertight, args.gt, trajectory);
  }
  ihs::WriteFileAtomically(out / "stats.json",
                           nlohmann::json{{"summary", summary}, {"frames", frames}}.dump(1) + "\n");
  return ihs::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
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
                 "the ground truth's)");
  app.add_flag("--init-from-gt", args.init_from_gt, "start the hand from the ground truth's pose");
  app.add_option("--template", args.template_name, "procedural, or the real hand data folder")
      ->capture_default_str();
  app.add_option("--hand-scale", args.hand_scale,
                 "scale of the template (default: the procedural one estimated over the first "
                 "frames, a scanned one 1)")
      ->check(CLI::Range(0.5, 2.0));
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
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off");
  app.add_flag("-q,--quiet", quiet, "only warnings and errors");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);
    std::fprintf(stderr, "inhandscan-scan: error: %s (see --help)\n", error.what());
    return ihs::kExitUsage;
  }
  if (args.contacts_only && args.gamma_t <= 0) {
    std::fprintf(stderr, "inhandscan-scan: error: --contacts-only needs --gamma-t > 0\n");
    return ihs::kExitUsage;
  }
  return ihs::RunReportingErrors("inhandscan-scan", [&] {
    ihs::SetUpLogging(ihs::ParseLogLevel(log_level), quiet);
    return Run(args);
  });
}
