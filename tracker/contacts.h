#pragma once
// Contact points exactly as the paper defines them: for each end-effector (distal phalanx),
// count its vertices within `threshold` of the nearest object point; more than `min_vertices`
// makes it a contact bone and all its vertices contact vertices. With fewer than `min_bones`
// contact bones, the threshold grows by `step_mm` and the count is repeated (up to `max_mm`).
// A grown threshold is kept only where it finds `min_bones` together (the grasp); otherwise the
// bones within the first threshold are the contacts. Beyond the paper, the object's surface is
// continued under each fingertip (ContactOptions::surface_mm), where the finger hides it.

#include <Eigen/Core>
#include <vector>

#include "tracker/hand_model.h"

namespace ihs {
class PointKdTree;
}  // namespace ihs

namespace ihs::tracker {

/// Options of the contact detection (defaults: the paper's, with the growth bounded at 10 mm).
struct ContactOptions {
  /// First distance threshold, its growth per retry and its largest value, mm. The bound is
  /// about the tracker's joint error (8–10 mm with the procedural template): a fingertip that
  /// pinches an object from the side is fitted that far off the little of the object's surface
  /// the camera sees under it. At 6 mm the second fingertip of a grasp was missed in 447 of the
  /// sphere session's 1680 frames and the scan lost the turns made in them (47.9 % of the ball
  /// scanned, +8.4 % volume; at 10 mm 90.7 %, +1.1 %).
  double start_mm = 1.0;
  double step_mm = 0.5;
  double max_mm = 10.0;
  /// Vertices within the threshold that make a contact bone, for a fingertip of
  /// `reference_fingertip_vertices` (the paper's hand model: 40 of about 350); templates with
  /// coarser or finer fingertips scale it by their own vertex count.
  int min_vertices = 40;
  int reference_fingertip_vertices = 350;
  /// Contact bones wanted before the threshold stops growing.
  int min_bones = 2;
  /// The surface under a fingertip (beyond the paper). A touching pad hides the object's
  /// surface it rests on, so the object points the camera sees lie around the finger's outline,
  /// 10-30 mm from the pad (a generated egg grasped: median 15 mm from the touching fingertips,
  /// 44 mm from the others), beyond any threshold that leaves out a lifted finger. With
  /// `surface_mm` > 0 the surface is continued under the fingertip: a sphere (or, where the
  /// points are flat, a plane) fitted to the object points within `surface_patch_mm` of the
  /// fingertip's centre — at least `surface_min_points` of them, lying within
  /// `surface_max_rms_mm` (RMS) of it: a patch across an edge or two surfaces is not continued
  /// — and a vertex's distance to that surface, where it is at most `surface_mm`, stands for its
  /// distance to the object when nearer than the seen points. The
  /// fitted fingertips' distance to the surface is about the truth's where their position
  /// along it is 5-10 mm off (the egg: median 8.9 against 8.2 mm, tip joint to surface), so
  /// the bound can stay small. On 36 generated lathe and ball full turns contacts were used in
  /// a median 63 % instead of 55 % of the grasping frames (false 2 instead of 3 %); the turn
  /// followed came nearer the truth's on 14, farther on 9 (docs/fusion.md, "Contacts under the
  /// fingertips"). The patches' RMS: a vase's 0.8 mm median, a plain box's 1.8 (edges).
  /// 0: off (the paper's rule alone).
  double surface_mm = 4.0;
  double surface_patch_mm = 25.0;
  int surface_min_points = 15;
  double surface_max_rms_mm = 1.5;
  /// A patch no one surface explains (a box's edge in it: 2-4.5 mm RMS around the touching
  /// fingertips of a generated box turn) is continued by the surface nearest the fingertip
  /// (SurfaceAround's `trim`).
  bool surface_trim = false;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// A fingertip's contact distance where no vertex of it has an object point near (mm).
inline constexpr double kNoContactMm = 1e9;

/// The contacts of one frame.
struct Contacts {
  /// End-effector bones in contact, and all their vertices (the contact vertices).
  std::vector<int> bones;
  std::vector<int> vertices;
  /// The threshold at which they were found, mm (the first one, `start_mm`, when the growth
  /// found no grasp).
  double threshold_mm = 0;
  /// 0 when detected in this frame; else how many frames the grasp has been held without
  /// being detected (GraspHold), this one included.
  int held_frames = 0;
  /// Per end-effector (HandModel::EndEffectors order), the smallest threshold at which the
  /// detection counts it a contact bone, mm (kNoContactMm where none would): how far its pad
  /// is from the object's surface.
  std::vector<double> tip_distance_mm;
};

/// Finds contacts of a posed hand with the object's points.
class ContactDetector {
 public:
  explicit ContactDetector(const HandModel& model, ContactOptions options = {});

  /// `posed_vertices`: the hand's skin vertices in the camera frame (model vertex order);
  /// `object_points`: a tree over the object's points (camera frame). Select(TipDistances()).
  Contacts Detect(const std::vector<Eigen::Vector3f>& posed_vertices,
                  const PointKdTree& object_points) const;
  /// Each end-effector's contact distance (Contacts::tip_distance_mm).
  std::vector<double> TipDistances(const std::vector<Eigen::Vector3f>& posed_vertices,
                                   const PointKdTree& object_points) const;
  /// The contacts of these contact distances; `tip_limits_mm`, where given, per end-effector
  /// the largest threshold at which it may count (ReleaseWatch::Limits).
  Contacts Select(std::vector<double> tip_distance_mm,
                  const std::vector<double>* tip_limits_mm = nullptr) const;

  /// The vertices of each end-effector (those skinned mostly to it), EndEffectors order.
  const std::vector<std::vector<int>>& fingertip_vertices() const { return fingertip_vertices_; }
  /// Per end-effector, the vertices within the threshold that make it a contact bone (the
  /// pad's share of the fingertip).
  const std::vector<int>& min_vertices() const { return min_vertices_; }

 private:
  const ContactOptions options_;
  std::vector<int> end_effectors_;
  std::vector<std::vector<int>> fingertip_vertices_;
  std::vector<int> min_vertices_;  // Per end-effector, scaled to its vertex count.

  // Each vertex's distance to the object's surface continued under fingertip `e` (1e9 where
  // the points around it are too few or fit no sphere or plane), mm.
  std::vector<float> SurfaceDistances(size_t e, const std::vector<Eigen::Vector3f>& posed_vertices,
                                      const std::vector<Eigen::Vector3f>& object_points) const;
};

}  // namespace ihs::tracker
