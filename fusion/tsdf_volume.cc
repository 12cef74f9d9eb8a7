#include "fusion/tsdf_volume.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include "core/check.h"
#include "core/parallel_runs.h"
#include "fusion/marching_cubes.h"

namespace ihs::fusion {
namespace {

constexpr float kTsdfScale = 32767.0f;

// The nearest integer, halves away from zero: std::lround without its library call.
inline int RoundToInt(float x) { return static_cast<int>(x >= 0 ? x + 0.5f : x - 0.5f); }

}  // namespace

void TsdfOptions::Check() const {
  IHS_CHECK_ARG(size_mm >= 20 && size_mm <= 5000,
                "tsdf.size_mm must be in [20, 5000] (a hand-held object's cube), got " << size_mm);
  // 8 bytes a voxel: 512³ voxels take 1 GiB, 1024³ 8 GiB.
  IHS_CHECK_ARG(resolution >= 8 && resolution <= 512,
                "tsdf.resolution must be in [8, 512] (512³ voxels take 1 GiB), got " << resolution);
  IHS_CHECK_ARG(truncation_voxels >= 1 && truncation_voxels <= 64,
                "tsdf.truncation_voxels must be in [1, 64], got " << truncation_voxels);
  IHS_CHECK_ARG(max_weight >= 1 && max_weight <= 65535,
                "tsdf.max_weight must be in [1, 65535], got " << max_weight);
  IHS_CHECK_ARG(threads >= 0,
                "tsdf.threads must be >= 0 (0: one per core but one), got " << threads);
  IHS_CHECK_ARG(
      color_band_voxels >= 0,
      "tsdf.color_band_voxels must be >= 0 (0: the whole band), got " << color_band_voxels);
}

TsdfVolume::TsdfVolume(TsdfOptions options)
    : options_((options.Check(), options)),
      n_(options_.resolution),
      bricks_((n_ + kBrickEdge - 1) / kBrickEdge),
      observed_lo_{n_, n_, n_},
      voxel_mm_(options_.size_mm / options_.resolution),
      truncation_mm_(options_.truncation_voxels * voxel_mm_),
      voxels_(static_cast<size_t>(bricks_) * bricks_ * bricks_ << (3 * kBrickShift)),
      touched_bits_(1, Bits((voxels_.size() + 63) / 64, 0)),
      half_mm_(static_cast<float>(0.5 * options_.size_mm)),
      voxel_mm_float_(static_cast<float>(voxel_mm_)),
      mm_per_tsdf_unit_(static_cast<float>(truncation_mm_) / kTsdfScale) {
  // Computed in double, each axis on its own, then rounded: as Centre always was.
  const double half = 0.5 * options_.size_mm;
  for (int i = 0; i < n_; ++i)
    centres_.push_back(static_cast<float>(-half + (i + 0.5) * voxel_mm_));
}

void TsdfVolume::Clear() {
  // The bricks around the observed box, whole: their voxels outside it were never observed.
  constexpr int brick_voxels = 1 << (3 * kBrickShift);
  auto bricks = [&](int a) {
    return std::array<int, 2>{observed_lo_[a] >> kBrickShift, observed_hi_[a] >> kBrickShift};
  };
  const auto [bi0, bi1] = bricks(0);
  const auto [bj0, bj1] = bricks(1);
  const auto [bk0, bk1] = bricks(2);
  for (int bk = bk0; bk <= bk1; ++bk) {
    for (int bj = bj0; bj <= bj1; ++bj) {
      for (int bi = bi0; bi <= bi1; ++bi) {
        const std::int64_t first = Index(bi << kBrickShift, bj << kBrickShift, bk << kBrickShift);
        std::fill_n(voxels_.begin() + first, brick_voxels, Voxel{});
      }
    }
  }
  observed_lo_ = {n_, n_, n_};
  observed_hi_ = {-1, -1, -1};
}

Eigen::Vector3f TsdfVolume::Centre(int i, int j, int k) const {
  return Eigen::Vector3f(centres_[i], centres_[j], centres_[k]);
}

Eigen::AlignedBox3f TsdfVolume::ObservedBox() const {
  Eigen::AlignedBox3f box;  // Empty.
  if (observed_hi_[0] < observed_lo_[0]) return box;
  const float half = static_cast<float>(0.5 * options_.size_mm);
  const float voxel = static_cast<float>(voxel_mm_);
  for (int a = 0; a < 3; ++a) {
    box.min()[a] = -half + observed_lo_[a] * voxel;
    box.max()[a] = -half + (observed_hi_[a] + 1) * voxel;
  }
  return box;
}

std::int64_t TsdfVolume::ObservedVoxels() const {
  return std::count_if(voxels_.begin(), voxels_.end(), [](const Voxel& v) { return v.weight > 0; });
}

int TsdfVolume::Threads(int rows) const {
  const int wanted = options_.threads > 0 ? options_.threads : std::max(1, ThreadsFor(0) - 1);
  return std::min({wanted, TsdfOptions::kMaxThreads, std::max(1, rows)});
}

struct TsdfVolume::IntegrationView {
  IntegrationView(const Frame& f, const std::vector<std::uint8_t>& m, const CameraIntrinsics& c)
      : frame(f), mask(m), intrinsics(c) {}
  const Frame& frame;
  const std::vector<std::uint8_t>& mask;
  const CameraIntrinsics& intrinsics;
  // volume_from_cam, and cam_from_volume, as floats.
  Eigen::Matrix3f rotation;
  Eigen::Vector3f translation;
  Eigen::Matrix3f cam_rotation;
  Eigen::Vector3f cam_translation;
  // The truncation band, mm.
  float band = 0;
  // Half-voxel samples along a ray across the band.
  int samples = 0;
  bool color = false;
  // Voxels this near the surface (mm, along the ray) take a pixel's colour.
  float color_band = 0;
  bool Observed(int pixel) const {
    return frame.depth_mm[pixel] != 0 && (mask.empty() || mask[pixel] != 0);
  }
};

int TsdfVolume::Integrate(const Frame& frame, const std::vector<std::uint8_t>& mask,
                          const CameraIntrinsics& intrinsics, const Rigid3& cam_from_volume) {
  IHS_CHECK_ARG(mask.empty() || mask.size() == frame.depth_mm.size(),
                "mask has " << mask.size() << " entries, the frame " << frame.depth_mm.size());
  IHS_CHECK_ARG(frame.width == intrinsics.width && frame.height == intrinsics.height,
                "frame " << frame.width << "x" << frame.height << " but intrinsics "
                         << intrinsics.width << "x" << intrinsics.height);
  const Rigid3 volume_from_cam = cam_from_volume.Inverse();
  IntegrationView view(frame, mask, intrinsics);
  view.rotation = volume_from_cam.rotation().cast<float>();
  view.translation = volume_from_cam.translation().cast<float>();
  view.cam_rotation = cam_from_volume.rotation().cast<float>();
  view.cam_translation = cam_from_volume.translation().cast<float>();
  view.band = static_cast<float>(truncation_mm_);
  view.samples = static_cast<int>(std::floor(2.0f * view.band / (0.5f * voxel_mm_float_))) + 1;
  view.color = options_.color && frame.HasColor();
  view.color_band = options_.color_band_voxels > 0
                        ? static_cast<float>(options_.color_band_voxels) * voxel_mm_float_
                        : view.band;

  // The voxels within the band of the observed pixels, each thread marking those of every
  // threads-th row in bits of its own, then gathered in memory order (each voxel once).
  const int threads = Threads(frame.height);
  while (static_cast<int>(touched_bits_.size()) < threads)
    touched_bits_.emplace_back(touched_bits_.front().size(), 0);
  std::vector<std::array<std::int64_t, 2>> ranges(
      threads, {static_cast<std::int64_t>(touched_bits_.front().size()), -1});
  ParallelRuns(threads, threads, [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      MarkBand(view, static_cast<int>(t), threads, touched_bits_[t].data(), &ranges[t][0],
               &ranges[t][1]);
    }
  });
  GatherMarkedWords(ranges);

