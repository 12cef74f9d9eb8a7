#pragma once
// Hand pose fitting to the hand's depth points, as in the paper (and Tzionas et al., GCPR 2014):
// E(θ) = E_model→data + E_data→model + γc·E_collision with soft joint limits, minimised by
// iterated closest points: correspondences are recomputed in each outer iteration and the inner
// least-squares problem is solved with Ceres (Levenberg–Marquardt, analytic derivatives).

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "tracker/hand_model.h"
#include "tracker/hand_pose.h"
#include "tracker/local_surface.h"
#include "tracker/segmentation.h"

namespace ihs::tracker {

/// Options of the hand fit (defaults: the paper's γc; the rest tuned on generator sequences of
/// the scripted motion and checked on the recorded ones).
struct HandFitOptions {
  /// γc, weight of the collision term (paper: 10).
  double collision_weight = 10.0;
  /// Correspondence updates per frame, and Levenberg–Marquardt iterations per update (three
  /// updates suffice with the data points below; see max_data_points).
  int outer_iterations = 3;
  int inner_iterations = 5;
  /// An inner solve also stops once an iteration lowers its cost by less than this fraction
  /// (Ceres' function tolerance; its own default is 1e-6). Its correspondences are found anew
  /// at the next update anyway, and a fit that keeps creeping on stale ones only adds frame-to-
  /// frame jitter: on the four recorded motions the contact error's median fell from 1.9–2.3 to
  /// 1.4–1.75 mm at the same joint error, and the fit took a quarter less time; at 5e-2 the
  /// joint error grew by 2–3 mm.
  double inner_function_tolerance = 1e-2;
  /// Data points matched to the model (data → model) and visible model points matched to the
  /// data (model → data), at most; both are subsampled evenly. Which data points a stride picks
  /// changes from frame to frame, and with few of them the fingers jitter by that: with 500
  /// instead of 200 (and three updates instead of four) the contact error's median fell from
  /// 1.55–1.89 to 1.12–1.43 mm on the four recorded sessions and from 1.44–1.60 to 1.09–1.30 mm
  /// on four other object × motion stretches, the joint error moved by −1.2 to +0.8 mm per
  /// sequence and the frame took about 1 ms longer. More model points did not help.
  int max_data_points = 500;
  int max_model_points = 200;
  /// The data points matched to the model are the centroids of the hand points in cubes of
  /// this size (a grid fixed in the camera frame; every n-th of them beyond max_data_points),
  /// mm; 0: every n-th hand point instead. A centroid averages the sensor's noise over the
  /// pixels of its cube, and the same cube gives much the same centroid in the next frame,
  /// where a stride picks other pixels each frame. Over 22 sequences of the recorded motions
  /// (from the truth's first pose) the contact error's median fell on every one (over 1.5 mm
  /// on 5 → 0 of them; water bottle session 1.61 → 1.39 mm) and the joint error on 19 (mean
  /// 8.63 → 8.41 mm); 3 mm cubes gained less, 8 mm as much with worse self-initialised scans
  /// (docs/tracker.md). The fit's coverage and mean distance are still measured on the points.
  double data_voxel_mm = 5.0;
  /// Pairs farther apart than this are dropped, mm.
  double max_correspondence_mm = 40.0;
  /// Pairs farther apart than this count with a Huber weight, mm.
  double robust_scale_mm = 8.0;
  /// Weight of soft joint limits (per rad beyond a limit) and of the pull toward the initial
  /// (predicted) joint angles (per rad), which keeps unseen fingers where they were. A firmer
  /// pull (5) damps the fingers' jitter on the recorded motions (lower contact error) but makes
  /// them lag fast finger motion: the scripted re-grasps' scans drifted and lost the surface
  /// (docs/tracker.md, "A firmer pull").
  double limit_weight = 30.0;
  double prior_weight = 1.5;
  /// Weight of data → model pairs taken point to point, besides point to plane (relative to
  /// that): the planes of a finger's side let it slide along its axis, which a template of other
  /// proportions than the user's hand then does frame after frame.
  double data_point_weight = 2.0;
  /// Weight of the silhouette term: model points whose image falls outside the observed hand
  /// and object pixels are pulled back into them (in mm at the point's depth, as a mean over the
  /// model's points, like the other terms). Pixels this close to the silhouette count as inside.
  double silhouette_weight = 1.0;
  double silhouette_tolerance_px = 2.0;
  /// A model point seen (visible) where the depth image has a surface that neither mask holds
  /// — the segmentation drops thin slivers of a finger seen between the object and other
  /// fingers — is paired with that surface's nearest point within this distance (5×5 pixels
  /// around its image) when it is nearer than the nearest hand point, mm; 0: never (the
  /// default). Without it such a point is pulled to the nearest hand point, centimetres away:
  /// the procedural template with the scanned hand's layout, the unit tests' scripted left hand
  /// seen end-on from the wrist, had its middle fingertip pulled 39 mm off the true pose in one
  /// fit. Measured on twelve 300-frame stretches of the recorded motions it was slightly worse
  /// (docs/tracker.md), hence off.
  double unlabelled_match_mm = 0.0;
  /// Weight of the pull of fingertips held in contact onto the object's surface under them
  /// (SurfaceContact; the tracker passes the fingertips found touching in the previous frame):
  /// each held fingertip's vertices nearest that surface are pulled onto it, point to plane,
  /// as a mean over them like the data terms (relative to those). A fingertip that goes round
  /// behind the object loses the depth that placed it and the fit lets it wander off the
  /// surface it holds. Off (0): on 34 generated full turns it found no more contacts and held
  /// misplaced fingertips where the fit had put them (docs/tracker.md, "Fingertips held on the
  /// object's surface").
  double contact_surface_weight = 0.0;
  /// Initial Levenberg–Marquardt trust region: correspondences hold only near the current pose.
  double initial_trust_radius = 10.0;
  /// The volume the hand points were cropped to (camera frame, mm): model points outside it
  /// have no data to match and are not pulled toward any. Unbounded by default; the tracker
  /// sets it to the segmentation's crop volume.
  Eigen::Vector3d crop_min_mm = Eigen::Vector3d::Constant(-1e9);
  Eigen::Vector3d crop_max_mm = Eigen::Vector3d::Constant(1e9);

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The fitted pose and how well it explains the data.
struct HandFitResult {
  HandPose pose;
  /// Mean distance of the (subsampled) data points to the nearest model point, and of the
  /// visible model points to the nearest data point, mm.
  double data_error_mm = 0;
  double model_error_mm = 0;
  /// Share of data points within 10 mm of the model, and of visible model points within 10 mm
  /// of the data.
  double data_coverage = 0;
  double model_coverage = 0;
  /// Data points used.
  int data_points = 0;
};

/// A fingertip held on the object's surface (HandFitOptions::contact_surface_weight).
struct SurfaceContact {
  /// The fingertip's skin vertices (model vertex indices).
  std::vector<int> vertices;
  /// How many of them, those nearest the surface (or deepest inside it), are pulled onto it:
  /// the pad's share of the fingertip.
  int pulled = 1;
  /// The surface under the fingertip (camera frame).
  LocalSurface surface;
};

/// Fits a hand model to hand points. Holds the model (by reference: it must outlive the
/// fitter) and its collision proxies.
class HandFitter {
 public:
  HandFitter(const HandModel& model, const CameraIntrinsics& intrinsics,
             HandFitOptions options = {});
  ~HandFitter();

