#pragma once
// Evaluating a scan against a generator's ground truth the way the paper does: Table 1 (the
// objects' dimensions), Table 2 (pairwise registration error at the fingertip contact points),
// and the surface's Chamfer distance and completeness after aligning by the known trajectory.
// Shared by inhandscan-scan, inhandscan-measure and the benchmark.

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/trajectory_io.h"
#include "core/triangle_mesh.h"
#include "fusion/measure.h"

namespace ihs::eval {

/// One of the paper's Table 1 measures.
struct DimensionRow {
  std::string measure;  ///< e.g. "diameter", "height", "head diameter".
  double truth_mm = 0;
  double captured_mm = 0;
  double Error() const { return captured_mm - truth_mm; }
};

/// The paper's measures of an object ("sphere": diameter; the bottles: height and diameter;
/// "bowling-pin": height, body and head diameters; any other body of revolution: height and
/// widest diameter), truth from `object_spec` (a paper object's name or `lathe:FILE`) and the
/// captured values measured on `scan`. Throws std::invalid_argument for an unknown object.
std::vector<DimensionRow> PaperDimensions(const std::string& object_spec, const TriangleMesh& scan);

/// Whether `mesh` is a box: MeasureBox finds at least 90 % of its area facing along three
/// orthogonal directions (a box's or a cube's true mesh: all of it; a bottle's: a third at most).
bool IsBox(const TriangleMesh& mesh);

/// A box's sides, longest first ("longest side", "middle side", "shortest side"): the extents of
/// `truth` (a box, IsBox) along its faces' directions, and of `scan` along the directions its own
/// faces gather around (fusion::MeasureBox, every vertex counted: what calipers would measure).
/// Compared by length, longest with longest, so neither needs the other's frame.
std::vector<DimensionRow> BoxDimensions(const TriangleMesh& truth, const TriangleMesh& scan);

/// The true dimensions of `object_spec`, measured on its densely resampled lathe mesh by the
/// same code that measures scans.
fusion::RevolutionMeasures TrueMeasures(const std::string& object_spec);

/// The volume enclosed by `object_spec`'s profile revolved (frustum by frustum), mm³.
double TrueVolume(const std::string& object_spec);

/// Pairwise registration error at the fingertip contact points (the paper's Table 2): for every
/// pair of consecutive frames both registered by the scan, and every fingertip touching the
/// object in both (ground truth), the object's surface point under that fingertip is carried
/// from the first frame to the second by the scan's relative motion and by the true one; the
/// error is the distance between the two.
struct PairwiseError {
  double mean_mm = 0;
  double std_mm = 0;
  double median_mm = 0;
  int samples = 0;
};

/// `gt_dir`: a generator's gt/ folder; `trajectory`: the scan's cam_from_object per registered
/// frame, stamped with the frames' timestamps.
PairwiseError ContactPairwiseError(const std::filesystem::path& gt_dir,
                                   const std::vector<StampedPose>& trajectory);

/// The scan (object frame of the scan) against the true object, placed into the true object's
/// frame by the first registered frame: Chamfer distance and completeness.
fusion::SurfaceComparison CompareWithTruth(const std::filesystem::path& gt_dir,
                                           const TriangleMesh& scan,
                                           const std::vector<StampedPose>& trajectory);

/// Drift of the scan's object trajectory: at every registered frame, how far the true object's
/// surface points are from where the scan puts them, both trajectories tied together at the
/// first registered frame (mean over the object's vertices), mm; and how far the scan's object
/// is turned from the true one (the angle of the rotation between them, degrees).
struct TrajectoryError {
  double mean_mm = 0;
  double max_mm = 0;
  double final_mm = 0;
  /// The rotation error: mean, largest and at the last compared frame, degrees.
  double rotation_mean_deg = 0;
  double rotation_max_deg = 0;
  double rotation_final_deg = 0;
  /// How far the object turned over the compared frames, the angles of the steps between
  /// consecutive compared frames summed (a full turn about one axis: 360), degrees: the truth's,
  /// and the scan's along the truth's step axes (a scan that follows none of the turn: 0).
  double truth_turned_deg = 0;
  double scan_turned_deg = 0;
  /// Where the turn was lost or made up: the steps in which the truth stood still (turned
  /// less than 0.05°: the object let go, the hand swinging back), how many, and the scan's
  /// turn in them about the truth's turn axis (its steps' axes summed, object frame; negative:
  /// turned back) and in all (its steps' angles summed; a scan that holds the object: 0),
  /// degrees.
  int still_steps = 0;
  double scan_turned_still_deg = 0;
  double scan_wandered_still_deg = 0;
  int frames = 0;
  /// Per compared frame: its time stamp (s) and its error (mm).
  std::vector<double> times_s, errors_mm;
};
TrajectoryError CompareTrajectory(const std::filesystem::path& gt_dir,
                                  const std::vector<StampedPose>& trajectory);

/// Whether the scan used fingertip contacts in a frame (time stamp, s): in the registration or
/// as ICP's anchors.
struct FrameContactUse {
  double time_s = 0;
  bool used = false;
  /// The fingers the tracker found touching (0 pinky, 1 ring, 2 middle, 3 index, 4 thumb, as
  /// HandModel::FingerOf); empty: not known, any finger counts.
  std::vector<int> fingers;
};

/// The contacts against the truth (gt/contacts.csv): of the frames where the truth has at least
/// two fingertips touching the object (a grasp), how many used contacts (recall); of the frames
/// that used contacts, how many had none of their fingers (FrameContactUse::fingers; any
/// finger where they are not known) within `false_mm` of the object (false contacts). Judged by
/// the fingers used: the scripted grasps curl the ring and little fingers 3 mm from the object
/// all along, and a frame whose contacts were fingers hovering 9 mm away counted as true.
struct ContactUse {
  int grasp_frames = 0;
  int used_in_grasp = 0;
  int used_frames = 0;
  int false_frames = 0;
  double recall = 0;
  double false_share = 0;
};
ContactUse CompareContactUse(const std::filesystem::path& gt_dir,
                             const std::vector<FrameContactUse>& frames, double false_mm = 3.0);

/// How near the tracker put the fingertips that grasp (gt/contacts.csv: the frames where the
/// truth has at least two touching): per distance in `within_mm`, the share of those frames in
/// which at least two of the touching fingers' tips in `tracked_csv` (a scan's or the tracker's
/// hand_joints.csv) lie within it of the truth's (gt/hand_joints.csv). A contact is found only
/// where the fitted fingertip is near the object, so this bounds the contact recall. A frame the
/// tracked file lacks counts as not within. Throws ihs::InputError for unreadable files.
struct GraspTips {
  int grasp_frames = 0;
  std::vector<double> within_mm;
  std::vector<double> share;  ///< One per `within_mm`.
};
GraspTips CompareGraspTips(const std::filesystem::path& gt_dir,
                           const std::filesystem::path& tracked_csv,
                           const std::vector<double>& within_mm = {6.0, 10.0, 15.0});

/// The pixels gt/labels/<index>.png (the generator's labels) marks as the object, row-major,
/// 1 where it is; empty when the file is missing or not `width` × `height`.
std::vector<std::uint8_t> TruthObjectPixels(const std::filesystem::path& gt_dir, std::int64_t index,
                                            int width, int height);

/// What a recording showed of the object at all: every frame's object pixels (gt/labels/, the
/// generator's) back-projected from the frame's own depth and placed in the truth's object frame
/// by the truth's pose. The share of the true surface within `within_mm` of those points is the
/// completeness a scan of this recording could reach with perfect registration (the bottom of a
/// bottle the camera never faces, a ball's patch always under the fingers are missing from it):
/// the scale a scan's completeness is read on.
class ShownSurface {
 public:
  /// Throws InputError when `gt_dir` lacks its trajectory, labels or object.
  ShownSurface(const std::filesystem::path& gt_dir, const CameraIntrinsics& intrinsics);