  // Projective update of each, the marked words split among the threads.
  std::vector<std::array<int, 3>> lo(threads, observed_lo_), hi(threads, observed_hi_);
  std::vector<int> updated(threads, 0);
  const size_t words = marked_words_.size();
  ParallelRuns(threads, threads, [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) {
      const size_t from = words * t / threads, to = words * (t + 1) / threads;
      updated[t] = UpdateWords(view, marked_words_.data() + from, to - from, &lo[t], &hi[t]);
    }
  });
  int total = 0;
  for (int t = 0; t < threads; ++t) {
    total += updated[t];
    for (int a = 0; a < 3; ++a) {
      observed_lo_[a] = std::min(observed_lo_[a], lo[t][a]);
      observed_hi_[a] = std::max(observed_hi_[a], hi[t][a]);
    }
  }
  return total;
}

void TsdfVolume::GatherMarkedWords(const std::vector<std::array<std::int64_t, 2>>& ranges) {
  std::int64_t first_word = ranges[0][0], last_word = ranges[0][1];
  for (const auto& [first, last] : ranges) {
    first_word = std::min(first_word, first), last_word = std::max(last_word, last);
  }
  marked_words_.clear();
  std::uint64_t* bits = touched_bits_.front().data();
  for (std::int64_t w = first_word; w <= last_word; ++w) {
    for (size_t t = 1; t < ranges.size(); ++t) {
      if (w < ranges[t][0] || w > ranges[t][1]) continue;
      bits[w] |= touched_bits_[t][w];
      touched_bits_[t][w] = 0;
    }
    if (bits[w] != 0) marked_words_.push_back(w);
  }
}