  /// Fits from `initial` (e.g. the previous pose, or a prediction) to `hand_points` (camera
  /// frame, mm). `frame` (optional) is the depth image they came from: model points hidden
  /// behind nearer surfaces (the object) are then not matched. `segmentation` (optional, of
  /// that frame) gives the silhouette the model must stay within. With no points the initial
  /// pose comes back with zero coverage. `contacts`: fingertips held on the object's surface
  /// (used with HandFitOptions::contact_surface_weight > 0).
  HandFitResult Fit(const std::vector<Eigen::Vector3f>& hand_points, const Frame* frame,
                    const HandPose& initial, const Segmentation* segmentation = nullptr,
                    const std::vector<SurfaceContact>& contacts = {}) const;

  const HandFitOptions& options() const { return options_; }

 private:
  struct Data;
  class FitState;  // One Fit call's state and steps (hand_fit.cc).
  const HandModel& model_;
  const CameraIntrinsics intrinsics_;
  const HandFitOptions options_;
  std::unique_ptr<Data> data_;
};

/// The pose of `model` whose 21 joints (HandModel::JointPositions) best match `joints_mm`
/// (camera frame), within soft joint limits: how a template of other proportions (the
/// procedural hand) takes over a pose known as joint positions (ground truth, another model).
HandPose FitPoseToJoints(const HandModel& model, const std::vector<Eigen::Vector3d>& joints_mm);

}  // namespace ihs::tracker
