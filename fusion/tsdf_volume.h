#pragma once
// The object model: a truncated signed distance function (Curless & Levoy 1996, as KinectFusion
// keeps it) on a dense cube of voxels in the object frame, with a colour per voxel. Integration
// touches only the voxels within the truncation band of the observed pixels, so its cost grows
// with the object's pixels, not with the volume; raycasting gives the model's surface as a
// camera sees it (for ICP and previews); marching cubes gives its zero level set as a mesh.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "core/huge_pages.h"
#include "core/rigid3.h"
#include "core/triangle_mesh.h"

namespace ihs::fusion {

/// Options of the TSDF volume (defaults: the paper's 350 mm cube at 256³).
struct TsdfOptions {
  /// Edge of the cube, mm (paper: 350).
  double size_mm = 350.0;
  /// Voxels per edge (paper: 256; 1.37 mm voxels).
  int resolution = 256;
  /// Signed distances are truncated to ± this many voxels.
  double truncation_voxels = 4.0;
  /// Cap of a voxel's integration weight: past this many observations the average keeps
  /// following new ones instead of freezing.
  int max_weight = 128;
  /// Whether voxels keep a colour (the weighted mean of the pixels that saw them).
  bool color = true;
  /// A voxel takes a pixel's colour only within this many voxels of the surface seen through
  /// the pixel (along the ray; 0: anywhere in the truncation band): the pixels that colour a
  /// voxel are then those that saw its surface (a voxel off the surface takes the colour of the
  /// point where the pixel's ray meets it), and their count (Voxel::color_weight) says how
  /// often the model's colour there was seen (ColourAlignOptions::min_model_colourings).
  /// Raycasts and meshes interpolate the colour between the voxels that have one.
  double color_band_voxels = 1.0;
  /// Threads that integrate and raycast, the calling one among them (at most kMaxThreads).
  /// 0: one per core but one, which the pipeline's tracker thread keeps busy (on two cores the
  /// calling thread alone). Each voxel and each pixel is computed by one thread as it would be
  /// alone, so the model and its raycasts are the same to the bit whatever the number. With a
  /// core to spare, two threads took a whole paper session's integration from 2.6 to 1.9 ms a
  /// frame and its raycasts from 2.8 to 2.1 ms; on two cores beside the busy tracker thread
  /// its raycasts took 2.6 → 3.2 ms instead (docs/app.md).
  int threads = 0;
  static constexpr int kMaxThreads = 8;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// What the model looks like from a camera: per pixel (row-major, width·height), the depth of
/// the model's surface (mm, camera frame; 0 where the ray misses it), its unit normal in the
/// camera frame and its colour.
struct RaycastImage {
  int width = 0;
  int height = 0;
  std::vector<float> depth_mm;
  std::vector<Eigen::Vector3f> normals;
  std::vector<TriangleMesh::Color> colors;
  /// How many pixels coloured the model there (0: none; at most 255).
  std::vector<std::uint8_t> color_weights;
  /// The pixels a raycast may have written (u0, v0, u1, v1; exclusive ends): everything
  /// outside is zero.
  std::array<int, 4> written = {0, 0, 0, 0};
};

/// A TSDF on a dense voxel cube centred on the origin of its own frame (the object frame:
/// `volume` in transform names). 8 bytes per voxel (≈ 134 MB at 256³). Not thread-safe.
class TsdfVolume {
 public:
  explicit TsdfVolume(TsdfOptions options = {});

  /// Integrates the pixels of `frame` whose `mask` entry is non-zero (every pixel with depth
  /// when `mask` is empty), seen by a camera with `intrinsics` at `cam_from_volume`. Returns the
  /// number of voxels updated.
  int Integrate(const Frame& frame, const std::vector<std::uint8_t>& mask,
                const CameraIntrinsics& intrinsics, const Rigid3& cam_from_volume);

  /// Forgets every observation (a loop closure re-fuses the model from its keyframes).
  void Clear();

  /// The model's surface seen from `cam_from_volume`: the first zero crossing along each ray.
  /// Only the pixels in `roi` (u0, v0, u1, v1, exclusive ends; all when empty) are cast. With
  /// `near_depth_mm` (per pixel, row-major), a ray is cast only where it is non-zero and only
  /// within `window_mm` of that depth: for ICP, the model near the observed points is enough.
  RaycastImage Raycast(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_volume,
                       const std::array<int, 4>& roi = {0, 0, 0, 0},
                       const std::vector<std::uint16_t>* near_depth_mm = nullptr,
                       float window_mm = 0) const;
  /// The same into `image`, reusing its storage from an earlier call (only what that call
  /// wrote is cleared): a scan casts every frame, and fresh megabytes per frame cost page
  /// faults that doubled the raycast's time on every other frame.
  void Raycast(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_volume,
               const std::array<int, 4>& roi, const std::vector<std::uint16_t>* near_depth_mm,
               float window_mm, RaycastImage* image) const;

  /// The zero level set by marching cubes (volume frame, mm), over cells whose eight corners
  /// have all been observed; with per-vertex colour when kept. Vertices are shared between
  /// cells, so a fully observed closed surface gives a closed mesh; normals point outward.
  TriangleMesh ExtractMesh() const;