void TsdfVolume::MarkBand(const IntegrationView& view, int v_first, int v_step, std::uint64_t* bits,
                          std::int64_t* first_word, std::int64_t* last_word) const {
  const Frame& frame = view.frame;
  // Kept in locals until the end: the threads' outputs share cache lines.
  std::int64_t first = *first_word, last = *last_word;
  for (int v = v_first; v < frame.height; v += v_step) {
    for (int u = 0; u < frame.width; ++u) {
      const int pixel = v * frame.width + u;
      if (!view.Observed(pixel)) continue;
      const Eigen::Vector3f point =
          view.intrinsics.BackProject(u, v, frame.depth_mm[pixel]).cast<float>();
      const Eigen::Vector3f ray = point.normalized();
      // Half-voxel steps along the ray, in voxel units of the volume's grid.
      const Eigen::Vector3f step = view.rotation * ray * 0.5f;
      Eigen::Vector3f grid =
          ((view.rotation * (point - view.band * ray) + view.translation).array() + half_mm_) /
          voxel_mm_float_;
      for (int s = 0; s < view.samples; ++s, grid += step) {
        // Inside the cube the coordinates are non-negative: truncation is their floor.
        if (!(grid.x() >= 0 && grid.y() >= 0 && grid.z() >= 0)) continue;
        const int i = static_cast<int>(grid.x());
        const int j = static_cast<int>(grid.y());
        const int k = static_cast<int>(grid.z());
        if (i >= n_ || j >= n_ || k >= n_) continue;
        const std::int64_t index = Index(i, j, k);
        bits[index >> 6] |= std::uint64_t{1} << (index & 63);
        first = std::min(first, index >> 6);
        last = std::max(last, index >> 6);
      }
    }
  }
  *first_word = first, *last_word = last;
}

