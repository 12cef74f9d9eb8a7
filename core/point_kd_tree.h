#pragma once
// Nearest-neighbour queries over a fixed set of 3D points (a k-d tree; nanoflann stays in the
// .cc file).

#include <Eigen/Core>
#include <memory>
#include <vector>

namespace ihs {

/// A k-d tree over points (copied in).
class PointKdTree {
 public:
  explicit PointKdTree(std::vector<Eigen::Vector3f> points);
  ~PointKdTree();
  PointKdTree(const PointKdTree&) = delete;
  PointKdTree& operator=(const PointKdTree&) = delete;

  /// Index of the point nearest `query` and its squared distance (mm²), or −1 when empty.
  int Nearest(const Eigen::Vector3f& query, float* distance_sq) const;
  /// Number of points within `radius_mm` of `query`.
  int CountWithin(const Eigen::Vector3f& query, float radius_mm) const;
  /// The nearest point nearer than √`max_distance_sq` (its squared distance in `distance_sq`),
  /// or −1 when there is none: Nearest's answer where that is within the bound, found without
  /// looking beyond it (a capped distance needs no more).
  int NearestWithin(const Eigen::Vector3f& query, float max_distance_sq, float* distance_sq) const;

  const std::vector<Eigen::Vector3f>& points() const;

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

}  // namespace ihs
