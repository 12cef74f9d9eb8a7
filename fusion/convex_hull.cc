#include "fusion/convex_hull.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

extern "C" {
#include <libqhull_r/qhull_ra.h>
}

namespace ihs::fusion {
namespace {

// qhull's messages (a degenerate input's "initial simplex is flat") go nowhere: an empty hull
// says the same to the caller.
struct FileCloser {
  void operator()(FILE* file) const { std::fclose(file); }
};

// The outward normals of the faces qhull finds for `coordinates` (x, y, z per point, centred),
// with `command` its options (offsets 0); empty when qhull fails (a flat or too small input).
std::vector<Eigen::Vector4f> QhullPlanes(std::vector<double>* coordinates,
                                         const std::string& command) {
  const std::unique_ptr<FILE, FileCloser> quiet(std::fopen("/dev/null", "w"));
  FILE* errors = quiet ? quiet.get() : stderr;
  qhT state;
  qhT* qh = &state;
  qh_zero(qh, errors);
  std::vector<char> options(command.begin(), command.end());
  options.push_back('\0');
  const int status = qh_new_qhull(qh, 3, static_cast<int>(coordinates->size() / 3),
                                  coordinates->data(), False, options.data(), nullptr, errors);
  std::vector<Eigen::Vector4f> planes;
  if (status == 0) {
    facetT* facet;
    FORALLfacets {  // The offset is set by the caller, from the points.
      planes.emplace_back(static_cast<float>(facet->normal[0]),
                          static_cast<float>(facet->normal[1]),
                          static_cast<float>(facet->normal[2]), 0.0f);
    }
  }
  qh_freeqhull(qh, !qh_ALL);
  int still_long = 0, total_long = 0;
  qh_memfreeshort(qh, &still_long, &total_long);
  return planes;
}

}  // namespace

ConvexHull ConvexHull::Of(const std::vector<Eigen::Vector3f>& points, double merge_mm) {
  ConvexHull hull;
  if (points.size() < 4) return hull;
  // Centred, so that qhull's precision is that of the object's size, not of its place.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : points) centre += p.cast<double>();
  centre /= static_cast<double>(points.size());
  std::vector<double> coordinates;
  coordinates.reserve(3 * points.size());
  for (const auto& p : points) {
    for (int axis = 0; axis < 3; ++axis) coordinates.push_back(p[axis] - centre[axis]);
  }
  std::string command = "qhull";
  if (merge_mm > 0) command += " C-" + std::to_string(merge_mm);
  hull.planes_ = QhullPlanes(&coordinates, command);
  // Back to the points' frame, each plane moved out to the farthest point (a merged face may
  // leave points up to about `merge_mm` outside it).
  for (auto& plane : hull.planes_) {
    const Eigen::Vector3f normal = plane.head<3>();
    float farthest = -std::numeric_limits<float>::max();
    for (const auto& p : points) farthest = std::max(farthest, normal.dot(p));
    plane[3] = farthest;
  }
  return hull;
}

float ConvexHull::SignedDistance(const Eigen::Vector3f& point, float limit) const {
  float distance = -limit;
  for (const auto& plane : planes_) {
    distance = std::max(distance, plane.head<3>().dot(point) - plane[3]);
    if (distance >= limit) return limit;
  }
  return distance;
}

std::vector<Eigen::Vector3f> RevolvedEnvelope(const std::vector<Eigen::Vector3f>& points,
                                              const Eigen::Vector3d& centre,
                                              const Eigen::Vector3d& axis, double slice_mm,
                                              int segments) {
  std::vector<Eigen::Vector3f> envelope;
  if (points.empty()) return envelope;
  // Per slice: the lowest and highest height along the axis and the largest distance from it.
  struct Slice {
    double low = INFINITY, high = -INFINITY, reach = 0;
  };
  std::vector<double> height(points.size());
  double lowest = INFINITY;
  for (size_t n = 0; n < points.size(); ++n) {
    height[n] = (points[n].cast<double>() - centre).dot(axis);
    lowest = std::min(lowest, height[n]);
  }
  std::vector<Slice> slices;
  for (size_t n = 0; n < points.size(); ++n) {
    const auto s = static_cast<size_t>((height[n] - lowest) / slice_mm);
    if (s >= slices.size()) slices.resize(s + 1);
    const Eigen::Vector3d off = points[n].cast<double>() - centre - height[n] * axis;
    slices[s].low = std::min(slices[s].low, height[n]);
    slices[s].high = std::max(slices[s].high, height[n]);
    slices[s].reach = std::max(slices[s].reach, off.norm());
  }
  // A polygon circumscribed about the circle of radius `reach`.
  const Eigen::Vector3d u = axis.unitOrthogonal(), v = axis.cross(u);
  for (const Slice& slice : slices) {
    if (slice.high < slice.low) continue;  // No point in this slice.
    const double radius = slice.reach / std::cos(M_PI / segments);
    for (const double h : {slice.low, slice.high}) {
      for (int k = 0; k < segments; ++k) {
        const double angle = 2 * M_PI * k / segments;
        envelope.push_back(
            (centre + h * axis + radius * (std::cos(angle) * u + std::sin(angle) * v))
                .cast<float>());
      }
    }
  }
  return envelope;
}

}  // namespace ihs::fusion