int TsdfVolume::UpdateWords(const IntegrationView& view, const std::int64_t* words, size_t count,
                            std::array<int, 3>* lo, std::array<int, 3>* hi) {
  const Frame& frame = view.frame;
  const CameraIntrinsics& intrinsics = view.intrinsics;
  const float band = view.band;
  int updated = 0;
  // Kept in locals until the end: the threads' outputs share cache lines.
  std::array<int, 3> low = *lo, high = *hi;
  // The distance along the ray from the voxel to the surface seen through its pixel.
  auto update = [&](std::int64_t index, int i, int j, int k) {
    const Eigen::Vector3f centre =
        view.cam_rotation * Eigen::Vector3f(centres_[i], centres_[j], centres_[k]) +
        view.cam_translation;
    if (centre.z() <= 0) return;
    const float x = static_cast<float>(intrinsics.fx) * centre.x() / centre.z() +
                    static_cast<float>(intrinsics.cx);
    const float y = static_cast<float>(intrinsics.fy) * centre.y() / centre.z() +
                    static_cast<float>(intrinsics.cy);
    // The nearest pixel (inside the image, truncation rounds).
    if (!intrinsics.Contains(x, y)) return;
    const int u = static_cast<int>(x + 0.5f), v = static_cast<int>(y + 0.5f);
    const int pixel = v * frame.width + u;
    if (!view.Observed(pixel)) return;
    const float along_ray = std::sqrt(centre.squaredNorm()) / centre.z();
    const float distance = (frame.depth_mm[pixel] - centre.z()) * along_ray;
    if (distance < -band) return;  // Behind the surface: not seen.
    const float tsdf = std::min(1.0f, distance / band);
    Voxel& voxel_ref = voxels_[index];
    const float weight = voxel_ref.weight;
    const float mean = (voxel_ref.tsdf / kTsdfScale * weight + tsdf) / (weight + 1);
    voxel_ref.tsdf = static_cast<std::int16_t>(RoundToInt(mean * kTsdfScale));
    if (view.color && std::abs(distance) < view.color_band) {
      const float seen = voxel_ref.color_weight;
      for (int c = 0; c < 3; ++c) {
        const float value = frame.rgb[3 * pixel + c];
        voxel_ref.rgb[c] =
            static_cast<std::uint8_t>(RoundToInt((voxel_ref.rgb[c] * seen + value) / (seen + 1)));
      }
      voxel_ref.color_weight = static_cast<std::uint8_t>(
          std::min<int>(std::min(255, options_.max_weight), voxel_ref.color_weight + 1));
    }
    voxel_ref.weight =
        static_cast<std::uint16_t>(std::min<int>(options_.max_weight, voxel_ref.weight + 1));
    const int ijk[3] = {i, j, k};
    for (int a = 0; a < 3; ++a) {
      low[a] = std::min(low[a], ijk[a]);
      high[a] = std::max(high[a], ijk[a]);
    }
    ++updated;
  };
  // A word is one z layer of a brick (8 x 8 voxels; the bricks' own layout in the header): its
  // brick's corner by division, its bits' (i, j) by their place in the word.
  static_assert(kBrickEdge * kBrickEdge == 64, "a bit word covers one layer of a brick");
  constexpr int layers = kBrickEdge, in_brick = kBrickEdge - 1;
  std::uint64_t* bits_of = touched_bits_.front().data();
  for (size_t n = 0; n < count; ++n) {
    const std::int64_t w = words[n];
    std::uint64_t bits = bits_of[w];
    bits_of[w] = 0;
    const std::int64_t brick = w / layers;
    const int i0 = static_cast<int>(brick % bricks_) << kBrickShift;
    const int j0 = static_cast<int>((brick / bricks_) % bricks_) << kBrickShift;
    const int k =
        (static_cast<int>(brick / bricks_ / bricks_) << kBrickShift) + static_cast<int>(w % layers);
    for (; bits != 0; bits &= bits - 1) {
      const int bit = std::countr_zero(bits);
      update(w * 64 + bit, i0 + (bit & in_brick), j0 + (bit >> kBrickShift), k);
    }
  }
  *lo = low, *hi = high;
  return updated;
}

