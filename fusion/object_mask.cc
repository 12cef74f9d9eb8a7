#include "fusion/object_mask.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace ihs::fusion {

int RemoveMeshPixels(const TriangleMesh& mesh, const Frame& frame,
                     const CameraIntrinsics& intrinsics, int dilation_px, double depth_margin_mm,
                     std::vector<std::uint8_t>* object_mask) {
  IHS_CHECK_ARG(object_mask->size() == frame.depth_mm.size(),
                "the object mask does not fit the frame");
  IHS_CHECK_ARG(dilation_px >= 0, "dilation_px must not be negative");
  const int width = frame.width, height = frame.height;
  // Nearest mesh depth per pixel: a small z-buffer of the projected triangles.
  std::vector<float> z_buffer(frame.depth_mm.size(), std::numeric_limits<float>::infinity());
  std::vector<Eigen::Vector3f> projected(mesh.vertices.size());  // u, v, z
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& p = mesh.vertices[i];
    if (p.z() <= 1.0f) {
      projected[i] = {0, 0, -1};
      continue;
    }
    projected[i] = {static_cast<float>(intrinsics.fx * p.x() / p.z() + intrinsics.cx),
                    static_cast<float>(intrinsics.fy * p.y() / p.z() + intrinsics.cy), p.z()};
  }
  bool any = false;
  for (const auto& face : mesh.faces) {
    const Eigen::Vector3f& a = projected[face[0]];
    const Eigen::Vector3f& b = projected[face[1]];
    const Eigen::Vector3f& c = projected[face[2]];
    if (a.z() <= 0 || b.z() <= 0 || c.z() <= 0) continue;
    const float area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (std::abs(area) < 1e-6f) continue;
    const int u0 = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int u1 =
        std::min(width - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int v0 = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int v1 =
        std::min(height - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        // Barycentric weights of the pixel centre.
        const float px = u + 0.5f, py = v + 0.5f;
        const float wa = ((b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px)) / area;
        const float wb = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / area;
        const float wc = 1.0f - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        float& z = z_buffer[v * width + u];
        z = std::min(z, wa * a.z() + wb * b.z() + wc * c.z());
        any = true;
      }
    }
  }
  if (!any) return 0;
  cv::Mat covered(height, width, CV_8U, cv::Scalar(0));
  for (int pixel = 0; pixel < width * height; ++pixel) {
    if (!std::isfinite(z_buffer[pixel])) continue;
    const std::uint16_t observed = frame.depth_mm[pixel];
    if (observed == 0 || z_buffer[pixel] <= observed + depth_margin_mm) {
      covered.data[pixel] = 255;
    }
  }
  if (dilation_px > 0) {
    cv::dilate(covered, covered,
               cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                         cv::Size(2 * dilation_px + 1, 2 * dilation_px + 1)));
  }
  int cleared = 0;
  for (int pixel = 0; pixel < width * height; ++pixel) {
    if (covered.data[pixel] && (*object_mask)[pixel]) {
      (*object_mask)[pixel] = 0;
      ++cleared;
    }
  }
  return cleared;
}

}  // namespace ihs::fusion
