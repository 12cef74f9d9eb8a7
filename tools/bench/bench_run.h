#pragma once
// The benchmark's runs: a case is a generator sequence (object × motion), rendered once and
// cached; every method scans the same frames. The hand tracker does not depend on the method, so
// it runs once per frame and each method's object stage (correspondences, registration, ICP,
// TSDF) gets its own copy of the tracked frame: all methods in one pass, on identical input.
// The Open3D baselines get the same frames with the hand's pixels removed by the ground truth.

#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/trajectory_io.h"
#include "core/triangle_mesh.h"

namespace ihs::bench {

/// A generator sequence.
struct BenchCase {
  std::string name;    ///< e.g. "004-sphere", "sphere-turn".
  /// Generator object: sphere, water-bottle, bowling-pin, small-bottle, box, plain-box, cube.
  std::string object;
  std::string motion;  ///< "scripted" or "recorded:DIR".
  bool textured = false;
  /// Frames [0, frames) of the motion; 0: all.
  int frames = 0;
  /// One of the paper's four sessions (its Table 1 and the γt sweep).
  bool paper = false;
  /// Seed of the generator's random choices (noise, sway, slip).
  unsigned seed = 1;
  /// Start the hand tracker from the ground truth's first pose instead of letting it find the
  /// hand (to tell the tracker's share of an error from the registration's; no default case
  /// does: a user's scan initialises itself).
  bool init_from_gt = false;
};

/// A way of scanning: ours or a baseline, as options of our stages.
struct Method {
  std::string name;     ///< e.g. "ours", "visual-only".
  double gamma_t = 15;  ///< Weight of the fingertip contacts (paper: 15).
  bool visual = true;   ///< SIFT matches.
  bool icp = true;      ///< ICP against the model.
  /// Only the registration is measured (γt sweep): no mesh.
  bool sweep_only = false;
};

/// The paper's γt values of its sweep figure.
std::vector<double> GammaSweep();
/// Ours, visual only (γt = 0), contacts only, no ICP; then the sweep's other γt values.
std::vector<Method> DefaultMethods(const std::vector<double>& sweep);

/// A scripted full turn of the benchmark.
struct FullTurn {
  std::string name;    ///< e.g. "cube-turn".
  std::string object;  ///< Generator object.
  bool textured = false;
  unsigned seed = 1;
};

/// The scripted full turns (the report's headline cases): sphere, bowling pin, water bottle,
/// small bottle, a 60 mm cube, the 60 × 45 × 90 mm box in one colour and textured.
std::vector<FullTurn> FullTurns();

/// Whether the case is one of the scripted full turns.
bool IsFullTurn(const BenchCase& bench_case);

/// The paper's four sessions (object × its recorded motion; `data`: the hand data folder with
/// sequences/), then the scripted full turns (FullTurns(), 240 frames, the hand tracker started
/// from the truth's first pose). `frames`: cap per case (0: whole); when it cuts the sessions,
/// the sphere's whole session is a case of its own ("004-sphere-whole", for the volume).
/// Without `data` only the scripted cases.
std::vector<BenchCase> DefaultCases(const std::filesystem::path& data, int frames);

/// One method's result on one case.
struct MethodResult {
  std::string method;
  bool ok = false;
  std::string error;  ///< Why it failed, when it did.
  int frames = 0, registered = 0;
  /// Dimensions, volume, pairwise error, trajectory drift, Chamfer (eval::ReportScan's JSON)
  /// plus "ms_per_frame", "export_ms", skip reasons.
  nlohmann::json measures = nlohmann::json::object();
  std::vector<StampedPose> trajectory;
  /// The meshes (object frame of the scan): TSDF surface smoothed, and watertight.
  TriangleMesh seen, watertight;
};

struct CaseResult {
  BenchCase bench_case;
  std::filesystem::path gt_dir;
  int frames = 0;  ///< Frames read.
  /// Hand tracker: mean joint error over frames with a pose, mm; ms per frame.
  double joint_error_mm = 0;
  int tracked_frames = 0;
  double track_ms = 0, mask_ms = 0;
  /// The share of the true surface the recording showed at all (eval::ShownSurface): the
  /// completeness perfect registration would reach.
  double shown_share = 0;
  std::vector<MethodResult> methods;
  /// The whole application (`inhandscan replay`) on the same recording: frames per second,
  /// peak resident memory; 0 when not run.
  double app_fps = 0, app_peak_mib = 0;
  std::vector<StampedPose> truth;
};

struct RunOptions {
  std::filesystem::path work;  ///< Sequences (cached) and per-method outputs.
  /// Run the Open3D baselines (frame to frame, frame to model) when built with Open3D, each in
  /// a process of its own: `open3d_program` (open3d_peer.h; inhandscan-bench runs itself).
  bool open3d = true;
  std::filesystem::path open3d_program;
  /// `inhandscan` to time the application with (empty: skip).
  std::filesystem::path app;
  bool quiet = false;
};

/// Renders the case's sequence (unless cached) and runs every method on it.
CaseResult RunCase(const BenchCase& bench_case, const std::vector<Method>& methods,
                   const RunOptions& options);

}  // namespace ihs::bench
