#include "core/point_kd_tree.h"

#include <nanoflann.hpp>

namespace ihs {
namespace {

struct Cloud {
  std::vector<Eigen::Vector3f> points;
  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return points[i][static_cast<int>(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box&) const {
    return false;
  }
};

using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Cloud>, Cloud,
                                                 3, std::uint32_t>;

}  // namespace

// Points per leaf. The trees here hold a few hundred to a few thousand points and are asked
// a few queries per point or, in the hand search, a million in all: 20 answered the same
// (the hands, trajectories and meshes of the scans byte for byte) in 6 % less time on a full
// turn's tracking than 12 (docs/app.md); 6 and 48 were slower.
constexpr size_t kLeafSize = 20;

struct PointKdTree::Index {
  Cloud cloud;
  Tree tree;
  explicit Index(std::vector<Eigen::Vector3f> points)
      : cloud{std::move(points)},
        tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(kLeafSize)) {
    tree.buildIndex();
  }
};

PointKdTree::PointKdTree(std::vector<Eigen::Vector3f> points)
    : index_(std::make_unique<Index>(std::move(points))) {}

PointKdTree::~PointKdTree() = default;

const std::vector<Eigen::Vector3f>& PointKdTree::points() const { return index_->cloud.points; }

int PointKdTree::Nearest(const Eigen::Vector3f& query, float* distance_sq) const {
  if (index_->cloud.points.empty()) return -1;
  std::uint32_t index = 0;
  float d2 = 0;
  index_->tree.knnSearch(query.data(), 1, &index, &d2);
  if (distance_sq) *distance_sq = d2;
  return static_cast<int>(index);
}

int PointKdTree::NearestWithin(const Eigen::Vector3f& query, float max_distance_sq,
                               float* distance_sq) const {
  if (index_->cloud.points.empty()) return -1;
  std::uint32_t index = 0;
  float d2 = 0;
  nanoflann::KNNResultSet<float, std::uint32_t> result(1);
  result.init(&index, &d2);
  d2 = max_distance_sq;  // The worst distance the search keeps: only nearer points are added.
  index_->tree.findNeighbors(result, query.data(), nanoflann::SearchParams());
  if (result.size() == 0) return -1;
  if (distance_sq) *distance_sq = d2;
  return static_cast<int>(index);
}

int PointKdTree::CountWithin(const Eigen::Vector3f& query, float radius_mm) const {
  if (index_->cloud.points.empty()) return 0;
  std::vector<std::pair<std::uint32_t, float>> matches;
  nanoflann::SearchParams params;
  params.sorted = false;
  return static_cast<int>(
      index_->tree.radiusSearch(query.data(), radius_mm * radius_mm, matches, params));
}

}  // namespace ihs
