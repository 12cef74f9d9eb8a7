#include "fusion/convex_hull.h"

#include <algorithm>
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

}  // namespace ihs::fusion