// SignedDistance, inlined into the raycast's loop (most of the raycast's time).
[[gnu::always_inline]] inline bool TsdfVolume::Sample(const Eigen::Vector3f& point,
                                                      float* distance_mm) const {
  const Eigen::Vector3f grid = (point.array() + half_mm_) / voxel_mm_float_ - 0.5f;
  // Outside the cube (also catches NaN): the comparisons are false.
  if (!(grid.x() >= 0 && grid.y() >= 0 && grid.z() >= 0)) return false;
  const int i = static_cast<int>(grid.x()), j = static_cast<int>(grid.y()),
            k = static_cast<int>(grid.z());
  if (i + 1 >= n_ || j + 1 >= n_ || k + 1 >= n_) return false;
  const float fx = grid.x() - i, fy = grid.y() - j, fz = grid.z() - k;
  // The cell's corners: x fastest, then y, then z. Index is a sum of one term per axis, so a
  // corner is the first one plus a step per axis: to the next voxel of the brick, or across to
  // the next brick from a brick's last voxel.
  constexpr int last = kBrickEdge - 1;
  const std::int64_t brick_voxels = std::int64_t{1} << (3 * kBrickShift);
  const std::int64_t dx = (i & last) != last ? 1 : brick_voxels - last;
  const std::int64_t dy =
      (j & last) != last ? kBrickEdge : bricks_ * brick_voxels - last * kBrickEdge;
  const std::int64_t dz = (k & last) != last ? kBrickEdge * kBrickEdge
                                             : std::int64_t{bricks_} * bricks_ * brick_voxels -
                                                   last * kBrickEdge * kBrickEdge;
  const Voxel* base = &voxels_[Index(i, j, k)];
  const Voxel* c[8] = {base,      base + dx,      base + dy,      base + dy + dx,
                       base + dz, base + dz + dx, base + dz + dy, base + dz + dy + dx};
  float value[8];
  for (int q = 0; q < 8; ++q) {
    if (c[q]->weight == 0) return false;
    value[q] = c[q]->tsdf;
  }
  auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
  const float y0 = lerp(lerp(value[0], value[1], fx), lerp(value[2], value[3], fx), fy);
  const float y1 = lerp(lerp(value[4], value[5], fx), lerp(value[6], value[7], fx), fy);
  *distance_mm = lerp(y0, y1, fz) * mm_per_tsdf_unit_;
  return true;
}

bool TsdfVolume::SignedDistance(const Eigen::Vector3f& point, float* distance_mm) const {
  return Sample(point, distance_mm);
}

RaycastImage TsdfVolume::Raycast(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_volume,
                                 const std::array<int, 4>& roi,
                                 const std::vector<std::uint16_t>* near_depth_mm,
                                 float window_mm) const {
  RaycastImage image;
  Raycast(intrinsics, cam_from_volume, roi, near_depth_mm, window_mm, &image);
  return image;
}

struct TsdfVolume::RaycastView {
  RaycastView(const CameraIntrinsics& c, const Rigid3& v, const std::vector<std::uint16_t>* n)
      : intrinsics(c), volume_from_cam(v), near_depth_mm(n) {}
  const CameraIntrinsics& intrinsics;
  const Rigid3& volume_from_cam;
  const std::vector<std::uint16_t>* near_depth_mm;
  // volume_from_cam's rotation and origin, cam_from_volume's rotation, as floats.
  Eigen::Matrix3f rotation;
  Eigen::Vector3f origin;
  Eigen::Matrix3f to_cam;
  // The truncation band and the window around the observed depth, mm.
  float band = 0, window = 0;
  // The observed box, and the pixels cast (exclusive ends).
  Eigen::Vector3f box_lo, box_hi;
  int u0 = 0, v0 = 0, u1 = 0, v1 = 0;
};

