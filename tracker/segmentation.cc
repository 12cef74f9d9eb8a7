#include "tracker/segmentation.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "core/check.h"
#include "tracker/skin_model.h"

namespace ihs::tracker {
namespace {

enum Class : std::uint8_t { kNone = 0, kSkin = 1, kOther = 2 };

// Labels 4-connected regions of equal class in a width × height image whose neighbouring depths
// differ by at most `max_step_mm`; a pixel's neighbour along each axis is the next one with
// depth, up to `gap_px` pixels without depth away (the step allowed growing with the distance).
// Returns the region of each pixel (−1 for kNone) and fills `sizes`.
std::vector<int> Regions(const std::vector<std::uint8_t>& classes,
                         const std::vector<std::uint16_t>& depth, int width, int height,
                         double max_step_mm, int gap_px, std::vector<int>* sizes) {
  std::vector<int> region(classes.size(), -1);
  std::vector<int> stack;
  sizes->clear();
  for (size_t start = 0; start < classes.size(); ++start) {
    if (classes[start] == kNone || region[start] >= 0) continue;
    const int id = static_cast<int>(sizes->size());
    int size = 0;
    region[start] = id;
    stack.push_back(static_cast<int>(start));
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      ++size;
      const int u = p % width, v = p / width;
      const int steps[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
      for (const auto& step : steps) {
        for (int k = 1; k <= gap_px + 1; ++k) {
          const int uu = u + k * step[0], vv = v + k * step[1];
          if (uu < 0 || vv < 0 || uu >= width || vv >= height) break;
          const int q = vv * width + uu;
          if (depth[q] == 0) continue;
          if (region[q] < 0 && classes[q] == classes[p] &&
              std::abs(static_cast<int>(depth[q]) - static_cast<int>(depth[p])) <=
                  k * max_step_mm) {
            region[q] = id;
            stack.push_back(q);
          }
          break;
        }
      }
    }
    sizes->push_back(size);
  }
  return region;
}

// Re-classes skin regions smaller than `min_pixels` whose outline lies on a non-skin surface
// as kOther: of the pixels just outside the region, at least `enclosed_share` are non-skin within
// `step_mm` in depth. Returns whether any changed.
bool GiveSpecksToObject(std::vector<std::uint8_t>* classes, const std::vector<int>& region,
                        const std::vector<int>& sizes, const std::vector<std::uint16_t>& depth,
                        int width, int height, int min_pixels, double enclosed_share,
                        double step_mm) {
  std::vector<int> outline(sizes.size(), 0), on_surface(sizes.size(), 0);
  auto small_skin = [&](size_t i) {
    return (*classes)[i] == kSkin && sizes[region[i]] < min_pixels;
  };
  const int steps[4][2] = {{-1, 0}, {1, 0}, {0, -1}, {0, 1}};
  for (size_t i = 0; i < classes->size(); ++i) {
    if (!small_skin(i)) continue;
    const int u = static_cast<int>(i % width), v = static_cast<int>(i / width);
    for (const auto& step : steps) {
      const int uu = u + step[0], vv = v + step[1];
      const bool in_box = uu >= 0 && vv >= 0 && uu < width && vv < height;
      const size_t q = in_box ? static_cast<size_t>(vv) * width + uu : 0;
      if (in_box && region[q] == region[i]) continue;
      ++outline[region[i]];
      on_surface[region[i]] +=
          in_box && (*classes)[q] == kOther &&
          std::abs(static_cast<int>(depth[q]) - static_cast<int>(depth[i])) <= step_mm;
    }
  }
  bool changed = false;
  for (size_t i = 0; i < classes->size(); ++i) {
    const int id = small_skin(i) ? region[i] : -1;
    if (id < 0 || outline[id] == 0 || on_surface[id] < enclosed_share * outline[id]) continue;
    (*classes)[i] = kOther;
    changed = true;
  }
  return changed;
}

// Regions (above) of a width × height box of classes, once skin specks printed on the object
// have been given to it (GiveSpecksToObject).
std::vector<int> ClassRegions(std::vector<std::uint8_t>* classes,
                              const std::vector<std::uint16_t>& depth, int width, int height,
                              const SegmentationOptions& options, std::vector<int>* sizes) {
  const std::vector<int> region = Regions(*classes, depth, width, height, options.connect_depth_mm,
                                          options.connect_gap_px, sizes);
  if (options.speck_enclosed_share == 0 ||
      !GiveSpecksToObject(classes, region, *sizes, depth, width, height, options.min_region_pixels,
                          options.speck_enclosed_share, options.speck_step_mm)) {
    return region;
  }
  return Regions(*classes, depth, width, height, options.connect_depth_mm, options.connect_gap_px,
                 sizes);
}

}  // namespace

void SegmentationOptions::Check() const {
  IHS_CHECK_ARG((crop_min_mm.array() < crop_max_mm.array()).all(),
                "segmentation.crop_min_mm must be below crop_max_mm on every axis");
  IHS_CHECK_ARG(crop_min_mm.z() > 0, "segmentation.crop_min_mm.z must be positive");
  IHS_CHECK_ARG(connect_depth_mm > 0, "segmentation.connect_depth_mm must be positive");
  IHS_CHECK_ARG(min_region_pixels >= 0, "segmentation.min_region_pixels must be >= 0");
  IHS_CHECK_ARG(speck_enclosed_share >= 0 && speck_enclosed_share <= 1,
                "segmentation.speck_enclosed_share must be in [0, 1]");
  IHS_CHECK_ARG(speck_step_mm >= 0, "segmentation.speck_step_mm must be >= 0");
  IHS_CHECK_ARG(connect_gap_px >= 0 && connect_gap_px <= 8,
                "segmentation.connect_gap_px must be in [0, 8]");
  IHS_CHECK_ARG(boundary_px >= 0 && boundary_px <= 20,
                "segmentation.boundary_px must be in [0, 20]");
  IHS_CHECK_ARG(max_object_distance_mm > 0, "segmentation.max_object_distance_mm must be positive");
  IHS_CHECK_ARG(object_margin_mm >= 0, "segmentation.object_margin_mm must be >= 0");
}

Segmenter::Segmenter(const CameraIntrinsics& intrinsics, SegmentationOptions options)
    : intrinsics_(intrinsics),
      options_(std::move(options)),
      skin_(std::make_unique<SkinColorModel>()) {
  intrinsics_.Check();
  options_.Check();
}

Segmenter::~Segmenter() = default;

Segmentation Segmenter::Segment(const Frame& frame) const {
  frame.Check();
  IHS_CHECK_ARG(frame.width == intrinsics_.width && frame.height == intrinsics_.height,
                "frame is " << frame.width << "x" << frame.height << ", the camera "
                            << intrinsics_.width << "x" << intrinsics_.height);
  const int w = frame.width, h = frame.height;
  const size_t n = static_cast<size_t>(w) * h;
  Segmentation out;
  out.width = w;
  out.height = h;
  out.hand_mask.assign(n, 0);
  out.object_mask.assign(n, 0);

  // Where a pixel lies: 0 outside the crop volume grown by the object's margin, 1 in the margin
  // only, 2 inside the volume. Everything after works in the box around the grown volume's pixels.
  const double margin = options_.object_margin_mm;
  auto crop_level = [&](int u, int v, std::uint16_t z) {
    if (z == 0 || z < options_.crop_min_mm.z() - margin || z > options_.crop_max_mm.z() + margin)
      return 0;
    const Eigen::Array3d x = intrinsics_.BackProject(u, v, z).array();
    const Eigen::Array3d low = options_.crop_min_mm.array(), high = options_.crop_max_mm.array();
    if ((x < low - margin).any() || (x > high + margin).any()) return 0;
    return (x >= low).all() && (x <= high).all() ? 2 : 1;
  };
  int u0 = w, v0 = h, u1 = 0, v1 = 0;
  for (int v = 0; v < h; ++v) {
    const std::uint16_t* row = &frame.depth_mm[static_cast<size_t>(v) * w];
    for (int u = 0; u < w; ++u) {
      if (crop_level(u, v, row[u]) == 0) continue;
      u0 = std::min(u0, u), v0 = std::min(v0, v), u1 = std::max(u1, u + 1), v1 = v + 1;
    }
  }
  if (u1 <= u0) return out;
  const int bw = u1 - u0, bh = v1 - v0;
  const size_t bn = static_cast<size_t>(bw) * bh;
  // Box index → image index, and the 3D point of a box pixel.
  auto image_index = [&](size_t i) {
    return static_cast<size_t>(static_cast<int>(i / bw) + v0) * w + static_cast<int>(i % bw) + u0;
  };
  std::vector<std::uint16_t> depth(bn);
  for (size_t i = 0; i < bn; ++i) depth[i] = frame.depth_mm[image_index(i)];
  auto point = [&](size_t i) {
    return intrinsics_.BackProject(static_cast<int>(i % bw) + u0, static_cast<int>(i / bw) + v0,
                                   depth[i]);
  };

  // Classify pixels by colour: skin only inside the crop volume, anything else within the margin.
  std::vector<std::uint8_t> classes(bn, kNone);
  std::vector<std::uint8_t> inside(bn, 0);
  for (size_t i = 0; i < bn; ++i) {
    const int level =
        crop_level(static_cast<int>(i % bw) + u0, static_cast<int>(i / bw) + v0, depth[i]);
    if (level == 0) continue;
    inside[i] = level == 2;
    out.cropped_pixels += inside[i];
    bool skin = false;
    if (frame.HasColor()) {
      const std::uint8_t* c = &frame.rgb[3 * image_index(i)];
      skin = skin_->LogLikelihoodRatio(c[0], c[1], c[2]) > options_.skin_log_ratio;
    }
    classes[i] = skin ? (inside[i] ? kSkin : kNone) : kOther;
  }

  // Depth-connected regions; skin specks printed on the object join it, other small ones go.
  std::vector<int> sizes;
  const std::vector<int> region = ClassRegions(&classes, depth, bw, bh, options_, &sizes);
  std::vector<std::uint8_t> hand(bn, 0);
  Eigen::Vector3d hand_sum = Eigen::Vector3d::Zero();
  int hand_count = 0;
  for (size_t i = 0; i < bn; ++i) {
    if (classes[i] != kSkin || sizes[region[i]] < options_.min_region_pixels) continue;
    hand[i] = 1;
    hand_sum += point(i);
    ++hand_count;
  }

  // Object regions: not skin, not touching the hand's boundary band, near the hand.
  std::vector<std::uint8_t> near_hand(bn, 0);
  const int r = options_.boundary_px;
  for (int v = 0; v < bh; ++v) {
    for (int u = 0; u < bw; ++u) {
      if (!hand[static_cast<size_t>(v) * bw + u]) continue;
      for (int vv = std::max(0, v - r); vv <= std::min(bh - 1, v + r); ++vv) {
        for (int uu = std::max(0, u - r); uu <= std::min(bw - 1, u + r); ++uu)
          near_hand[static_cast<size_t>(vv) * bw + uu] = 1;
      }
    }
  }
  // Each object region's part inside the crop volume: its centre and size.
  std::vector<Eigen::Vector3d> region_sum(sizes.size(), Eigen::Vector3d::Zero());
  std::vector<int> inside_sizes(sizes.size(), 0);
  for (size_t i = 0; i < bn; ++i) {
    if (classes[i] != kOther || !inside[i]) continue;
    region_sum[region[i]] += point(i);
    ++inside_sizes[region[i]];
  }
  const Eigen::Vector3d hand_centre =
      hand_count > 0 ? Eigen::Vector3d(hand_sum / hand_count) : Eigen::Vector3d::Zero();
  for (size_t i = 0; i < bn; ++i) {
    if (hand[i]) {
      out.hand_mask[image_index(i)] = 1;
      out.hand_points.push_back(point(i).cast<float>());
      continue;
    }
    if (classes[i] != kOther || near_hand[i]) continue;
    const int id = region[i];
    if (sizes[id] < options_.min_region_pixels || inside_sizes[id] == 0) continue;
    if (hand_count > 0 && (region_sum[id] / inside_sizes[id] - hand_centre).norm() >
                              options_.max_object_distance_mm) {
      continue;
    }
    out.object_mask[image_index(i)] = 1;
    out.object_points.push_back(point(i).cast<float>());
  }
  return out;
}

}  // namespace ihs::tracker