  /// Adds `frame`'s object pixels (its depth timestamp finds the truth's pose and labels; a
  /// frame the truth does not have adds nothing). Throws InputError when its labels are missing.
  void Add(const Frame& frame);
  /// The same with the frame's object pixels already read (TruthObjectPixels).
  void Add(const Frame& frame, const std::vector<std::uint8_t>& object_pixels);

  /// The share of the true surface (gt/object.ply) within `within_mm` of what was shown.
  double Share(double within_mm = 2.0) const;

 private:
  std::filesystem::path gt_dir_;
  CameraIntrinsics intrinsics_;
  std::vector<StampedPose> truth_;
  // One shown point per millimetre cube of the object frame.
  std::unordered_map<std::int64_t, Eigen::Vector3f> points_;
};

/// Prints a scan's measures as a table for people on `out` (nullptr: prints nothing) and returns
/// them as JSON: with
/// `object` (a paper object or lathe:FILE) the paper's dimensions measured on `seen` ("dimensions",
/// "dimension_error_mm_mean") and, when `watertight` is another mesh, on it too (what the user
/// gets: "dimensions_watertight", "dimension_error_mm_mean_watertight"), and when `watertight`
/// is watertight, its volume against the truth
/// ("volume_mm3", "volume_error"); with `gt_dir` the pairwise registration error at the
/// fingertips, the trajectory's drift, how far the object turned ("rotation_error_deg",
/// "turned_deg") and `seen` against the true surface ("pairwise_error_mm", "trajectory_error_mm",
/// "chamfer_mm", "completeness" within "completeness_within_mm"), `seen` placed by `trajectory`.
/// With `unseen_share` (the share of `watertight`'s surface no frame saw: fusion::UnseenShare,
/// which every export computes) the volume comes with it ("volume_unseen_share"). An `object`
/// the paper's measures do not know (IsBodyOfRevolution: a box, a cube) or none gets no
/// dimensions; with `gt_dir` its volume is then measured against gt/object.ply's.
nlohmann::json ReportScan(const std::string& object, const TriangleMesh& seen,
                          const TriangleMesh& watertight, const std::filesystem::path& gt_dir,
                          const std::vector<StampedPose>& trajectory,
                          std::optional<double> unseen_share, std::FILE* out = stdout);

/// Whether the paper's measures know `object` (a generator object's name or spec): the paper's
/// four bodies of revolution and "lathe:FILE".
bool IsBodyOfRevolution(const std::string& object);

/// Why `object` is not one (a command-line option's error), or "" when it is.
std::string NotABodyOfRevolution(const std::string& object);

/// The volume of `watertight` against `truth_mm3` (ReportScan's line; e.g. gt/object.ply's volume
/// for an object that is no body of revolution), printed to `out` unless it is null and added to
/// `report`: "volume_mm3", "volume_error" and, with `unseen_share`, "volume_unseen_share".
void ReportVolume(double truth_mm3, const TriangleMesh& watertight,
                  std::optional<double> unseen_share, std::FILE* out, nlohmann::json* report);

/// The pose of `trajectory` stamped `time_s` (within half a millisecond), or nullptr.
const StampedPose* FindPose(const std::vector<StampedPose>& trajectory, double time_s);

}  // namespace ihs::eval