void TsdfVolume::Raycast(const CameraIntrinsics& intrinsics, const Rigid3& cam_from_volume,
                         const std::array<int, 4>& roi,
                         const std::vector<std::uint16_t>* near_depth_mm, float window_mm,
                         RaycastImage* out) const {
  RaycastImage& image = *out;
  const size_t pixels = static_cast<size_t>(intrinsics.width) * intrinsics.height;
  if (image.width != intrinsics.width || image.height != intrinsics.height ||
      image.depth_mm.size() != pixels || image.normals.size() != pixels ||
      image.colors.size() != pixels || image.color_weights.size() != pixels) {
    image.width = intrinsics.width;
    image.height = intrinsics.height;
    image.depth_mm.assign(pixels, 0.0f);
    image.normals.assign(pixels, Eigen::Vector3f::Zero());
    image.colors.assign(pixels, {0, 0, 0});
    image.color_weights.assign(pixels, 0);
  } else {
    const auto [x0, y0, x1, y1] = image.written;
    for (int v = std::max(0, y0); v < std::min(image.height, y1); ++v) {
      const size_t row = static_cast<size_t>(v) * image.width;
      for (size_t p = row + std::max(0, x0); p < row + std::min(image.width, x1); ++p) {
        image.depth_mm[p] = 0;
        image.normals[p] = Eigen::Vector3f::Zero();
        image.colors[p] = {0, 0, 0};
        image.color_weights[p] = 0;
      }
    }
  }
  image.written = {0, 0, 0, 0};
  // Rays are followed only through the box of observed voxels.
  const Eigen::AlignedBox3f observed = ObservedBox();
  if (observed.isEmpty()) return;  // Nothing to see yet.
  IHS_CHECK_ARG(near_depth_mm == nullptr || near_depth_mm->size() == pixels,
                "near_depth_mm has " << near_depth_mm->size() << " entries, the image " << pixels);
  const Rigid3 volume_from_cam = cam_from_volume.Inverse();
  RaycastView view(intrinsics, volume_from_cam, near_depth_mm);
  view.rotation = volume_from_cam.rotation().cast<float>();
  view.origin = volume_from_cam.translation().cast<float>();
  view.to_cam = cam_from_volume.rotation().cast<float>();
  view.band = static_cast<float>(truncation_mm_);
  view.window = window_mm;
  view.box_lo = observed.min(), view.box_hi = observed.max();
  const bool whole = roi[2] <= roi[0] || roi[3] <= roi[1];
  view.u0 = whole ? 0 : std::max(0, roi[0]), view.v0 = whole ? 0 : std::max(0, roi[1]);
  view.u1 = whole ? image.width : std::min(image.width, roi[2]);
  view.v1 = whole ? image.height : std::min(image.height, roi[3]);
  image.written = {view.u0, view.v0, view.u1, view.v1};
  // Each thread every threads-th row (the object's rows shared alike): first every ray, then
  // (once all hits are in) the normals.
  const int rows = std::max(0, view.v1 - view.v0);
  const int threads = Threads(rows);
  for (auto pass : {&TsdfVolume::CastRows, &TsdfVolume::NormalRows}) {
    ParallelRuns(threads, threads, [&](size_t begin, size_t end) {
      for (size_t t = begin; t < end; ++t) {
        (this->*pass)(view, view.v0 + static_cast<int>(t), threads, &image);
      }
    });
  }
}

