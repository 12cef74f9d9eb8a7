#pragma once
// All the scanner's options in one struct: the tracker's, the fusion's, the meshing's and the
// application's own. `app` fills it from a config file and the command line (see
// RegisterScannerOptions) and hands the sub-structs to the stages; nothing changes it after the
// pipeline starts.

#include <string>

#include "app/option_registry.h"
#include "fusion/object_fusion.h"
#include "fusion/shot_matcher.h"
#include "fusion/sift_matcher.h"
#include "fusion/surface_mesh.h"
#include "tracker/hand_tracker.h"

namespace ihs::app {

/// Which correspondences the pairwise registration uses and what else a scan does beyond the
/// stages' own options.
struct ScanOptions {
  /// Hand template: "procedural", or a folder with the real hand model (../shared/data/...).
  std::string hand_template = "procedural";
  /// Scale of the template (0: the procedural template's is estimated over the first frames, a
  /// scanned template is used at 1).
  double hand_scale = 0.0;
  /// The scanning hand is a left one: the procedural template is built mirrored, and a scanned
  /// template must be a left hand (the paper's, and the default, is a right hand).
  bool left_hand = false;
  /// Pixels around the posed hand model that are never the object's (the paper: "dilated a few
  /// pixels").
  int hand_dilation_px = 4;
  /// The posed hand model removes object pixels up to this far behind the observed depth, mm.
  double hand_depth_margin_mm = 10.0;
  /// SIFT matches on the object's colour (E_feat2d; off: contacts and ICP only).
  bool features_2d = true;
  /// ISS3D + CSHOT matches on the object's points (E_feat3d; off by default: about 200 ms per
  /// frame, and misleading on symmetric objects).
  bool features_3d = false;
  /// Fuse frames in which the tracker has no hand it trusts (no hand found, or a fit that does
  /// not explain the data). Off: such a frame is skipped with the reason "no hand", so neither a
  /// hand the tracker lost (its pixels are not masked out) nor a scene without a hand is fused,
  /// and a recording without a hand scans nothing. On: for an object that is not held (a
  /// turntable), where every frame's non-skin pixels are fused as the tracker segments them.
  bool fuse_without_hand = false;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Options of the threaded pipeline.
struct PipelineOptions {
  /// Frames each queue between two threads holds.
  int queue_capacity = 4;
  /// Write a preview image every this many fused frames (0: never).
  int preview_every = 30;
  /// Frames the capture thread reads at most (0: all).
  int max_frames = 0;
  /// From a live source, the hand tracker's searches, its periodic check of the fit turned over
  /// and its scale estimate's fits run beside its tracking (TrackerOptions::search_beside): they
  /// no longer stall the tracker while the camera's frames are dropped or wait. Unpaced replays
  /// do them in place whatever this says (repeatable).
  bool live_search_beside = true;
  /// After a stop, the frames in hand get this long, seconds (a frame takes well under one; a
  /// sanitizer build's several). A stage still busy then (a source read or a fit that does not
  /// return) is left behind: `inhandscan` exports the model so far without those frames, says
  /// what it saved and exits with code 5 (Pipeline::Abandon).
  double stop_grace_s = 20;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Every option of the scanner.
struct ScannerOptions {
  ScanOptions scan;
  tracker::TrackerOptions tracker;
  fusion::SiftOptions sift;
  fusion::ShotOptions shot;
  fusion::FusionOptions fusion;
  fusion::MeshingOptions meshing;
  PipelineOptions pipeline;

  /// Checks every sub-struct; throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The option groups (COLMAP's Add*Options style): each registers the fields of one stage's
/// options under its dotted names ("fusion.icp.max_distance_mm") with one line of meaning; a tool
/// adds the groups it uses, and names from other groups are unknown to it. The registry points
/// into the structs, which must outlive it.
void AddScanOptions(OptionRegistry& registry, ScanOptions* options);                 ///< scan.*
void AddTrackerOptions(OptionRegistry& registry, tracker::TrackerOptions* options);  ///< tracker.*
void AddFeatureOptions(OptionRegistry& registry, fusion::SiftOptions* sift,
                       fusion::ShotOptions* shot);                                  ///< features.*
void AddFusionOptions(OptionRegistry& registry, fusion::FusionOptions* options);    ///< fusion.*
void AddMeshingOptions(OptionRegistry& registry, fusion::MeshingOptions* options);  ///< mesh.*
void AddPipelineOptions(OptionRegistry& registry, PipelineOptions* options);        ///< pipeline.*

/// Every group: all the options of `options` (inhandscan's and inhandscan-scan's).
OptionRegistry RegisterScannerOptions(ScannerOptions* options);

}  // namespace ihs::app
