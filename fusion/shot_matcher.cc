#include "fusion/shot_matcher.h"

#include <pcl/features/normal_3d.h>
#include <pcl/features/shot.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/keypoints/iss_3d.h>
// PCL ships no compiled ISS3D for coloured points: its implementation is compiled here.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <cmath>
#include <limits>
#include <pcl/keypoints/impl/iss_3d.hpp>

#include "core/check.h"

namespace ihs::fusion {

void ShotOptions::Check() const {
  // The cloud is thinned to one point per resolution_mm cube before keypoints are looked for.
  IHS_CHECK_ARG(resolution_mm >= 0.5 && resolution_mm <= 50,
                "shot.resolution_mm must be in [0.5, 50]");
  // Radii in resolutions; a support of r resolutions holds about r² points of a surface each.
  IHS_CHECK_ARG(normal_radius > 0 && salient_radius > 0 && non_max_radius > 0 &&
                    support_radius > 0 && normal_radius <= 100 && salient_radius <= 100 &&
                    non_max_radius <= 100 && support_radius <= 100,
                "shot.normal_radius, salient_radius, non_max_radius and support_radius must be in "
                "(0, 100] resolutions");
  IHS_CHECK_ARG(ratio > 0 && ratio < 1, "shot.ratio must be in (0, 1)");
}

struct ShotMatcher::State {
  bool has_previous = false;
  std::vector<Eigen::Vector3d> previous_points;
  std::vector<pcl::SHOT1344> previous_descriptors;
};

ShotMatcher::ShotMatcher(const CameraIntrinsics& intrinsics, ShotOptions options)
    : intrinsics_(intrinsics),
      options_((options.Check(), options)),
      state_(std::make_unique<State>()) {}

ShotMatcher::~ShotMatcher() = default;

namespace {

float DescriptorDistanceSq(const pcl::SHOT1344& a, const pcl::SHOT1344& b) {
  float sum = 0;
  for (int i = 0; i < 1344; ++i) {
    const float d = a.descriptor[i] - b.descriptor[i];
    sum += d * d;
  }
  return sum;
}

bool Valid(const pcl::SHOT1344& d) { return std::isfinite(d.descriptor[0]); }

}  // namespace

std::vector<PointMatch> ShotMatcher::Match(const Frame& frame,
                                           const std::vector<std::uint8_t>& object_mask) {
  IHS_CHECK_ARG(object_mask.size() == frame.depth_mm.size(),
                "the object mask does not fit the frame");
  using Cloud = pcl::PointCloud<pcl::PointXYZRGB>;
  const double r = options_.resolution_mm;
  // The object's points, downsampled to the resolution.
  Cloud::Ptr points(new Cloud);
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const int pixel = v * frame.width + u;
      if (!object_mask[pixel] || frame.depth_mm[pixel] == 0) continue;
      const Eigen::Vector3d p = intrinsics_.BackProject(u, v, frame.depth_mm[pixel]);
      pcl::PointXYZRGB point;
      point.x = static_cast<float>(p.x()), point.y = static_cast<float>(p.y());
      point.z = static_cast<float>(p.z());
      if (frame.HasColor()) {
        point.r = frame.rgb[3 * pixel], point.g = frame.rgb[3 * pixel + 1];
        point.b = frame.rgb[3 * pixel + 2];
      }
      points->push_back(point);
    }
  }
  std::vector<Eigen::Vector3d> keypoint_positions;
  std::vector<pcl::SHOT1344> descriptors;
  if (points->size() >= 50) {
    Cloud::Ptr cloud(new Cloud);
    pcl::VoxelGrid<pcl::PointXYZRGB> grid;
    grid.setInputCloud(points);
    grid.setLeafSize(static_cast<float>(r), static_cast<float>(r), static_cast<float>(r));
    grid.filter(*cloud);

    pcl::search::KdTree<pcl::PointXYZRGB>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZRGB>);
    tree->setInputCloud(cloud);
    // Normals toward the camera (PCL's default viewpoint is the origin: the camera).
    pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
    pcl::NormalEstimation<pcl::PointXYZRGB, pcl::Normal> normal_estimation;
    normal_estimation.setInputCloud(cloud);
    normal_estimation.setSearchMethod(tree);
    normal_estimation.setRadiusSearch(options_.normal_radius * r);
    normal_estimation.compute(*normals);

    Cloud::Ptr keypoints(new Cloud);
    pcl::ISSKeypoint3D<pcl::PointXYZRGB, pcl::PointXYZRGB> iss;
    iss.setSearchMethod(tree);
    iss.setSalientRadius(options_.salient_radius * r);
    iss.setNonMaxRadius(options_.non_max_radius * r);
    iss.setThreshold21(0.975);
    iss.setThreshold32(0.975);
    iss.setMinNeighbors(5);
    iss.setNumberOfThreads(1);
    iss.setInputCloud(cloud);
    iss.compute(*keypoints);

    if (!keypoints->empty()) {
      pcl::PointCloud<pcl::SHOT1344> shots;
      pcl::SHOTColorEstimation<pcl::PointXYZRGB, pcl::Normal, pcl::SHOT1344> shot;
      shot.setInputCloud(keypoints);
      shot.setSearchSurface(cloud);
      shot.setInputNormals(normals);
      shot.setSearchMethod(tree);
      shot.setRadiusSearch(options_.support_radius * r);
      shot.compute(shots);
      for (size_t k = 0; k < keypoints->size() && k < shots.size(); ++k) {
        if (!Valid(shots[k])) continue;
        const auto& p = (*keypoints)[k];
        keypoint_positions.emplace_back(p.x, p.y, p.z);
        descriptors.push_back(shots[k]);
      }
    }
  }

  std::vector<PointMatch> matches;
  if (state_->has_previous && state_->previous_descriptors.size() >= 2) {
    for (size_t k = 0; k < descriptors.size(); ++k) {
      float best = std::numeric_limits<float>::infinity(), second = best;
      size_t best_index = 0;
      for (size_t j = 0; j < state_->previous_descriptors.size(); ++j) {
        const float d = DescriptorDistanceSq(descriptors[k], state_->previous_descriptors[j]);
        if (d < best) {
          second = best, best = d, best_index = j;
        } else if (d < second) {
          second = d;
        }
      }
      // Ratio test on distances (squared distances against the squared ratio).
      if (best < options_.ratio * options_.ratio * second) {
        matches.push_back({state_->previous_points[best_index], keypoint_positions[k]});
      }
    }
  }
  state_->previous_points = std::move(keypoint_positions);
  state_->previous_descriptors = std::move(descriptors);
  state_->has_previous = true;
  return matches;
}

std::vector<PointMatch> ShotMatcher::Match(const MatchContext& context) {
  IHS_CHECK_ARG(context.frame != nullptr && context.object_mask != nullptr,
                "ShotMatcher needs a frame and its object mask");
  return Match(*context.frame, *context.object_mask);
}

}  // namespace ihs::fusion