  /// The truncated signed distance at `point` (volume frame, mm), in mm, interpolated
  /// trilinearly; false where the point is outside the cube or a corner is unobserved.
  bool SignedDistance(const Eigen::Vector3f& point, float* distance_mm) const;

  double voxel_mm() const { return voxel_mm_; }
  double truncation_mm() const { return truncation_mm_; }
  const TsdfOptions& options() const { return options_; }
  /// Voxels observed at least once.
  std::int64_t ObservedVoxels() const;
  /// The box (volume frame, mm) around the voxels observed so far: the model's surface with
  /// its truncation band. Empty (`isEmpty()`) before the first integration.
  Eigen::AlignedBox3f ObservedBox() const;

 private:
  // The colour at `point` (volume frame, mm) for a cube of edge 2·`half` and voxel `voxel`.
  // and how many pixels coloured it there (the corners' weighted mean).
  TriangleMesh::Color ColorAt(const Eigen::Vector3f& point, float half, float voxel,
                              std::uint8_t* weight) const;
  struct Voxel {
    std::int16_t tsdf = 0;  // Signed distance / truncation, scaled to ±32767.
    std::uint16_t weight = 0;
    std::uint8_t rgb[3] = {0, 0, 0};
    std::uint8_t color_weight = 0;  // Pixels that coloured it (at most 255).
  };
  // Voxels lie in bricks of 8³ (4 KiB, x fastest inside a brick, then y, then z; the bricks in
  // the same order): a voxel's neighbours along all three axes are mostly in its own brick, so
  // integration and raycasting, which touch a thin shell of voxels, read a few pages instead of
  // one per voxel row (row-major, a step in z was 512 KiB away).
  static constexpr int kBrickShift = 3;
  static constexpr int kBrickEdge = 1 << kBrickShift;
  std::int64_t Index(int i, int j, int k) const {
    constexpr int mask = kBrickEdge - 1;
    const std::int64_t brick =
        (static_cast<std::int64_t>(k >> kBrickShift) * bricks_ + (j >> kBrickShift)) * bricks_ +
        (i >> kBrickShift);
    return (brick << (3 * kBrickShift)) |
           (((k & mask) << (2 * kBrickShift)) | ((j & mask) << kBrickShift) | (i & mask));
  }
  bool Sample(const Eigen::Vector3f& point, float* distance_mm) const;
  // The threads to split `rows` image rows among (TsdfOptions::threads).
  int Threads(int rows) const;
  // Integrate's two passes: marks in `bits` the voxels within the band of the observed pixels of
  // rows v_first, v_first + v_step, ... (and widens [*first_word, *last_word] to their words);
  // updates the voxels of the marked `words` (clearing their bits), widening `lo`/`hi` to them.
  // Returns the voxels updated.
  struct IntegrationView;
  void MarkBand(const IntegrationView& view, int v_first, int v_step, std::uint64_t* bits,
                std::int64_t* first_word, std::int64_t* last_word) const;
  int UpdateWords(const IntegrationView& view, const std::int64_t* words, size_t count,
                  std::array<int, 3>* lo, std::array<int, 3>* hi);
  // Ors the other threads' bits (each marked within its `ranges` entry: first and last word)
  // into the first thread's, clearing theirs, and lists the marked words in marked_words_.
  void GatherMarkedWords(const std::vector<std::array<std::int64_t, 2>>& ranges);
  // Raycast's two passes over rows v_first, v_first + v_step, ... of the cast region: the first
  // surface along each ray, then the hits' normals (which need the neighbouring rows' hits).
  struct RaycastView;
  void CastRows(const RaycastView& view, int v_first, int v_step, RaycastImage* image) const;
  void NormalRows(const RaycastView& view, int v_first, int v_step, RaycastImage* image) const;
  // The centre of voxel (i, j, k) in the volume frame.
  Eigen::Vector3f Centre(int i, int j, int k) const;

  const TsdfOptions options_;
  const int n_;
  // Bricks per edge: n_ / kBrickEdge rounded up (the voxels past n_ are never touched).
  const int bricks_;
  // Index bounds (inclusive) of the voxels updated so far; lo > hi while none is.
  std::array<int, 3> observed_lo_;
  std::array<int, 3> observed_hi_ = {-1, -1, -1};
  const double voxel_mm_;
  const double truncation_mm_;
  // Both are read at scattered places: in huge pages (core/huge_pages.h).
  std::vector<Voxel, HugePageAllocator<Voxel>> voxels_;
  // Scratch for Integrate: one bit per voxel for each thread marking, all zero between calls
  // (the first thread's made at construction, the others' when first needed).
  using Bits = std::vector<std::uint64_t, HugePageAllocator<std::uint64_t>>;
  std::vector<Bits> touched_bits_;
  // The marked words of a call, in memory order.
  std::vector<std::int64_t> marked_words_;
  // The cube's half edge, the voxel's edge (mm) and a stored distance's unit, as floats.
  const float half_mm_;
  const float voxel_mm_float_;
  const float mm_per_tsdf_unit_;
  // The voxels' centres along an axis (the same along each), mm.
  std::vector<float> centres_;
};

}  // namespace ihs::fusion