void TsdfVolume::CastRows(const RaycastView& view, int v_first, int v_step,
                          RaycastImage* out) const {
  RaycastImage& image = *out;
  const CameraIntrinsics& intrinsics = view.intrinsics;
  const Eigen::Matrix3f& rotation = view.rotation;
  const Eigen::Vector3f& origin = view.origin;
  const float voxel = voxel_mm_float_, band = view.band, half = half_mm_;
  for (int v = v_first; v < view.v1; v += v_step) {
    for (int u = view.u0; u < view.u1; ++u) {
      const std::uint16_t near =
          view.near_depth_mm ? (*view.near_depth_mm)[v * image.width + u] : 0;
      if (view.near_depth_mm && near == 0) continue;
      const Eigen::Vector3f ray_cam = intrinsics.BackProject(u, v, 1.0).cast<float>();
      const Eigen::Vector3f ray = rotation * ray_cam.normalized();
      // Where the ray is inside the observed box (slabs), and the window.
      float t_near = 0, t_far = std::numeric_limits<float>::infinity();
      if (view.near_depth_mm) {
        const float length = ray_cam.norm();  // Along the ray per mm of depth.
        t_near = std::max(0.0f, (near - view.window) * length);
        t_far = (near + view.window) * length;
      }
      for (int a = 0; a < 3; ++a) {
        if (std::abs(ray[a]) < 1e-9f) {
          if (origin[a] < view.box_lo[a] || origin[a] > view.box_hi[a]) t_far = -1;
          continue;
        }
        float t0 = (view.box_lo[a] - origin[a]) / ray[a],
              t1 = (view.box_hi[a] - origin[a]) / ray[a];
        if (t0 > t1) std::swap(t0, t1);
        t_near = std::max(t_near, t0), t_far = std::min(t_far, t1);
      }
      if (t_near >= t_far) continue;
      float t = t_near + 0.5f * voxel, previous_t = 0, previous = 0;
      bool has_previous = false;
      while (t < t_far) {
        float distance = 0;
        if (!Sample(origin + t * ray, &distance)) {
          has_previous = false;
          // An unobserved stretch: half-band steps land at least once in the band's front half.
          t += 0.5f * band;
          continue;
        }
        if (distance < 0) {
          if (!has_previous || previous <= 0) break;  // Entered from behind: no front surface.
          const float hit = previous_t + (t - previous_t) * previous / (previous - distance);
          const Eigen::Vector3f point = origin + hit * ray;
          const size_t pixel = static_cast<size_t>(v) * image.width + u;
          image.depth_mm[pixel] = (hit * ray_cam.normalized()).z();
          image.colors[pixel] = ColorAt(point, half, voxel, &image.color_weights[pixel]);
          break;
        }
        previous_t = t, previous = distance, has_previous = true;
        t += std::max(voxel, 0.8f * distance);
      }
    }
  }
}

void TsdfVolume::NormalRows(const RaycastView& view, int v_first, int v_step,
                            RaycastImage* out) const {
  // Normals from the hits' neighbours (as KinectFusion does): central differences of the
  // surface points across the pixel, one-sided at the hits' edge; neighbours across a depth step
  // of more than the truncation band lie on another surface. Where a pixel has no neighbour
  // along a direction, the signed distance's central-difference gradient gives its normal.
  RaycastImage& image = *out;
  const CameraIntrinsics& intrinsics = view.intrinsics;
  const int u0 = view.u0, v0 = view.v0, u1 = view.u1, v1 = view.v1;
  const float voxel = voxel_mm_float_, band = view.band;
  auto surface_point = [&](int u, int v) -> Eigen::Vector3f {
    return intrinsics.BackProject(u, v, image.depth_mm[static_cast<size_t>(v) * image.width + u])
        .cast<float>();
  };
  for (int v = v_first; v < view.v1; v += v_step) {
    for (int u = u0; u < u1; ++u) {
      const size_t pixel = static_cast<size_t>(v) * image.width + u;
      const float depth = image.depth_mm[pixel];
      if (depth == 0) continue;
      auto usable = [&](int nu, int nv) {
        if (nu < u0 || nu >= u1 || nv < v0 || nv >= v1) return false;
        const float other = image.depth_mm[static_cast<size_t>(nv) * image.width + nu];
        return other != 0 && std::abs(other - depth) <= band;
      };
      // The surface's tangent along one image axis: (du, dv) one pixel step.
      auto tangent = [&](int du, int dv, Eigen::Vector3f* along) {
        const bool ahead = usable(u + du, v + dv), behind = usable(u - du, v - dv);
        if (!ahead && !behind) return false;
        *along = (ahead ? surface_point(u + du, v + dv) : surface_point(u, v)) -
                 (behind ? surface_point(u - du, v - dv) : surface_point(u, v));
        return true;
      };
      Eigen::Vector3f across, down;
      if (tangent(1, 0, &across) && tangent(0, 1, &down)) {
        // Image x right, y down: down × across points toward the camera.
        const Eigen::Vector3f normal = down.cross(across);
        if (normal.squaredNorm() > 1e-12f) {
          image.normals[pixel] = normal.normalized();
          continue;
        }
      }
      const Eigen::Vector3f point = view.volume_from_cam * surface_point(u, v);
      Eigen::Vector3f gradient;
      bool ok = true;
      for (int a = 0; a < 3 && ok; ++a) {
        Eigen::Vector3f step = Eigen::Vector3f::Zero();
        step[a] = voxel;
        float plus = 0, minus = 0;
        ok = SignedDistance(point + step, &plus) && SignedDistance(point - step, &minus);
        gradient[a] = plus - minus;
      }
      if (ok && gradient.norm() > 1e-6f) image.normals[pixel] = view.to_cam * gradient.normalized();
    }
  }
}

