#pragma once
// Where the object is not: the evidence that bounds the closure. The TSDF keeps only a band
// around the surface it saw, so a closure over what no frame saw (Poisson's) may balloon
// through space a ray crossed on its way to the background, the hand or the object's far side,
// and through the hand itself, whose fingers hide the object where they hold it. This keeps,
// from registered frames taken from directions not yet kept, the depth around the object, the
// posed hand model's extent along each pixel's ray (fingers behind the object included) and the
// camera's pose in the object frame; afterwards a point's emptiness is read off those views
// (space carving, as Kutulakos & Seitz; KinectFusion keeps the rays' part in its volume).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace ihs::fusion {

/// Options of the free-space evidence (defaults: Kinect-class depth of an object held at
/// 0.4–0.9 m).
struct FreeSpaceOptions {
  /// Keep views and bound the closed mesh by them (MakeMeshes).
  bool enabled = true;
  /// A registered frame is kept when the object has turned at least this far (degrees) from
  /// its pose in every view kept so far: a full turn keeps about 360 / this many views.
  double min_turn_deg = 4.0;
  /// At most this many views are kept (each 50–200 kB: the depth around the object and the
  /// hand's spans); later frames are not kept.
  int max_views = 200;
  /// The depth kept around the object's pixels: their bounding box grown on each side by this
  /// share of its size (room for the closure's guesses beside the object).
  double crop_margin = 0.5;
  /// A point counts as seen empty by a view only when it lies this far (mm, along the view's
  /// axis) in front of the measured depth: nearer the surface the TSDF's band (4 voxels of
  /// 1.37 mm by default) and the sensor's noise decide.
  double margin_mm = 5.5;
  /// A point is empty when at least this many views saw through it and more of them saw
  /// through it than saw a surface at it (a misregistered view alone removes nothing).
  int min_views = 2;
  /// Pixels without depth whose neighbours within `no_depth_radius_px` have none either count
  /// as rays that met nothing (beyond the sensor's range, the shadow beside an object); pixels
  /// without depth next to ones with depth (dropouts at edges, dark or shiny patches) say
  /// nothing. Off: only measured depth is evidence (and the hand).
  bool no_depth_is_empty = true;
  int no_depth_radius_px = 2;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// One kept view: the depth around the object and where the camera was.
struct DepthView {
  /// Depth value of a pixel whose ray met nothing (FreeSpaceOptions::no_depth_is_empty).
  static constexpr std::uint16_t kNothing = 0xFFFF;
  /// The fused frame's number (ObjectFusion's count), for a loop closure's correction.
  int stamp = 0;
  Rigid3 cam_from_object;
  /// The same in single precision, for the many points a bound projects.
  Eigen::Matrix3f rotation;
  Eigen::Vector3f translation;
  /// The crop of the image: its top-left pixel and size.
  int u0 = 0, v0 = 0, width = 0, height = 0;
  /// Row-major depth of the crop, mm; 0 where there is no evidence, kNothing where the ray met
  /// nothing.
  std::vector<std::uint16_t> depth_mm;
  /// Where a pixel's ray runs inside the posed hand model: from `near_mm` to `far_mm` (depth
  /// along the axis) at crop column `u`. Sorted by row, then column; a row's spans are
  /// `hand_spans[hand_row_start[v]]` up to `hand_spans[hand_row_start[v + 1]]` (no hand: both
  /// empty).
  struct HandSpan {
    std::uint16_t u = 0;
    std::uint16_t near_mm = 0;
    std::uint16_t far_mm = 0;
  };
  std::vector<HandSpan> hand_spans;
  std::vector<std::uint32_t> hand_row_start;

  /// The deepest a point at crop pixel (u, v), depth `z_mm`, lies inside a hand span (mm from
  /// its nearer end; negative outside every span).
  float DepthInsideHand(int u, int v, float z_mm) const;
};

/// How the views voted on a point (FreeSpace::Emptiness).
struct EmptinessVotes {
  /// Views that saw through it (by more than the margin), those of them that had it inside the
  /// hand, and views that saw a surface within the margin of it.
  int through = 0;
  int in_hand = 0;
  int at_surface = 0;
};

/// The kept views. Copies share the views (a snapshot for the export thread costs pointers).
class FreeSpace {
 public:
  FreeSpace(const CameraIntrinsics& intrinsics, FreeSpaceOptions options = {});
  /// No views: bounds nothing.
  FreeSpace() : FreeSpace(CameraIntrinsics{}) {}

  /// Considers a registered frame: its whole depth (hand and background included) seen from
  /// `cam_from_object`, the object's pixels inside `object_box` (u0, v0, u1, v1; exclusive
  /// ends), and the posed hand model (`hand`, camera frame, closed; null: none). Returns
  /// whether it was kept. `stamp` numbers the frame (DepthView::stamp).
  bool Observe(const Frame& frame, const std::array<int, 4>& object_box,
               const Rigid3& cam_from_object, const TriangleMesh* hand = nullptr, int stamp = 0);
  /// Moves every view's object frame by `correction(stamp)` (new cam_from_object = old ·
  /// correction): a loop closure corrected the poses it was seen from. Views shared with
  /// earlier copies are copied, not changed.
  void Repose(const std::function<Rigid3(int stamp)>& correction);

  /// How deep `point` (object frame, mm) lies inside space the views saw empty, clamped to
  /// [−limit, limit]: positive where at least `min_views` views saw through it by more than
  /// the margin, or had it inside the hand by more than the margin (the `min_views`-th largest
  /// of those distances), and more saw through it than saw a surface at it; negative
  /// elsewhere.
  float Emptiness(const Eigen::Vector3f& point, float limit,
                  EmptinessVotes* votes = nullptr) const;
  /// The same for many points, one view at a time (faster for many: each view's depth stays in
  /// the cache).
  std::vector<float> Emptiness(const std::vector<Eigen::Vector3f>& points, float limit) const;

  int views() const { return static_cast<int>(views_.size()); }
  const FreeSpaceOptions& options() const { return options_; }

 private:
  struct Tally;
  // Adds `view`'s vote on `point` (object frame) to `tally`.
  void Vote(const DepthView& view, const Eigen::Vector3f& point, float limit, Tally* tally) const;
  // The emptiness the votes give.
  float Result(const Tally& tally, float limit) const;

  CameraIntrinsics intrinsics_;
  FreeSpaceOptions options_;
  std::vector<std::shared_ptr<const DepthView>> views_;
};

}  // namespace ihs::fusion
