#include "fusion/silhouette.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace ihs::fusion {

void SilhouetteOptions::Check() const {
  IHS_CHECK_ARG(weight >= 0, "silhouette.weight must be >= 0");
  IHS_CHECK_ARG(search_px >= 1 && search_px <= 32, "silhouette.search_px must be in [1, 32]");
  IHS_CHECK_ARG(background_gap_mm > 0, "silhouette.background_gap_mm must be positive");
  IHS_CHECK_ARG(max_points >= 1, "silhouette.max_points must be >= 1");
  IHS_CHECK_ARG(min_edge_facing >= 0 && min_edge_facing <= 1,
                "silhouette.min_edge_facing must be in [0, 1]");
}

namespace {

// What a pixel next to an object pixel of depth `depth` is.
enum class Side { kObject, kBackground, kBlocked };

class ContourFinder {
 public:
  ContourFinder(const Frame& frame, const std::vector<std::uint8_t>& mask,
                const SilhouetteOptions& options)
      : frame_(frame), mask_(mask), options_(options) {}

  bool IsObject(int u, int v) const {
    const int pixel = v * frame_.width + u;
    return mask_[pixel] && frame_.depth_mm[pixel] > 0;
  }

  Side Classify(int u, int v, double depth) const {
    if (u < 0 || v < 0 || u >= frame_.width || v >= frame_.height) return Side::kBlocked;
    const int pixel = v * frame_.width + u;
    if (mask_[pixel]) return Side::kObject;
    const double there = frame_.depth_mm[pixel];
    if (there == 0 || there > depth + options_.background_gap_mm) return Side::kBackground;
    return Side::kBlocked;
  }

  // Whether (u, v), an object pixel, is on the occluding contour: a background 4-neighbour,
  // and nothing nearer (the hand, left-out pixels) within 3 pixels: a shadow of the hand on
  // the object has no depth either, and the object goes on behind it.
  bool OnContour(int u, int v) const {
    const double depth = frame_.depth_mm[v * frame_.width + u];
    const int du[4] = {1, -1, 0, 0};
    const int dv[4] = {0, 0, 1, -1};
    bool background = false;
    for (int k = 0; k < 4; ++k)
      background |= Classify(u + du[k], v + dv[k], depth) == Side::kBackground;
    if (!background) return false;
    for (int y = v - 3; y <= v + 3; ++y) {
      for (int x = u - 3; x <= u + 3; ++x) {
        if (Classify(x, y, depth) == Side::kBlocked) return false;
      }
    }
    return true;
  }

  // The outline's outward normal at (u, v): away from the object pixels around it.
  bool Normal(int u, int v, Eigen::Vector2d* normal) const {
    Eigen::Vector2d towards = Eigen::Vector2d::Zero();
    for (int y = v - 2; y <= v + 2; ++y) {
      for (int x = u - 2; x <= u + 2; ++x) {
        if (x < 0 || y < 0 || x >= frame_.width || y >= frame_.height) continue;
        if (mask_[y * frame_.width + x]) towards += Eigen::Vector2d(x - u, y - v);
      }
    }
    // A thin sliver (object on both sides) has no outline direction to speak of.
    if (towards.norm() < 2.0) return false;
    *normal = -towards.normalized();
    return true;
  }

 private:
  const Frame& frame_;
  const std::vector<std::uint8_t>& mask_;
  const SilhouetteOptions& options_;
};

}  // namespace

std::vector<ContourPoint> FindContour(const Frame& frame, const std::vector<std::uint8_t>& mask,
                                      const std::array<int, 4>& box,
                                      const CameraIntrinsics& intrinsics,
                                      const SilhouetteOptions& options) {
  std::vector<ContourPoint> contour;
  if (mask.size() != frame.depth_mm.size()) return contour;
  const ContourFinder finder(frame, mask, options);
  for (int v = std::max(0, box[1]); v < std::min(frame.height, box[3]); ++v) {
    for (int u = std::max(0, box[0]); u < std::min(frame.width, box[2]); ++u) {
      if (!finder.IsObject(u, v) || !finder.OnContour(u, v)) continue;
      ContourPoint point;
      if (!finder.Normal(u, v, &point.normal)) continue;
      point.point = intrinsics.BackProject(u, v, frame.depth_mm[v * frame.width + u]);
      contour.push_back(point);
    }
  }
  if (static_cast<int>(contour.size()) > options.max_points) {
    // Evenly spaced: every k-th in the order found.
    std::vector<ContourPoint> kept;
    const double stride = static_cast<double>(contour.size()) / options.max_points;
    for (int i = 0; i < options.max_points; ++i)
      kept.push_back(contour[static_cast<size_t>(i * stride)]);
    contour.swap(kept);
  }
  return contour;
}

