#include "app/scanner_options.h"

#include <stdexcept>

#include "core/check.h"

namespace ihs::app {

void ScanOptions::Check() const {
  IHS_CHECK_ARG(!hand_template.empty(), "scan.hand_template must name a template");
  IHS_CHECK_ARG(hand_scale == 0.0 || (hand_scale >= 0.5 && hand_scale <= 2.0),
                "scan.hand_scale must be 0 (estimate) or in [0.5, 2]");
  IHS_CHECK_ARG(hand_dilation_px >= 0 && hand_dilation_px <= 50,
                "scan.hand_dilation_px must be in [0, 50]");
  IHS_CHECK_ARG(hand_depth_margin_mm >= 0, "scan.hand_depth_margin_mm must be ≥ 0");
}

void PipelineOptions::Check() const {
  IHS_CHECK_ARG(queue_capacity >= 1 && queue_capacity <= 1000,
                "pipeline.queue_capacity must be in [1, 1000]");
  IHS_CHECK_ARG(preview_every >= 0, "pipeline.preview_every must be ≥ 0");
  IHS_CHECK_ARG(max_frames >= 0, "pipeline.max_frames must be ≥ 0");
  IHS_CHECK_ARG(stop_grace_s >= 1 && stop_grace_s <= 3600,
                "pipeline.stop_grace_s must be in [1, 3600]");
}

void ScannerOptions::Check() const {
  scan.Check();
  tracker.Check();
  sift.Check();
  shot.Check();
  fusion.Check();
  meshing.Check();
  pipeline.Check();
  IHS_CHECK_ARG(scan.features_2d || scan.features_3d || fusion.pairwise.contact_weight > 0,
                "fusion.pairwise.contact_weight must be > 0 when no visual features are on");
}

namespace {

// The tracker's sub-groups: segmentation, the hand fit, the contacts.
void AddSegmentationOptions(OptionRegistry& r, tracker::SegmentationOptions* segmentation) {
  tracker::SegmentationOptions& s = *segmentation;
  r.Add("tracker.segmentation.crop_min_mm", &s.crop_min_mm,
        "crop volume's lower corner, camera frame, mm (paper: -100,-140,400)");
  r.Add("tracker.segmentation.crop_max_mm", &s.crop_max_mm,
        "crop volume's upper corner, camera frame, mm (paper: 100,220,1000)");
  r.Add("tracker.segmentation.skin_log_ratio", &s.skin_log_ratio,
        "skin when log p(rgb|skin) - log p(rgb|non-skin) exceeds this");
  r.Add("tracker.segmentation.connect_depth_mm", &s.connect_depth_mm,
        "neighbouring pixels join one region when their depths differ by at most this, mm");
  r.Add("tracker.segmentation.min_region_pixels", &s.min_region_pixels,
        "regions smaller than this many pixels are dropped");
  r.Add("tracker.segmentation.speck_enclosed_share", &s.speck_enclosed_share,
        "a small skin region with this share of its outline on the object joins it (0: off)");
  r.Add("tracker.segmentation.speck_step_mm", &s.speck_step_mm,
        "depth step across a skin speck's outline still on the object's surface, mm");
  r.Add("tracker.segmentation.connect_gap_px", &s.connect_gap_px,
        "pixels also join a region across this many pixels without depth (0: neighbours only)");
  r.Add("tracker.segmentation.boundary_px", &s.boundary_px,
        "object pixels this close to the hand are left out");
  r.Add("tracker.segmentation.max_object_distance_mm", &s.max_object_distance_mm,
        "object regions farther than this from the hand's centre are left out, mm");
  r.Add("tracker.segmentation.object_margin_mm", &s.object_margin_mm,
        "an object region reaching into the crop volume goes on this far beyond it, mm");
}

void AddHandFitOptions(OptionRegistry& r, tracker::HandFitOptions* fit) {
  tracker::HandFitOptions& f = *fit;
  r.Add("tracker.fit.collision_weight", &f.collision_weight,
        "gamma_c, weight of the finger collision term (paper: 10)");
  r.Add("tracker.fit.outer_iterations", &f.outer_iterations, "correspondence updates per frame");
  r.Add("tracker.fit.inner_iterations", &f.inner_iterations,
        "Levenberg-Marquardt iterations per correspondence update");
  r.Add("tracker.fit.max_data_points", &f.max_data_points, "data points matched to the model");
  r.Add("tracker.fit.data_voxel_mm", &f.data_voxel_mm,
        "data points: centroids of the hand points in cubes of this size, mm (0: a stride)");
  r.Add("tracker.fit.max_model_points", &f.max_model_points,
        "visible model points matched to the data");
  r.Add("tracker.fit.max_correspondence_mm", &f.max_correspondence_mm,
        "pairs farther apart are dropped, mm");
  r.Add("tracker.fit.robust_scale_mm", &f.robust_scale_mm,
        "pairs farther apart count with a Huber weight, mm");
  r.Add("tracker.fit.limit_weight", &f.limit_weight, "weight of the soft joint limits, per rad");
  r.Add("tracker.fit.prior_weight", &f.prior_weight,
        "pull toward the predicted joint angles, per rad");
  r.Add("tracker.fit.data_point_weight", &f.data_point_weight,
        "weight of point-to-point data-to-model pairs besides point-to-plane");
  r.Add("tracker.fit.silhouette_weight", &f.silhouette_weight, "weight of the silhouette term");
  r.Add("tracker.fit.silhouette_tolerance_px", &f.silhouette_tolerance_px,
        "model points this close to the silhouette count as inside, px");
  r.Add("tracker.fit.unlabelled_match_mm", &f.unlabelled_match_mm,
        "a seen model point is paired with an unsegmented depth pixel this near, mm (0: never)");
  r.Add("tracker.fit.contact_surface_weight", &f.contact_surface_weight,
        "pull of the fingertips touching in the previous frame onto the object's surface (0: off)");
  r.Add("tracker.fit.initial_trust_radius", &f.initial_trust_radius,
        "initial Levenberg-Marquardt trust region");
}

void AddContactOptions(OptionRegistry& r, tracker::ContactOptions* contacts) {
  tracker::ContactOptions& c = *contacts;
  r.Add("tracker.contacts.start_mm", &c.start_mm,
        "first fingertip-to-object distance threshold, mm (paper: 1)");
  r.Add("tracker.contacts.step_mm", &c.step_mm, "threshold growth per retry, mm (paper: 0.5)");
  r.Add("tracker.contacts.max_mm", &c.max_mm, "largest threshold, mm");
  r.Add("tracker.contacts.min_vertices", &c.min_vertices,
        "vertices within the threshold that make a contact bone (paper: 40)");
  r.Add("tracker.contacts.reference_fingertip_vertices", &c.reference_fingertip_vertices,
        "fingertip vertex count min_vertices refers to (other templates scale it)");
  r.Add("tracker.contacts.min_bones", &c.min_bones, "contact bones wanted (paper: 2)");
  r.Add("tracker.contacts.surface_mm", &c.surface_mm,
        "a fingertip vertex this near the object's surface continued under it (a sphere or plane "
        "fitted to the points around it) counts as touching, mm (0: off)");
  r.Add("tracker.contacts.surface_patch_mm", &c.surface_patch_mm,
        "object points within this of a fingertip's centre make its surface, mm");
  r.Add("tracker.contacts.surface_min_points", &c.surface_min_points,
        "fewest object points that make a fingertip's surface");
  r.Add("tracker.contacts.surface_max_rms_mm", &c.surface_max_rms_mm,
        "a fingertip's surface is continued only where its points lie this near it (RMS), mm");
  r.Add("tracker.contacts.surface_trim", &c.surface_trim,
        "continue a patch no one surface explains by the surface nearest the fingertip");
}

void AddGraspHoldOptions(OptionRegistry& r, tracker::GraspHoldOptions* hold) {
  tracker::GraspHoldOptions& h = *hold;
  r.Add("tracker.grasp_hold.enabled", &h.enabled,
        "hold a detected grasp through frames the detection misses while the hand keeps its "
        "shape (off: the paper's per-frame contacts)");
  r.Add("tracker.grasp_hold.max_shape_change_mm", &h.max_shape_change_mm,
        "a held fingertip moving farther in the hand's frame lets go, mm");
  r.Add("tracker.grasp_hold.max_reach_mm", &h.max_reach_mm,
        "a held fingertip farther from every object point lets go, mm");
  r.Add("tracker.grasp_hold.max_frames", &h.max_frames,
        "frames in a row a grasp is held without being detected at most");
}

void AddReleaseOptions(OptionRegistry& r, tracker::ReleaseOptions* release) {
  tracker::ReleaseOptions& o = *release;
  r.Add("tracker.release.enabled", &o.enabled,
        "a grasp whose fingertips rise off the object together is let go: they are no "
        "contacts until they come back");
  r.Add("tracker.release.frames", &o.frames, "frames over which the grasp's fingertips rise");
  r.Add("tracker.release.rise_mm", &o.rise_mm,
        "how far every fingertip of the grasp rises when it lets go, mm");
  r.Add("tracker.release.return_mm", &o.return_mm,
        "a let-go fingertip counts again within this of where it was before, mm");
  r.Add("tracker.release.max_frames", &o.max_frames, "frames a fingertip stays let go at most");
}

void AddGraspSideOptions(OptionRegistry& r, tracker::GraspSideOptions* side) {
  tracker::GraspSideOptions& g = *side;
  r.Add("tracker.grasp_side.weight", &g.weight,
        "score penalty per unit of cosine a palm turns away from the held object beyond "
        "min_cosine (0: off)");
  r.Add("tracker.grasp_side.min_cosine", &g.min_cosine,
        "cosine between the palm's normal and the direction to the object's middle below which a "
        "pose is penalised");
  r.Add("tracker.grasp_side.near_hand_mm", &g.near_hand_mm,
        "object points within this distance of the hand points' centroid make the held object, mm");
  r.Add("tracker.grasp_side.min_object_points", &g.min_object_points,
        "fewer object points near the hand: no object seen, no penalty");
  r.Add("tracker.grasp_side.opposition_weight", &g.opposition_weight,
        "score penalty per unit of cosine beyond max_opposition_cosine between the thumb's tip and "
        "the fingertips seen from the held object's middle (0: off)");
  r.Add("tracker.grasp_side.max_opposition_cosine", &g.max_opposition_cosine,
        "cosine between the thumb's tip and the fingertips, from the object's middle, above which "
        "a pose is penalised (-1: straight across)");
}

// The fusion's sub-groups: the TSDF volume, and the registration (pairwise and ICP).
void AddTsdfOptions(OptionRegistry& r, fusion::FusionOptions* fusion) {
  fusion::FusionOptions& u = *fusion;
  r.Add("fusion.tsdf.size_mm", &u.tsdf.size_mm, "edge of the TSDF cube, mm (paper: 350)");
  r.Add("fusion.tsdf.resolution", &u.tsdf.resolution, "TSDF voxels per edge (paper: 256)");
  r.Add("fusion.tsdf.truncation_voxels", &u.tsdf.truncation_voxels,
        "signed distances truncated to this many voxels");
  r.Add("fusion.tsdf.max_weight", &u.tsdf.max_weight, "cap of a voxel's integration weight");
  r.Add("fusion.tsdf.color", &u.tsdf.color, "voxels keep a colour");
  r.Add("fusion.tsdf.color_band_voxels", &u.tsdf.color_band_voxels,
        "voxels within this many voxels of the surface (along the ray) take a pixel's colour "
        "(0: the whole truncation band)");
  r.Add("fusion.tsdf.threads", &u.tsdf.threads,
        "threads that integrate and raycast (0: one per core but the tracker thread's; at most "
        "8); the model is the same whatever the number");
}

void AddRegistrationOptions(OptionRegistry& r, fusion::FusionOptions* fusion) {
  fusion::FusionOptions& u = *fusion;
  r.Add("fusion.pairwise.contact_weight", &u.pairwise.contact_weight,
        "gamma_t, weight of a contact pair against a visual pair (paper: 15; 0: visual only)");
  r.Add("fusion.pairwise.visual_weight", &u.pairwise.visual_weight,
        "weight of visual pairs (0: contacts only)");
  r.Add("fusion.pairwise.check_contacts", &u.pairwise.check_contacts,
        "drop contacts that a consistent set of visual matches contradicts");
  r.Add("fusion.pairwise.ransac_iterations", &u.pairwise.ransac_iterations,
        "RANSAC hypotheses over the visual pairs");
  r.Add("fusion.pairwise.inlier_mm", &u.pairwise.inlier_mm, "RANSAC inlier distance, mm");
  r.Add("fusion.pairwise.min_visual_inliers", &u.pairwise.min_visual_inliers,
        "inliers a visual set needs to count");
  r.Add("fusion.pairwise.min_contacts", &u.pairwise.min_contacts,
        "contact pairs needed when they are all there is");
  r.Add("fusion.pairwise.min_contact_spread_mm", &u.pairwise.min_contact_spread_mm,
        "contacts count only when spread at least this far (two fingertips), mm");
  r.Add("fusion.pairwise.visual_turn_prior_deg", &u.pairwise.visual_turn_prior_deg,
        "visual matches alone: their turn shrinks toward none under this prior per frame, "
        "degrees (0: kept)");
  r.Add("fusion.pairwise.max_rms_mm", &u.pairwise.max_rms_mm,
        "a motion whose pairs lie farther from it (RMS, mm) is not used (0: never)");
  r.Add("fusion.pairwise.seed", &u.pairwise.seed, "seed of the RANSAC sampling");
  r.Add("fusion.icp.iterations", &u.icp.iterations, "ICP Gauss-Newton iterations at most");
  r.Add("fusion.icp.max_distance_mm", &u.icp.max_distance_mm,
        "ICP pairs farther apart are not used, mm (paper: 5)");
  r.Add("fusion.icp.min_inlier_fraction", &u.icp.min_inlier_fraction,
        "ICP with fewer pairs than this share of points is not trusted");
  r.Add("fusion.icp.anchor_share", &u.icp.anchor_share,
        "share of the surface pairs' weight the contact anchors carry in ICP");
  r.Add("fusion.icp.min_constraint_over_noise", &u.icp.min_constraint_over_noise,
        "without anchors, ICP leaves directions the surface constrains less than this many times "
        "its normals' noise at the prediction (0: solves all)");
  r.Add("fusion.icp.min_kept_pair_fraction", &u.icp.min_kept_pair_fraction,
        "ICP ending with fewer than this share of the pairs it started with slid: its "
        "best-paired iterate is kept (0: off)");
}

void AddLoopClosureOptions(OptionRegistry& r, fusion::LoopClosureOptions* options) {
  fusion::LoopClosureOptions& l = *options;
  r.Add("fusion.loop_closure.enabled", &l.enabled,
        "keep keyframes, register views seen again after a turn against them and correct the "
        "drift (pose graph, model re-fused)");
  r.Add("fusion.loop_closure.keyframe_turn_deg", &l.keyframe_turn_deg,
        "a frame becomes a keyframe when the object turned this far since the last, degrees");
  r.Add("fusion.loop_closure.max_keyframes", &l.max_keyframes, "keyframes kept at most");
  r.Add("fusion.loop_closure.loop_min_gap", &l.loop_min_gap,
        "a loop joins keyframes at least this many keyframes apart");
  r.Add("fusion.loop_closure.loop_max_turn_deg", &l.loop_max_turn_deg,
        "... whose views are within this turn of each other, degrees");
  r.Add("fusion.loop_closure.loop_tries", &l.loop_tries,
        "earlier keyframes registered per new keyframe at most");
  r.Add("fusion.loop_closure.loop_agreement_mm", &l.loop_agreement_mm,
        "a loop counts once another agrees with it on where the object is within this, mm");
  r.Add("fusion.loop_closure.loop_pending_keyframes", &l.loop_pending_keyframes,
        "... another of the same keyframe or of the next this many");
  r.Add("fusion.loop_closure.icp_start_mm", &l.icp_start_mm,
        "a loop's ICP pairs points this far apart at first, then half, then a quarter, mm");
  r.Add("fusion.loop_closure.min_inlier_fraction", &l.min_inlier_fraction,
        "a loop pairs at least this share of the new keyframe's points");
  r.Add("fusion.loop_closure.max_rms_mm", &l.max_rms_mm, "... at this RMS at most, mm");
  r.Add("fusion.loop_closure.max_correction_mm", &l.max_correction_mm,
        "... and moves the chain's estimate by less than this, mm");
  r.Add("fusion.loop_closure.refuse_min_mm", &l.refuse_min_mm,
        "the model is re-fused when the solved graph moves a keyframe farther than this, mm");
  r.Add("fusion.loop_closure.chain_trusted_kept", &l.chain_trusted_kept,
        "the tracked motion between keyframes weighs less in the pose graph where a frame's "
        "ICP kept fewer than this share of its first pairs");
  r.Add("fusion.loop_closure.lever_mm", &l.graph.lever_mm,
        "the pose graph weighs turns by how far they move points this far from the object's "
        "origin, mm");
  r.Add("fusion.loop_closure.feature_loops", &l.feature_loops,
        "where the surface leaves the turn free, loops are registered by the keyframes' SIFT "
        "keypoints (objects with a pattern)");
  r.Add("fusion.loop_closure.feature_keypoints", &l.feature_keypoints,
        "SIFT keypoints a keyframe keeps for that, at most");
  r.Add("fusion.loop_closure.feature_max_turn_deg", &l.feature_max_turn_deg,
        "earlier keyframes within this turn of a new one are tried, degrees");
  r.Add("fusion.loop_closure.feature_tries", &l.feature_tries,
        "of those, the ones with most matches tried per new keyframe");
  r.Add("fusion.loop_closure.feature_min_inliers", &l.feature_min_inliers,
        "matches one motion must explain to make a loop");
  r.Add("fusion.loop_closure.feature_inlier_mm", &l.feature_inlier_mm,
        "a match explained by a motion lands within this distance, mm");
  r.Add("fusion.loop_closure.feature_distinct_deg", &l.feature_distinct_deg,
        "motions turned more than this from the loop's are its rivals, degrees");
  r.Add("fusion.loop_closure.feature_max_rival", &l.feature_max_rival,
        "no loop where a rival explains more than this share of the loop's matches");
  r.Add("fusion.loop_closure.feature_drift_share", &l.feature_drift_share,
        "a loop by keypoints turns the chain by at most this share of the turn it travelled "
        "since the earlier keyframe ...");
  r.Add("fusion.loop_closure.feature_min_gate_deg", &l.feature_min_gate_deg,
        "... or this many degrees");
  r.Add("fusion.loop_closure.feature_alias_share", &l.feature_alias_share,
        "once a registration by keypoints was seen off by a turn (past the drift gate, or "
        "against another of the same keyframe: a pattern that repeats), loops by keypoints turn "
        "the chain by less than this share of the least such turn");
  r.Add("fusion.loop_closure.feature_min_inlier_fraction", &l.feature_min_inlier_fraction,
        "a loop by keypoints pairs at least this share of the new keyframe's points");
  r.Add("fusion.loop_closure.spin_axis_loops", &l.spin_axis_loops,
        "where the surface leaves the turn free, a loop's correction is spread as spins about "
        "the line the largest correction turned about");
  r.Add("fusion.loop_closure.spin_axis_min_deg", &l.spin_axis_min_deg,
        "... once a correction turned at least this far, degrees");
  r.Add("fusion.loop_closure.spin_weight", &l.graph.spin_weight,
        "... the chain's hold on that spin against its hold on the line");
}

}  // namespace

void AddScanOptions(OptionRegistry& r, ScanOptions* options) {
  ScanOptions& scan = *options;
  r.Add("scan.hand_template", &scan.hand_template,
        "hand template: procedural, or the folder of a scanned hand model");
  r.Add("scan.hand_scale", &scan.hand_scale,
        "template scale (0: estimated over the first frames for the procedural template)");
  r.Add("scan.left_hand", &scan.left_hand,
        "the scanning hand is a left one (the procedural template is mirrored)");
  r.Add("scan.hand_dilation_px", &scan.hand_dilation_px,
        "pixels around the posed hand model never counted as the object");
  r.Add("scan.fuse_without_hand", &scan.fuse_without_hand,
        "fuse frames without a tracked hand too (an object that is not held; off: skipped as "
        "'no hand')");
  r.Add("scan.hand_depth_margin_mm", &scan.hand_depth_margin_mm,
        "the hand model hides object pixels up to this far behind the observed depth, mm");
  r.Add("scan.features_2d", &scan.features_2d, "SIFT matches on the object's colour (E_feat2d)");
  r.Add("scan.features_3d", &scan.features_3d,
        "ISS3D + CSHOT matches (E_feat3d; slow, misleading on symmetric objects)");
}

void AddTrackerOptions(OptionRegistry& r, tracker::TrackerOptions* options) {
  tracker::TrackerOptions& t = *options;
  r.Add("tracker.min_hand_points", &t.min_hand_points, "hand points a frame needs to be fitted");
  r.Add("tracker.min_data_coverage", &t.min_data_coverage,
        "share of hand points within 10 mm of the model below which the fit has diverged");
  r.Add("tracker.search_data_coverage", &t.search_data_coverage,
        "share of hand points within 10 mm of the model below which the fit is doubtful");
  r.Add("tracker.doubtful_frames_to_search", &t.doubtful_frames_to_search,
        "doubtful frames in a row before searching for the hand anew from the hand cloud");
  r.Add("tracker.search_when_points_grow", &t.search_when_points_grow,
        "search anew, while the hand touches nothing, on a frame with this many times the hand "
        "points of every frame searched before (0: never)");
  r.Add("tracker.search_growth_gain", &t.search_growth_gain,
        "how many times better a search started by more hand points must score to be taken");
  r.Add("tracker.search.directions", &t.search.directions,
        "a search's directions of the hand's long axis (spread evenly)");
  r.Add("tracker.search.rolls", &t.search.rolls, "a search's turns about each direction");
  r.Add("tracker.search.placement_iterations", &t.search.placement_iterations,
        "rigid ICP iterations placing each search hypothesis on the hand points");
  r.Add("tracker.search.sample_points", &t.search.sample_points,
        "model and hand points used to place and score a search hypothesis");
  r.Add("tracker.search.grasp_rolls", &t.search.grasp_rolls,
        "where an object is seen in the hand, starts holding it in the palm, turned about the "
        "palm's normal in this many steps (0: none)");
  r.Add("tracker.search.grasp_tilt_deg", &t.search.grasp_tilt_deg,
        "those starts' palm normal also tilted this much four ways, degrees");
  r.Add("tracker.search.score_cap_mm", &t.search.score_cap_mm,
        "largest distance a search hypothesis's score counts per point, mm");
  r.Add("tracker.search.threads", &t.search.threads,
        "threads placing a search's starts (0: one per core; the same result whatever the "
        "number)");
  r.Add("tracker.search_candidates", &t.search_candidates,
        "a search's best placed hypotheses that the hand fit tries");
  r.Add("tracker.search_coarse_iterations", &t.search_coarse_iterations,
        "correspondence updates for each of a search's hypotheses");
  r.Add("tracker.search_refined", &t.search_refined,
        "a search's best hypotheses fitted on after the coarse fits");
  r.Add("tracker.initialisation_iterations", &t.initialisation_iterations,
        "correspondence updates for each refined search hypothesis");
  r.Add("tracker.scale_frames", &t.scale_frames,
        "frames over which the template's scale is estimated (0: none)");
  r.Add("tracker.scale_range", &t.scale_range, "scale candidates span 1 ± this");
  r.Add("tracker.scale_step", &t.scale_step, "step between scale candidates");
  r.Add("tracker.flip_check_frames", &t.flip_check_frames,
        "frames between fits of the hand turned over (palm for back) beside the fit (0: never)");
  r.Add("tracker.flip_tie_score", &t.flip_tie_score,
        "fit scores this close make the turned-over fit a tie and the pose doubtful");
  r.Add("tracker.thumb_check", &t.thumb_check,
        "with each turned-over check, also fit the thumb started in other places");
  AddSegmentationOptions(r, &t.segmentation);
  AddHandFitOptions(r, &t.fit);
  AddContactOptions(r, &t.contacts);
  AddGraspHoldOptions(r, &t.grasp_hold);
  AddReleaseOptions(r, &t.release);
  AddGraspSideOptions(r, &t.grasp_side);
}

void AddFeatureOptions(OptionRegistry& r, fusion::SiftOptions* sift, fusion::ShotOptions* shot) {
  r.Add("features.sift.max_features", &sift->max_features, "SIFT keypoints per frame");
  r.Add("features.sift.ratio", &sift->ratio, "Lowe's ratio test for SIFT matches");
  r.Add("features.sift.support_inside", &sift->support_inside,
        "share of a keypoint's neighbourhood radius that must lie on the object (0: any "
        "keypoint on it)");
  r.Add("features.shot.resolution_mm", &shot->resolution_mm,
        "voxel size of the cloud ISS3D + CSHOT work on, mm");
  r.Add("features.shot.normal_radius", &shot->normal_radius, "normal radius, in resolutions");
  r.Add("features.shot.salient_radius", &shot->salient_radius,
        "ISS salient radius, in resolutions");
  r.Add("features.shot.non_max_radius", &shot->non_max_radius,
        "ISS non-maximum suppression radius, in resolutions");
  r.Add("features.shot.support_radius", &shot->support_radius,
        "CSHOT support radius, in resolutions");
  r.Add("features.shot.ratio", &shot->ratio, "ratio test for CSHOT matches");
}

void AddFusionOptions(OptionRegistry& r, fusion::FusionOptions* options) {
  fusion::FusionOptions& u = *options;
  r.Add("fusion.use_icp", &u.use_icp, "refine with point-to-plane ICP against the model");
  r.Add("fusion.icp_retry_fraction", &u.icp_retry_fraction,
        "ICP is retried from the previous pose when it pairs fewer than this share of points");
  r.Add("fusion.icp_retry_drop", &u.icp_retry_drop,
        "... and when it pairs less than this share of what the last frame's ICP paired, "
        "where the surface fixes every direction (0: never)");
  r.Add("fusion.icp_retry_gain", &u.icp_retry_gain,
        "... the retry kept where it pairs this many times the first's points");
  r.Add("fusion.colour_weighs_still", &u.colour_weighs_still,
        "where the surface leaves a turn free and the object shows a pattern, ICP and the "
        "colours also from the previous pose, kept where the colours match better");
  r.Add("fusion.colour_still_margin", &u.colour_still_margin,
        "... by more than this much correlation");
  r.Add("fusion.colour_recheck_frames", &u.colour_recheck_frames,
        "after a frame whose colours show no pattern, the colour alignment looks again this "
        "many frames later (1: every frame)");
  r.Add("fusion.hidden.share", &u.hidden.share,
        "a frame with fewer than this share of the most object points of the recent frames in "
        "view shows the object hidden: tracked, not integrated (0: never)");
  r.Add("fusion.hidden.reference_frames", &u.hidden.reference_frames,
        "... over this many recent frames in view");
  r.Add("fusion.hidden.shown_share", &u.hidden.shown_share,
        "... and where it shows the object at fewer than this share of the pixels where the "
        "model is in view at the frame's pose (0: not checked)");
  r.Add("fusion.hidden.background_margin_mm", &u.hidden.background_margin_mm,
        "... pixels more than this far behind the model show the background: not counted, mm");
  r.Add("fusion.see_through.max_share", &u.see_through.max_share,
        "a frame whose depth lies behind the model, raycast at its pose, at more than this share "
        "of the model's pixels sees through it: ICP again from the object's points, else "
        "tracked, not integrated (0: not checked)");
  r.Add("fusion.see_through.margin_mm", &u.see_through.margin_mm,
        "... depth more than this far behind the model sees through it, mm");
  r.Add("fusion.see_through.max_held_frames", &u.see_through.max_held_frames,
        "... at most this many frames in a row held out; later ones integrated as registered");
  r.Add("fusion.see_through.step_px", &u.see_through.step_px,
        "... the model raycast at every this-many-th pixel along each image axis");
  r.Add("fusion.predict_moving", &u.predict_moving,
        "where nothing registers a frame, the object moves on as in the last frame (when the "
        "surface left no direction free there; off by default)");
  r.Add("fusion.drop_features_moving_back", &u.drop_features_moving_back,
        "where the hand swings back, feature pairs moving with it are left out");
  r.Add("fusion.free_turn_min_visual_inliers", &u.free_turn_min_visual_inliers,
        "where the surface leaves a turn free, a feature set needs this many inliers");
  r.Add("fusion.free_turn_visual_prior_deg", &u.free_turn_visual_prior_deg,
        "where the surface leaves a turn free, the features' turn is shrunk with this prior per "
        "frame, degrees (0: kept as fitted)");
  r.Add("fusion.min_object_points", &u.min_object_points, "object points a frame needs");
  r.Add("fusion.loose_contact_mm", &u.loose_contact_mm,
        "contacts found farther from the object are used only where its surface leaves a turn "
        "free, mm");
  r.Add("fusion.max_jump_mm", &u.max_jump_mm,
        "a frame moving the object's centre farther than this is rejected, mm");
  r.Add("fusion.max_jump_deg", &u.max_jump_deg,
        "a frame turning the object more than this is rejected, degrees");
  r.Add("fusion.jump_held_frames", &u.jump_held_frames,
        "... unless the jump holds over this many frames in a row: then it is taken (0: never)");
  r.Add("fusion.anchor_contacts", &u.anchor_contacts,
        "contacts held over frames are anchored at one object point (off: paper's chaining)");
  r.Add("fusion.contact_noise_reference_mm", &u.contact_noise_reference_mm,
        "contacts' disagreement at which they hold icp.anchor_share in ICP (scaled by "
        "1/disagreement^2; 0: fixed share), mm");
  r.Add("fusion.anchor_slip_mm", &u.anchor_slip_mm,
        "a contact or feature farther than this from its anchor has slipped, mm");
  r.Add("fusion.anchor_features", &u.anchor_features,
        "visual features tracked over frames are anchored at one object point (off: matched "
        "frame to frame only)");
  r.Add("fusion.icp_contacts_need_spread", &u.icp_contacts_need_spread,
        "contacts hold ICP only when spread like pairwise.min_contact_spread_mm asks (off: one "
        "fingertip's patch holds it too, in the directions the surface leaves free)");
  r.Add("fusion.silhouette.weight", &u.silhouette.weight,
        "ICP holds the object's outline against the background to the model's edge; each "
        "outline point weighs this many surface pairs (0: off)");
  r.Add("fusion.silhouette.search_px", &u.silhouette.search_px,
        "how far along the outline's normal the model's edge is looked for, pixels");
  r.Add("fusion.silhouette.background_gap_mm", &u.silhouette.background_gap_mm,
        "a pixel next to the object is background when it lies this much farther or has no "
        "depth, mm");
  r.Add("fusion.silhouette.max_points", &u.silhouette.max_points,
        "outline points ICP uses at most");
  r.Add("fusion.silhouette.min_edge_facing", &u.silhouette.min_edge_facing,
        "the model's edge counts where its surface faces the camera at least this much (cosine; "
        "a crease, not a ball's outline)");
  r.Add("fusion.colour.enabled", &u.colour.enabled,
        "after ICP, the object's colours are aligned to the model's in the directions its "
        "surface leaves free (a patterned ball's or bottle's turn)");
  r.Add("fusion.colour.shading_blur_px", &u.colour.shading_blur_px,
        "the colour alignment compares the log grey less its blur by this, pixels (0: the grey)");
  r.Add("fusion.colour.remove_shading", &u.colour.remove_shading,
        "the colour alignment takes out of both images what the surface's normals explain");
  r.Add("fusion.colour.max_shading_share", &u.colour.max_shading_share,
        "where the normals explain more of the frame's detail, the colour alignment does not run");
  r.Add("fusion.colour.coarse_blur_px", &u.colour.coarse_blur_px,
        "the colour alignment's first blur of both grey images, pixels");
  r.Add("fusion.colour.fine_blur_px", &u.colour.fine_blur_px,
        "the colour alignment's second blur, pixels");
  r.Add("fusion.colour.iterations", &u.colour.iterations,
        "the colour alignment's Gauss-Newton iterations per blur");
  r.Add("fusion.colour.stride", &u.colour.stride,
        "the colour alignment uses every n-th object pixel each way");
  r.Add("fusion.colour.max_points", &u.colour.max_points,
        "the colour alignment uses at most about this many object pixels (a wider stride)");
  r.Add("fusion.colour.prior_mm", &u.colour.prior_mm,
        "the colour alignment's prior on its motion away from ICP's pose, mm RMS");
  r.Add("fusion.colour.max_depth_gap_mm", &u.colour.max_depth_gap_mm,
        "a pixel's colour is compared with the model's only where their depths differ less, mm");
  r.Add("fusion.colour.min_facing", &u.colour.min_facing,
        "the colour alignment leaves out model surface facing the camera less (cosine)");
  r.Add("fusion.colour.profile_mm", &u.colour.profile_mm,
        "the colour alignment judges its basin by the cost this far either way, mm");
  r.Add("fusion.colour.correlated_samples", &u.colour.correlated_samples,
        "object pixels whose colour residuals one blur footprint correlates");
  r.Add("fusion.colour.min_model_colourings", &u.colour.min_model_colourings,
        "the colour alignment compares the model's colour only where this many pixels coloured "
        "it");
  r.Add("fusion.colour.min_points", &u.colour.min_points,
        "object pixels the colour alignment needs");
  r.Add("fusion.colour.min_grey_spread", &u.colour.min_grey_spread,
        "the least spread of the frame's detail after the shading (100 x log grey) that the "
        "colour alignment takes for a pattern");
  r.Add("fusion.model_contacts.enabled", &u.model_contacts.enabled,
        "fingertips on the model's surface in the previous frame are contacts too");
  r.Add("fusion.model_contacts.distance_mm", &u.model_contacts.distance_mm,
        "a fingertip vertex within this of the model's surface (or inside) is on it, mm");
  r.Add("fusion.model_contacts.min_vertex_share", &u.model_contacts.min_vertex_share,
        "share of a fingertip's vertices on the surface that makes it a contact");
  r.Add("fusion.model_contacts.min_fingertips", &u.model_contacts.min_fingertips,
        "fingertips on the surface needed for any to count");
  r.Add("fusion.turn_carry.enabled", &u.turn_carry.enabled,
        "once the hand is seen turning the object one way, it carries the turn the surface "
        "leaves free (a ball's, a bottle's about its axis) and turning back leaves it");
  r.Add("fusion.turn_carry.window_frames", &u.turn_carry.window_frames,
        "frames with contacts over which the one-way turn is recognised");
  r.Add("fusion.turn_carry.recognise_deg", &u.turn_carry.recognise_deg,
        "the hand's net turn over those frames that recognises it, degrees");
  r.Add("fusion.turn_carry.min_consistency", &u.turn_carry.min_consistency,
        "the net turn's least share of all the turning in those frames");
  r.Add("fusion.turn_carry.smoothing_frames", &u.turn_carry.smoothing_frames,
        "frames the hand's turn is averaged over to tell turning on from back");
  r.Add("fusion.turn_carry.undecided_to_contacts", &u.turn_carry.undecided_to_contacts,
        "a hand turning neither on nor back leaves the frame to the contacts (off: taken for a "
        "turn back)");
  r.Add("fusion.turn_carry.catch_up_frames", &u.turn_carry.catch_up_frames,
        "once the turn is recognised, the object catches up the hand's turn in the last this "
        "many frames nothing registered (0: none)");
  r.Add("fusion.turn_carry.fast_back_kept_out", &u.turn_carry.fast_back_kept_out,
        "a frame whose hand turns back faster than max_frame_turn_deg keeps its contacts out too");
  r.Add("fusion.turn_carry.recognise_max_frame_deg", &u.turn_carry.recognise_max_frame_deg,
        "a frame's turn counts at most this much towards recognising it, degrees");
  r.Add("fusion.turn_carry.max_frame_turn_deg", &u.turn_carry.max_frame_turn_deg,
        "a hand turning farther than this in one frame was refitted, not followed, degrees");
  r.Add("fusion.turn_carry.surface_frames", &u.turn_carry.surface_frames,
        "frames over which ICP's free directions are counted");
  r.Add("fusion.turn_carry.min_free_share", &u.turn_carry.min_free_share,
        "least share of those frames with a free direction for the hand to carry the turn");
  r.Add("fusion.turn_carry.hand_weight", &u.turn_carry.hand_weight,
        "where the hand turns on, the weight of its turn against the registered one about the "
        "recognised axis (0: the registration's alone)");
  r.Add("fusion.coverage.max_incidence_deg", &u.coverage.max_incidence_deg,
        "a surface counts as seen from a camera within this angle of its normal, degrees "
        "(coverage)");
  r.Add("fusion.free_space.enabled", &u.free_space.enabled,
        "keep the depth of frames from new directions to bound the closed mesh by the space "
        "seen empty");
  r.Add("fusion.free_space.min_turn_deg", &u.free_space.min_turn_deg,
        "a frame is kept when the object has turned this far from every kept one, degrees");
  r.Add("fusion.free_space.max_views", &u.free_space.max_views, "views kept at most");
  r.Add("fusion.free_space.margin_mm", &u.free_space.margin_mm,
        "space counts as seen empty only this far in front of the measured depth, mm");
  r.Add("fusion.free_space.min_views", &u.free_space.min_views,
        "views that must see through a point for it to be empty");
  r.Add("fusion.free_space.no_depth_is_empty", &u.free_space.no_depth_is_empty,
        "pixels without depth far from any with depth are rays that met nothing");
  AddLoopClosureOptions(r, &u.loop_closure);
  AddTsdfOptions(r, options);
  AddRegistrationOptions(r, options);
}

void AddMeshingOptions(OptionRegistry& r, fusion::MeshingOptions* options) {
  fusion::MeshingOptions& m = *options;
  r.Add("mesh.min_component_fraction", &m.min_component_fraction,
        "pieces smaller than this share of the largest are dropped");
  r.Add("mesh.smoothing_iterations", &m.smoothing_iterations, "HC Laplacian iterations (0: none)");
  r.Add("mesh.smoothing_alpha", &m.smoothing_alpha, "HC alpha (Vollmer et al.: 0)");
  r.Add("mesh.smoothing_beta", &m.smoothing_beta, "HC beta (Vollmer et al.: 0.5)");
  r.Add("mesh.poisson", &m.poisson, "Poisson reconstruction into a watertight mesh");
  r.Add("mesh.poisson_depth", &m.poisson_depth,
        "Poisson octree depth (paper: 10; 9 is finer than the TSDF's voxels)");
  r.Add("mesh.poisson_samples_per_node", &m.poisson_samples_per_node,
        "Poisson minimum samples per octree node");
  r.Add("mesh.poisson_scale", &m.poisson_scale, "Poisson cube edge over the points' bounding box");
  r.Add("mesh.poisson_threads", &m.poisson_threads,
        "threads of Poisson's solve (0: one per core; more than 1 is faster but not the same "
        "mesh bit for bit from run to run)");
  r.Add("mesh.bound_voxel_mm", &m.bound_voxel_mm,
        "lattice step of the closed mesh cut back to the space not seen empty, mm");
  r.Add("mesh.bound_keep_seen_mm", &m.bound_keep_seen_mm,
        "nothing within this of the seen surface is cut, mm");
  r.Add("mesh.bound_by_seen_hull", &m.bound_by_seen_hull,
        "also cut the closed mesh to the convex hull of the seen surface (a bottle's unseen base "
        "ends flat at the lowest seen ring)");
  r.Add("mesh.bound_revolve_max_residual", &m.bound_revolve_max_residual,
        "a seen surface whose sections fit circles within this share of their radius is turned "
        "all round its axis before its hull is taken (its unseen round side is not cut; 0: never)");
  r.Add("mesh.bound_box_min_face_share", &m.bound_box_min_face_share,
        "otherwise, a seen surface this much of which faces along three orthogonal directions is "
        "bounded by its box along them, not its hull (a box's unseen corner is kept; 0: never)");
  r.Add("mesh.bound_box_outlier_share", &m.bound_box_outlier_share,
        "the box leaves out this share of the seen surface's vertices beyond each face (a blob "
        "of hand fused proud of a face is cut back to the face)");
  r.Add("mesh.repair_self_intersections", &m.repair_self_intersections,
        "a closed mesh whose faces cross is re-made from its signed distance on the bound's "
        "lattice");
  r.Add("mesh.color", &m.color, "per-vertex colours in the exported meshes");
}

void AddPipelineOptions(OptionRegistry& r, PipelineOptions* options) {
  PipelineOptions& p = *options;
  r.Add("pipeline.queue_capacity", &p.queue_capacity, "frames each queue between threads holds");
  r.Add("pipeline.preview_every", &p.preview_every,
        "write a preview image every this many fused frames (0: never)");
  r.Add("pipeline.max_frames", &p.max_frames, "stop after this many frames (0: all)");
  r.Add("pipeline.live_search_beside", &p.live_search_beside,
        "from a live source, the tracker's searches, its periodic check of the fit turned over "
        "and its scale estimate's fits run beside its tracking instead of stalling it");
  r.Add("pipeline.stop_grace_s", &p.stop_grace_s,
        "seconds the frames in hand get after a stop before a stage still busy is left behind "
        "and the model so far is exported without them (exit 5)");
}

OptionRegistry RegisterScannerOptions(ScannerOptions* options) {
  OptionRegistry r;
  AddScanOptions(r, &options->scan);
  AddTrackerOptions(r, &options->tracker);
  AddFeatureOptions(r, &options->sift, &options->shot);
  AddFusionOptions(r, &options->fusion);
  AddMeshingOptions(r, &options->meshing);
  AddPipelineOptions(r, &options->pipeline);
  return r;
}

}  // namespace ihs::app