TriangleMesh::Color TsdfVolume::ColorAt(const Eigen::Vector3f& point, float half, float voxel,
                                        std::uint8_t* weight) const {
  // Trilinear over the cell's corners that have a colour.
  const Eigen::Vector3f grid = (point.array() + half) / voxel - 0.5f;
  const int i = std::clamp(static_cast<int>(std::floor(grid.x())), 0, n_ - 2);
  const int j = std::clamp(static_cast<int>(std::floor(grid.y())), 0, n_ - 2);
  const int k = std::clamp(static_cast<int>(std::floor(grid.z())), 0, n_ - 2);
  const Eigen::Vector3f f = (grid - Eigen::Vector3f(i, j, k)).cwiseMax(0.0f).cwiseMin(1.0f);
  float sum[3] = {0, 0, 0}, total = 0, seen = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
    const Voxel& v = voxels_[Index(i + dx, j + dy, k + dz)];
    if (v.color_weight == 0) continue;
    const float w = (dx ? f.x() : 1 - f.x()) * (dy ? f.y() : 1 - f.y()) * (dz ? f.z() : 1 - f.z());
    for (int c = 0; c < 3; ++c) sum[c] += w * v.rgb[c];
    total += w;
    seen += w * v.color_weight;
  }
  *weight = 0;
  if (!(total > 0)) return {0, 0, 0};
  *weight = static_cast<std::uint8_t>(std::lround(seen / total));
  TriangleMesh::Color rgb;
  for (int c = 0; c < 3; ++c) rgb[c] = static_cast<std::uint8_t>(std::lround(sum[c] / total));
  return rgb;
}

TriangleMesh TsdfVolume::ExtractMesh() const {
  TriangleMesh mesh;
  const bool color = options_.color;
  auto value = [&](int i, int j, int k, float* sample) {
    const Voxel& voxel = voxels_[Index(i, j, k)];
    *sample = voxel.tsdf;
    return voxel.weight > 0;
  };
  auto add_vertex = [&](const LatticePoint& a, const LatticePoint& b, float s) {
    const Eigen::Vector3f pa = Centre(a[0], a[1], a[2]);
    const Eigen::Vector3f pb = Centre(b[0], b[1], b[2]);
    mesh.vertices.push_back(pa + s * (pb - pa));
    if (color) {
      const Voxel& va = voxels_[Index(a[0], a[1], a[2])];
      const Voxel& vb = voxels_[Index(b[0], b[1], b[2])];
      // Between the two where both have a colour, else the one that has.
      const float t = va.color_weight == 0 ? 1.0f : vb.color_weight == 0 ? 0.0f : s;
      TriangleMesh::Color rgb;
      for (int c = 0; c < 3; ++c) {
        rgb[c] = static_cast<std::uint8_t>(std::lround(va.rgb[c] + t * (vb.rgb[c] - va.rgb[c])));
      }
      mesh.colors.push_back(rgb);
    }
    return static_cast<std::int32_t>(mesh.vertices.size() - 1);
  };
  MarchingCubes({n_, n_, n_}, value, add_vertex, &mesh.faces);
  mesh.ComputeVertexNormals();
  return mesh;
}

}  // namespace ihs::fusion
