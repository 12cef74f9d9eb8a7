#include "fusion/see_through.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace ihs::fusion {

void SeeThroughOptions::Check() const {
  IHS_CHECK_ARG(max_share >= 0 && max_share <= 1, "fusion.see_through.max_share must be in [0, 1]");
  IHS_CHECK_ARG(margin_mm > 0, "fusion.see_through.margin_mm must be positive");
  IHS_CHECK_ARG(max_held_frames >= 0, "fusion.see_through.max_held_frames must be >= 0");
  IHS_CHECK_ARG(step_px >= 1, "fusion.see_through.step_px must be at least 1");
}

void SeeThroughPixels(const Frame& frame, int step_px, std::vector<std::uint16_t>* near_depth) {
  near_depth->assign(frame.depth_mm.size(), 0);
  for (int v = step_px / 2; v < frame.height; v += step_px) {
    for (int u = step_px / 2; u < frame.width; u += step_px) {
      const int pixel = v * frame.width + u;
      (*near_depth)[pixel] = frame.depth_mm[pixel];
    }
  }
}

std::array<int, 4> ImageBoxOf(const Eigen::AlignedBox3f& observed, const Rigid3& cam_from_volume,
                              const CameraIntrinsics& intrinsics) {
  if (observed.isEmpty()) return {0, 0, 0, 0};
  double u0 = intrinsics.width, v0 = intrinsics.height, u1 = 0, v1 = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d in_volume =
        observed.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).cast<double>();
    const Eigen::Vector3d point = cam_from_volume * in_volume;
    if (point.z() < 1.0) return {0, 0, 0, 0};
    const Eigen::Vector2d pixel = intrinsics.Project(point);
    u0 = std::min(u0, pixel.x()), v0 = std::min(v0, pixel.y());
    u1 = std::max(u1, pixel.x()), v1 = std::max(v1, pixel.y());
  }
  // At least one pixel wide, that an empty box is not the whole image.
  const int left = std::clamp(static_cast<int>(std::floor(u0)), 0, intrinsics.width - 1);
  const int top = std::clamp(static_cast<int>(std::floor(v0)), 0, intrinsics.height - 1);
  return {left, top, std::clamp(static_cast<int>(std::ceil(u1)) + 1, left + 1, intrinsics.width),
          std::clamp(static_cast<int>(std::ceil(v1)) + 1, top + 1, intrinsics.height)};
}

SeeThrough MeasureSeeThrough(const RaycastImage& model, const Frame& frame,
                             const CameraIntrinsics& intrinsics, const SeeThroughOptions& options) {
  IHS_CHECK_ARG(model.width == frame.width && model.height == frame.height,
                "the model's raycast does not fit the frame");
  const int step = options.step_px;
  const float margin = static_cast<float>(options.margin_mm);
  auto model_at = [&](int u, int v) {
    return u < 0 || v < 0 || u >= model.width || v >= model.height
               ? 0.0f
               : model.depth_mm[v * model.width + u];
  };
  SeeThrough seen;
  const auto [u0, v0, u1, v1] = model.written;
  // The sampled pixels only (SeeThroughPixels).
  const int v_first = v0 + ((step / 2 - v0) % step + step) % step;
  const int u_first = u0 + ((step / 2 - u0) % step + step) % step;
  for (int v = v_first; v < v1; v += step) {
    for (int u = u_first; u < u1; u += step) {
      const int pixel = v * model.width + u;
      const float model_mm = model.depth_mm[pixel];
      const std::uint16_t depth = frame.depth_mm[pixel];
      if (!(model_mm > 0) || depth == 0) continue;
      if (depth + margin >= model_mm) {  // Not behind something in front (the hand).
        seen.visible_centroid += intrinsics.BackProject(u, v, model_mm);
        ++seen.visible;
      }
      // The model's outermost samples are left out: its edges lie a voxel or two off.
      if (!(model_at(u - step, v) > 0 && model_at(u + step, v) > 0 && model_at(u, v - step) > 0 &&
            model_at(u, v + step) > 0)) {
        continue;
      }
      ++seen.in_view;
      if (depth > model_mm + margin) ++seen.through;
    }
  }
  if (seen.visible > 0) seen.visible_centroid /= seen.visible;
  return seen;
}

}  // namespace ihs::fusion