void MarkContourBand(const std::vector<ContourPoint>& contour, const CameraIntrinsics& intrinsics,
                     int search_px, std::vector<std::uint16_t>* near_depth_mm) {
  for (const ContourPoint& point : contour) {
    const Eigen::Vector2d pixel = intrinsics.Project(point.point);
    const auto depth = static_cast<std::uint16_t>(std::lround(point.point.z()));
    for (int t = 1; t <= search_px + 1; ++t) {
      const Eigen::Vector2d at = pixel + t * point.normal;
      const int u = static_cast<int>(std::lround(at.x()));
      const int v = static_cast<int>(std::lround(at.y()));
      if (u < 0 || v < 0 || u >= intrinsics.width || v >= intrinsics.height) break;
      std::uint16_t& near = (*near_depth_mm)[static_cast<size_t>(v) * intrinsics.width + u];
      if (near == 0) near = depth;
    }
  }
}

bool PairContourPoint(const Eigen::Vector3d& point, const Eigen::Vector2d& normal,
                      const RaycastImage& model, const CameraIntrinsics& intrinsics,
                      double depth_gate_mm, int search_px, double min_edge_facing,
                      Eigen::Vector3d* direction, double* residual_mm) {
  if (point.z() <= 0) return false;
  const Eigen::Vector2d at = intrinsics.Project(point);
  // -1: off the image or the model has surface in front (no edge to speak of); 0: nothing
  // there (or only surface far behind); 1: the point's own surface.
  auto pixel_at = [&](int t) {
    const Eigen::Vector2d q = at + t * normal;
    return Eigen::Vector2i(static_cast<int>(std::lround(q.x())),
                           static_cast<int>(std::lround(q.y())));
  };
  auto sample = [&](int t) {
    const Eigen::Vector2i q = pixel_at(t);
    const int u = q.x(), v = q.y();
    if (u < 0 || v < 0 || u >= model.width || v >= model.height) return -1;
    const float depth = model.depth_mm[static_cast<size_t>(v) * model.width + u];
    if (depth <= 0 || depth > point.z() + depth_gate_mm) return 0;
    return depth < point.z() - depth_gate_mm ? -1 : 1;
  };
  const int here = sample(0);
  if (here < 0) return false;
  // The model's edge: between its last pixel on the surface and the first with nothing.
  double edge = 0;
  int inside = 0;  // the model's last pixel on the surface, along the walk
  bool found = false;
  for (int t = 1; t <= search_px && !found; ++t) {
    const int s = here == 1 ? sample(t) : sample(-t);
    if (s < 0) return false;
    if (here == 1 && s == 0) edge = t - 0.5, inside = t - 1, found = true;
    if (here == 0 && s == 1) edge = -t + 0.5, inside = -t, found = true;
  }
  if (!found) return false;
  // A crease, not where the surface turns away from the camera.
  const Eigen::Vector2i last = pixel_at(inside);
  const size_t index = static_cast<size_t>(last.y()) * model.width + last.x();
  const Eigen::Vector3d ray = intrinsics.BackProject(last.x(), last.y(), 1.0).normalized();
  if (!(std::abs(model.normals[index].cast<double>().dot(ray)) >= min_edge_facing)) return false;
  // The frame's edge is half a pixel out from its contour pixel.
  const double f = 0.5 * (intrinsics.fx + intrinsics.fy);
  *residual_mm = (0.5 - edge) * point.z() / f;
  // d(residual)/d(point): the image motion along the normal, in mm at the point's depth.
  const double nx = normal.x() * intrinsics.fx / f;
  const double ny = normal.y() * intrinsics.fy / f;
  *direction = Eigen::Vector3d(nx, ny, -(nx * point.x() + ny * point.y()) / point.z());
  return true;
}

}  // namespace ihs::fusion
