#include "fusion/sift_matcher.h"

#include <algorithm>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/check.h"

namespace ihs::fusion {

void SiftOptions::Check() const {
  IHS_CHECK_ARG(max_features >= 10 && max_features <= 100000,
                "sift.max_features must be in [10, 100000]");
  IHS_CHECK_ARG(ratio > 0 && ratio < 1, "sift.ratio must be in (0, 1)");
  IHS_CHECK_ARG(support_inside >= 0 && support_inside <= 4,
                "sift.support_inside must be in [0, 4]");
}

namespace {

// Drops the keypoints whose neighbourhood reaches farther off `mask` than `share` of its radius
// allows (SiftOptions::support_inside).
void KeepInside(const cv::Mat& mask, double share, std::vector<cv::KeyPoint>* keypoints,
                cv::Mat* descriptors) {
  // Each pixel's distance to the nearest pixel off the object (or the search box's edge).
  cv::Mat padded, distance;
  cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
  cv::distanceTransform(padded, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  std::vector<cv::KeyPoint> kept;
  cv::Mat kept_descriptors;
  for (size_t k = 0; k < keypoints->size(); ++k) {
    const cv::KeyPoint& keypoint = (*keypoints)[k];
    const int u = cvRound(keypoint.pt.x) + 1, v = cvRound(keypoint.pt.y) + 1;
    if (u < 0 || v < 0 || u >= distance.cols || v >= distance.rows) continue;
    if (distance.at<float>(v, u) < share * keypoint.size / 2) continue;
    kept.push_back(keypoint);
    kept_descriptors.push_back(descriptors->row(static_cast<int>(k)));
  }
  *keypoints = std::move(kept);
  *descriptors = kept_descriptors;
}

// The keypoints of `frame` on the object's pixels (with depth), back-projected, and their
// descriptors (one row each).
void Detect(cv::SIFT& sift, const Frame& frame, const std::vector<std::uint8_t>& object_mask,
            const CameraIntrinsics& intrinsics, const SiftOptions& options,
            std::vector<Eigen::Vector3d>* points, cv::Mat* kept) {
  // Only the object's bounding box (with room for the descriptors' support) is searched.
  int u0 = frame.width, v0 = frame.height, u1 = -1, v1 = -1;
  for (int v = 0; v < frame.height; ++v) {
    for (int u = 0; u < frame.width; ++u) {
      const int pixel = v * frame.width + u;
      if (!object_mask[pixel] || frame.depth_mm[pixel] == 0) continue;
      u0 = std::min(u0, u), v0 = std::min(v0, v), u1 = std::max(u1, u), v1 = std::max(v1, v);
    }
  }
  if (u1 < u0) return;
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  constexpr int kPad = 16;
  const cv::Rect box =
      cv::Rect(u0 - kPad, v0 - kPad, u1 - u0 + 1 + 2 * kPad, v1 - v0 + 1 + 2 * kPad) &
      cv::Rect(0, 0, frame.width, frame.height);
  const cv::Mat rgb(frame.height, frame.width, CV_8UC3,
                    const_cast<std::uint8_t*>(frame.rgb.data()));
  cv::Mat gray;
  cv::cvtColor(rgb(box), gray, cv::COLOR_RGB2GRAY);
  cv::Mat mask(box.height, box.width, CV_8U);
  for (int v = 0; v < box.height; ++v) {
    for (int u = 0; u < box.width; ++u) {
      const int pixel = (v + box.y) * frame.width + u + box.x;
      mask.at<std::uint8_t>(v, u) = object_mask[pixel] && frame.depth_mm[pixel] != 0 ? 255 : 0;
    }
  }
  sift.detectAndCompute(gray, mask, keypoints, descriptors);
  if (options.support_inside > 0)
    KeepInside(mask, options.support_inside, &keypoints, &descriptors);
  // Keypoints with depth at their (rounded) position, back-projected.
  for (size_t k = 0; k < keypoints.size(); ++k) {
    const cv::Point2f at = keypoints[k].pt + cv::Point2f(box.x, box.y);
    const int u = cvRound(at.x), v = cvRound(at.y);
    if (u < 0 || v < 0 || u >= frame.width || v >= frame.height) continue;
    const std::uint16_t z = frame.DepthAt(u, v);
    if (z == 0 || !object_mask[v * frame.width + u]) continue;
    points->push_back(intrinsics.BackProject(at.x, at.y, z));
    kept->push_back(descriptors.row(static_cast<int>(k)));
  }
}

cv::Ptr<cv::SIFT> MakeSift(const SiftOptions& options) {
  // OpenCV's defaults but the edge threshold, which the authors' configuration raises to 15.
  return cv::SIFT::create(options.max_features, 3, 0.04, 15.0, 1.6);
}

}  // namespace

struct SiftMatcher::State {
  cv::Ptr<cv::SIFT> sift;
  cv::BFMatcher matcher{cv::NORM_L2};
  bool has_previous = false;
  std::vector<Eigen::Vector3d> previous_points;
  cv::Mat previous_descriptors;
  // Each previous keypoint's track: the id its first sighting was given.
  std::vector<int> previous_tracks;
  int next_track = 0;
  int NewTrack() {
    const int track = next_track;
    next_track = next_track == std::numeric_limits<int>::max() ? 0 : next_track + 1;
    return track;
  }
};

SiftMatcher::SiftMatcher(const CameraIntrinsics& intrinsics, SiftOptions options)
    : intrinsics_(intrinsics),
      options_((options.Check(), options)),
      state_(std::make_unique<State>()) {
  state_->sift = MakeSift(options_);
}

SiftMatcher::~SiftMatcher() = default;

ObjectKeypoints DetectObjectKeypoints(const Frame& frame,
                                      const std::vector<std::uint8_t>& object_mask,
                                      const CameraIntrinsics& intrinsics,
                                      const SiftOptions& options) {
  options.Check();
  IHS_CHECK_ARG(object_mask.size() == frame.depth_mm.size(),
                "the object mask does not fit the frame");
  ObjectKeypoints found;
  if (!frame.HasColor()) return found;
  std::vector<Eigen::Vector3d> points;
  cv::Mat descriptors;
  Detect(*MakeSift(options), frame, object_mask, intrinsics, options, &points, &descriptors);
  for (const Eigen::Vector3d& point : points) found.points.push_back(point.cast<float>());
  descriptors.convertTo(descriptors, CV_32F);
  found.descriptors.assign(descriptors.ptr<float>(),
                           descriptors.ptr<float>() + descriptors.total());
  return found;
}

std::vector<PointMatch> SiftMatcher::Match(const Frame& frame,
                                           const std::vector<std::uint8_t>& object_mask) {
  IHS_CHECK_ARG(object_mask.size() == frame.depth_mm.size(),
                "the object mask does not fit the frame");
  std::vector<PointMatch> matches;
  if (!frame.HasColor()) {
    state_->has_previous = false;
    return matches;
  }
  std::vector<Eigen::Vector3d> points;
  cv::Mat kept;
  Detect(*state_->sift, frame, object_mask, intrinsics_, options_, &points, &kept);
  std::vector<int> tracks(points.size(), -1);
  if (state_->has_previous && !kept.empty() && state_->previous_descriptors.rows >= 2) {
    std::vector<std::vector<cv::DMatch>> candidates;
    state_->matcher.knnMatch(kept, state_->previous_descriptors, candidates, 2);
    std::vector<bool> continued(state_->previous_points.size(), false);
    for (const auto& pair : candidates) {
      if (pair.size() < 2 || pair[0].distance >= options_.ratio * pair[1].distance) continue;
      const int current = pair[0].queryIdx, previous = pair[0].trainIdx;
      // A track goes on in one keypoint: another matched to the same one starts its own.
      if (!continued[previous]) tracks[current] = state_->previous_tracks[previous];
      continued[previous] = true;
      if (tracks[current] < 0) tracks[current] = state_->NewTrack();
      matches.push_back({state_->previous_points[previous], points[current], tracks[current]});
    }
  }
  for (int& track : tracks) {
    if (track < 0) track = state_->NewTrack();
  }
  state_->previous_points = std::move(points);
  state_->previous_descriptors = kept;
  state_->previous_tracks = std::move(tracks);
  state_->has_previous = true;
  return matches;
}

std::vector<PointMatch> SiftMatcher::Match(const MatchContext& context) {
  IHS_CHECK_ARG(context.frame != nullptr && context.object_mask != nullptr,
                "SiftMatcher needs a frame and its object mask");
  return Match(*context.frame, *context.object_mask);
}

}  // namespace ihs::fusion
