#include "app/object_mask.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace ihs::app {

int RemoveMeshPixels(const TriangleMesh& mesh, const Frame& frame,
                     const CameraIntrinsics& intrinsics, int dilation_px, double depth_margin_mm,
                     std::vector<std::uint8_t>* object_mask) {
  IHS_CHECK_ARG(object_mask->size() == frame.depth_mm.size(),
                "the object mask does not fit the frame");
  IHS_CHECK_ARG(dilation_px >= 0, "dilation_px must not be negative");
  const int width = frame.width, height = frame.height;
  std::vector<Eigen::Vector3f> projected(mesh.vertices.size());  // u, v, z
  // The image box the mesh projects into, grown by the dilation: the only pixels touched.
  float low_u = std::numeric_limits<float>::infinity(), low_v = low_u;
  float high_u = -low_u, high_v = -low_u;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Eigen::Vector3f& p = mesh.vertices[i];
    if (p.z() <= 1.0f) {
      projected[i] = {0, 0, -1};
      continue;
    }
    projected[i] = {static_cast<float>(intrinsics.fx * p.x() / p.z() + intrinsics.cx),
                    static_cast<float>(intrinsics.fy * p.y() / p.z() + intrinsics.cy), p.z()};
    low_u = std::min(low_u, projected[i].x()), high_u = std::max(high_u, projected[i].x());
    low_v = std::min(low_v, projected[i].y()), high_v = std::max(high_v, projected[i].y());
  }
  const auto clamp_to = [](float x, int limit) {
    return static_cast<int>(std::clamp(x, -1.0f, static_cast<float>(limit)));
  };
  const int box_u0 = std::max(0, clamp_to(std::floor(low_u), width) - dilation_px);
  const int box_v0 = std::max(0, clamp_to(std::floor(low_v), height) - dilation_px);
  const int box_u1 = std::min(width - 1, clamp_to(std::ceil(high_u), width) + dilation_px);
  const int box_v1 = std::min(height - 1, clamp_to(std::ceil(high_v), height) + dilation_px);
  if (box_u1 < box_u0 || box_v1 < box_v0) return 0;
  const int box_width = box_u1 - box_u0 + 1, box_height = box_v1 - box_v0 + 1;
  // Nearest mesh depth per pixel of the box: a small z-buffer of the projected triangles.
  std::vector<float> z_buffer(static_cast<size_t>(box_width) * box_height,
                              std::numeric_limits<float>::infinity());
  bool any = false;
  for (const auto& face : mesh.faces) {
    const Eigen::Vector3f& a = projected[face[0]];
    const Eigen::Vector3f& b = projected[face[1]];
    const Eigen::Vector3f& c = projected[face[2]];
    if (a.z() <= 0 || b.z() <= 0 || c.z() <= 0) continue;
    const float area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (std::abs(area) < 1e-6f) continue;
    const int u0 = std::max(box_u0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int u1 = std::min(box_u1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int v0 = std::max(box_v0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int v1 = std::min(box_v1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        // Barycentric weights of the pixel centre; a weight's sign is its numerator's times the
        // area's, so most pixels outside are told without dividing.
        const float px = u + 0.5f, py = v + 0.5f;
        const float na = (b.x() - px) * (c.y() - py) - (b.y() - py) * (c.x() - px);
        const float nb = (c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px);
        if ((area > 0) ? (na < 0 || nb < 0) : (na > 0 || nb > 0)) continue;
        const float wa = na / area, wb = nb / area;
        const float wc = 1.0f - wa - wb;
        if (wa < 0 || wb < 0 || wc < 0) continue;
        float& z = z_buffer[static_cast<size_t>(v - box_v0) * box_width + (u - box_u0)];
        z = std::min(z, wa * a.z() + wb * b.z() + wc * c.z());
        any = true;
      }
    }
  }
  if (!any) return 0;
  cv::Mat covered(box_height, box_width, CV_8U, cv::Scalar(0));
  for (int v = box_v0; v <= box_v1; ++v) {
    for (int u = box_u0; u <= box_u1; ++u) {
      const size_t cell = static_cast<size_t>(v - box_v0) * box_width + (u - box_u0);
      if (!std::isfinite(z_buffer[cell])) continue;
      const std::uint16_t observed = frame.depth_mm[v * width + u];
      if (observed == 0 || z_buffer[cell] <= observed + depth_margin_mm) covered.data[cell] = 255;
    }
  }
  if (dilation_px > 0) {
    // The box holds the dilation's reach around every covered pixel; outside it nothing is.
    cv::dilate(covered, covered,
               cv::getStructuringElement(cv::MORPH_ELLIPSE,
                                         cv::Size(2 * dilation_px + 1, 2 * dilation_px + 1)),
               cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  }
  int cleared = 0;
  for (int v = box_v0; v <= box_v1; ++v) {
    for (int u = box_u0; u <= box_u1; ++u) {
      std::uint8_t& object = (*object_mask)[v * width + u];
      if (covered.data[static_cast<size_t>(v - box_v0) * box_width + (u - box_u0)] && object) {
        object = 0;
        ++cleared;
      }
    }
  }
  return cleared;
}

}  // namespace ihs::app
