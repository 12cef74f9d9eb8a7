#include "fusion/keyframe_graph.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <utility>

#include "core/check.h"
#include "core/rigid_fit.h"
#include "fusion/pairwise_registration.h"

namespace ihs::fusion {
namespace {

// The angle between two poses' views of the object, degrees.
double TurnDeg(const Rigid3& a, const Rigid3& b) { return a.RotationAngleToRad(b) * 180.0 / M_PI; }

// A keyframe's descriptors as OpenCV's matcher takes them (one float row each).
cv::Mat Descriptors(const Keyframe& keyframe) {
  const int rows = static_cast<int>(keyframe.keypoints.size());
  cv::Mat bytes(rows, ObjectKeypoints::kDescriptorSize, CV_8U,
                const_cast<std::uint8_t*>(keyframe.descriptors.data()));
  cv::Mat floats;
  bytes.convertTo(floats, CV_32F);
  return floats;
}

// The pairs (from's keypoint, to's keypoint) whose descriptors match by Lowe's ratio.
std::vector<PointMatch> MatchKeypoints(const Keyframe& from, const Keyframe& to, double ratio) {
  std::vector<PointMatch> pairs;
  if (from.keypoints.empty() || to.keypoints.size() < 2) return pairs;
  std::vector<std::vector<cv::DMatch>> candidates;
  cv::BFMatcher(cv::NORM_L2).knnMatch(Descriptors(from), Descriptors(to), candidates, 2);
  for (const auto& pair : candidates) {
    if (pair.size() < 2 || pair[0].distance >= ratio * pair[1].distance) continue;
    pairs.push_back({from.keypoints[pair[0].queryIdx].cast<double>(),
                     to.keypoints[pair[0].trainIdx].cast<double>()});
  }
  return pairs;
}

Eigen::Vector3d Centroid(const std::vector<Eigen::Vector3f>& points) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& point : points) sum += point.cast<double>();
  return sum / std::max<size_t>(1, points.size());
}

}  // namespace

void LoopClosureOptions::Check() const {
  IHS_CHECK_ARG(keyframe_turn_deg > 0, "fusion.loop_closure.keyframe_turn_deg must be positive");
  IHS_CHECK_ARG(max_keyframes >= 2, "fusion.loop_closure.max_keyframes must be >= 2");
  IHS_CHECK_ARG(loop_min_gap >= 2, "fusion.loop_closure.loop_min_gap must be >= 2");
  IHS_CHECK_ARG(loop_max_turn_deg > 0 && loop_max_turn_deg < 90,
                "fusion.loop_closure.loop_max_turn_deg must be in (0, 90)");
  IHS_CHECK_ARG(loop_tries >= 1, "fusion.loop_closure.loop_tries must be >= 1");
  IHS_CHECK_ARG(loop_pending_keyframes >= 1,
                "fusion.loop_closure.loop_pending_keyframes must be >= 1");
  IHS_CHECK_ARG(loop_agreement_mm > 0, "fusion.loop_closure.loop_agreement_mm must be positive");
  IHS_CHECK_ARG(chain_trusted_kept > 0.5 && chain_trusted_kept <= 1,
                "fusion.loop_closure.chain_trusted_kept must be in (0.5, 1]");
  IHS_CHECK_ARG(icp_start_mm > 0, "fusion.loop_closure.icp_start_mm must be positive");
  IHS_CHECK_ARG(min_inlier_fraction > 0 && min_inlier_fraction <= 1,
                "fusion.loop_closure.min_inlier_fraction must be in (0, 1]");
  IHS_CHECK_ARG(max_rms_mm > 0 && max_correction_mm > 0 && refuse_min_mm >= 0,
                "fusion.loop_closure.max_rms_mm and max_correction_mm must be positive, "
                "refuse_min_mm >= 0");
  IHS_CHECK_ARG(feature_keypoints >= 10 && feature_keypoints <= 2000,
                "fusion.loop_closure.feature_keypoints must be in [10, 2000]");
  IHS_CHECK_ARG(feature_max_turn_deg > 0 && feature_max_turn_deg <= 180,
                "fusion.loop_closure.feature_max_turn_deg must be in (0, 180]");
  IHS_CHECK_ARG(feature_tries >= 1, "fusion.loop_closure.feature_tries must be >= 1");
  IHS_CHECK_ARG(feature_min_inliers >= 3, "fusion.loop_closure.feature_min_inliers must be >= 3");
  IHS_CHECK_ARG(feature_inlier_mm > 0 && feature_distinct_deg > 0,
                "fusion.loop_closure.feature_inlier_mm and feature_distinct_deg must be positive");
  IHS_CHECK_ARG(feature_max_rival >= 0 && feature_max_rival <= 1,
                "fusion.loop_closure.feature_max_rival must be in [0, 1]");
  IHS_CHECK_ARG(feature_min_inlier_fraction > 0 && feature_min_inlier_fraction <= 1,
                "fusion.loop_closure.feature_min_inlier_fraction must be in (0, 1]");
  IHS_CHECK_ARG(spin_axis_min_deg > 0, "fusion.loop_closure.spin_axis_min_deg must be positive");
  IHS_CHECK_ARG(feature_alias_share > 0,
                "fusion.loop_closure.feature_alias_share must be positive");
  IHS_CHECK_ARG(feature_drift_share > 0 && feature_min_gate_deg >= 0,
                "fusion.loop_closure.feature_drift_share must be positive, feature_min_gate_deg "
                ">= 0");
  graph.Check();
}

void Keyframe::PasteInto(Frame* frame, std::vector<std::uint8_t>* mask) const {
  const bool color =
      !rgb.empty() && frame->rgb.size() == 3 * static_cast<size_t>(frame->width) * frame->height;
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t at = static_cast<size_t>(v) * width + u;
      if (depth_mm[at] == 0) continue;
      const size_t pixel = static_cast<size_t>(v0 + v) * frame->width + (u0 + u);
      frame->depth_mm[pixel] = depth_mm[at];
      (*mask)[pixel] = 1;
      if (color) std::copy_n(&rgb[3 * at], 3, &frame->rgb[3 * pixel]);
    }
  }
}

void Keyframe::ClearFrom(Frame* frame, std::vector<std::uint8_t>* mask) const {
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const size_t pixel = static_cast<size_t>(v0 + v) * frame->width + (u0 + u);
      frame->depth_mm[pixel] = 0;
      (*mask)[pixel] = 0;
    }
  }
}

KeyframeGraph::KeyframeGraph(const CameraIntrinsics& intrinsics, LoopClosureOptions options,
                             IcpOptions icp)
    : intrinsics_(intrinsics),
      options_((options.Check(), std::move(options))),
      icp_(std::move(icp)) {
  icp_.Check();
}

Rigid3 KeyframeGraph::CorrectionAt(const std::vector<Keyframe>& keyframes,
                                   const std::vector<Rigid3>& corrections, int stamp) {
  IHS_CHECK_ARG(keyframes.size() == corrections.size() && !keyframes.empty(),
                "a correction per keyframe is needed");
  if (stamp <= keyframes.front().stamp) return corrections.front();
  for (size_t i = 1; i < keyframes.size(); ++i) {
    if (stamp > keyframes[i].stamp) continue;
    const double s = static_cast<double>(stamp - keyframes[i - 1].stamp) /
                     std::max(1, keyframes[i].stamp - keyframes[i - 1].stamp);
    return corrections[i - 1].Interpolate(corrections[i], s);
  }
  return corrections.back();
}

KeyframeUpdate KeyframeGraph::Observe(const Frame& frame, const std::vector<std::uint8_t>& mask,
                                      const std::array<int, 4>& box, const Rigid3& cam_from_object,
                                      int stamp, double kept_pairs, bool turn_free) {
  KeyframeUpdate update;
  chain_kept_ = std::min(chain_kept_, kept_pairs);
  if (!options_.enabled || static_cast<int>(keyframes_.size()) >= options_.max_keyframes ||
      box[2] <= box[0] || box[3] <= box[1]) {
    return update;
  }
  if (!keyframes_.empty() &&
      TurnDeg(cam_from_object, keyframes_.back().cam_from_object) < options_.keyframe_turn_deg) {
    return update;
  }
  const bool by_keypoints = turn_free && options_.feature_loops;
  keyframes_.push_back(Keep(frame, mask, box, cam_from_object, stamp));
  if (by_keypoints) {
    SiftOptions sift;
    sift.max_features = options_.feature_keypoints;
    const ObjectKeypoints found = DetectObjectKeypoints(frame, mask, intrinsics_, sift);
    keyframes_.back().keypoints = found.points;
    // SIFT's descriptors are whole numbers in [0, 255] (OpenCV saturates them to bytes).
    keyframes_.back().descriptors.assign(found.descriptors.begin(), found.descriptors.end());
  }
  update.added = true;
  if (keyframes_.size() == 1) return update;
  AddChainEdge(turn_free);
  update.loops = AddConfirmedLoops(by_keypoints);
  update.feature_loops = feature_loops_;
  if (update.loops > 0) Solve(&update);
  return update;
}

void KeyframeGraph::AddChainEdge(bool spin_free) {
  // The tracked motion from the previous keyframe, trusted less where a frame in between
  // may have slid.
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  const double trust =
      std::clamp((chain_kept_ - 0.5) / (options_.chain_trusted_kept - 0.5), 0.1, 1.0);
  chain_kept_ = 1.0;
  edges_.push_back(
      {newest - 1, newest,
       keyframes_[newest].cam_from_object * keyframes_[newest - 1].cam_from_object.Inverse(),
       std::pow(trust, 4), spin_free});
}

int KeyframeGraph::AddConfirmedLoops(bool by_keypoints) {
  // Loops with the earlier keyframes. One counts only where another agrees with it — of this
  // keyframe or of one of the last `loop_pending_keyframes`, carried along the chain — on
  // where this keyframe's object is, within `loop_agreement_mm`: a view that registers where
  // it is not (a cube's faces are alike) rarely does so twice alike.
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  std::vector<Loop> found;
  if (by_keypoints) {
    found = KeypointLoops();
  } else {
    for (int earlier : LoopCandidates()) {
      const std::optional<Rigid3> motion = Register(keyframes_[newest], keyframes_[earlier]);
      if (!motion) continue;
      found.push_back({{newest, earlier, *motion, 1.0},
                       motion->Inverse() * keyframes_[earlier].cam_from_object,
                       false,
                       false});
    }
  }
  std::vector<Loop*> all;
  for (Loop& loop : pending_) all.push_back(&loop);
  for (Loop& loop : found) all.push_back(&loop);
  // Where each puts the newest keyframe: its own keyframe's placement moved on by the chain.
  std::vector<Rigid3> placed;
  for (const Loop* loop : all) {
    const Rigid3& then = keyframes_[loop->edge.from].cam_from_object;
    placed.push_back(keyframes_[newest].cam_from_object * then.Inverse() * loop->placed);
  }
  for (size_t i = 0; i < all.size(); ++i) {
    for (size_t j = i + 1; j < all.size(); ++j) {
      if (all[i]->edge.from == all[j]->edge.from && all[i]->edge.to == all[j]->edge.to) continue;
      if (PoseDistanceMm(placed[i], placed[j], options_.graph.lever_mm) <=
          options_.loop_agreement_mm) {
        all[i]->confirmed = all[j]->confirmed = true;
      }
    }
  }
  int added = 0;
  feature_loops_ = 0;
  std::vector<Loop> still_pending;
  for (size_t i = 0; i < all.size(); ++i) {
    const Loop* loop = all[i];
    if (loop->confirmed && loop->by_keypoints && options_.spin_axis_loops) {
      // The correction this loop asks of the newest keyframe turns about the object's spin axis.
      const Rigid3 correction = keyframes_[newest].cam_from_object.Inverse() * placed[i];
      const double deg = correction.RotationAngleToRad(Rigid3()) * 180.0 / M_PI;
      if (deg > spin_axis_deg_) {
        if (std::optional<SpinAxis> axis = ScrewAxis(correction, options_.spin_axis_min_deg)) {
          spin_axis_ = axis;
          spin_axis_deg_ = deg;
        }
      }
    }
    if (loop->confirmed) {
      edges_.push_back(loop->edge);
      ++added;
      feature_loops_ += loop->by_keypoints ? 1 : 0;
    } else if (newest - loop->edge.from < options_.loop_pending_keyframes) {
      still_pending.push_back(*loop);
    }
  }
  pending_ = std::move(still_pending);
  return added;
}

Keyframe KeyframeGraph::Keep(const Frame& frame, const std::vector<std::uint8_t>& mask,
                             const std::array<int, 4>& box, const Rigid3& cam_from_object,
                             int stamp) const {
  Keyframe kept;
  kept.stamp = stamp;
  kept.cam_from_object = cam_from_object;
  kept.u0 = std::max(0, box[0]);
  kept.v0 = std::max(0, box[1]);
  kept.width = std::min(frame.width, box[2]) - kept.u0;
  kept.height = std::min(frame.height, box[3]) - kept.v0;
  const size_t size = static_cast<size_t>(kept.width) * kept.height;
  kept.depth_mm.assign(size, 0);
  const bool color = frame.rgb.size() == 3 * static_cast<size_t>(frame.width) * frame.height;
  if (color) kept.rgb.assign(3 * size, 0);
  for (int v = 0; v < kept.height; ++v) {
    for (int u = 0; u < kept.width; ++u) {
      const size_t pixel = static_cast<size_t>(kept.v0 + v) * frame.width + (kept.u0 + u);
      const std::uint16_t depth = frame.depth_mm[pixel];
      if (!mask[pixel] || depth == 0) continue;
      const size_t at = static_cast<size_t>(v) * kept.width + u;
      kept.depth_mm[at] = depth;
      if (color) std::copy_n(&frame.rgb[3 * pixel], 3, &kept.rgb[3 * at]);
      if (u % 2 == 0 && v % 2 == 0) {
        kept.points.push_back(
            intrinsics_.BackProject(kept.u0 + u, kept.v0 + v, depth).cast<float>());
      }
    }
  }
  return kept;
}

std::vector<KeyframeGraph::Loop> KeyframeGraph::KeypointLoops() {
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  const Rigid3& chain = keyframes_[newest].cam_from_object;
  std::vector<Loop> found;
  for (int earlier : KeypointCandidates()) {
    const std::optional<Rigid3> motion =
        RegisterByKeypoints(keyframes_[newest], keyframes_[earlier]);
    if (!motion) continue;
    const Rigid3 placed = motion->Inverse() * keyframes_[earlier].cam_from_object;
    // Within the drift the chain can have gathered since the earlier keyframe; past it, a view
    // matched to a copy of its pattern.
    const double gate = std::max(options_.feature_min_gate_deg,
                                 options_.feature_drift_share * Travelled(earlier, newest));
    const double correction = TurnDeg(placed, chain);
    if (correction > gate) {
      alias_deg_ = std::min(alias_deg_, correction);
      continue;
    }
    for (const Loop& other : found) {
      const double apart = TurnDeg(placed, other.placed);
      if (apart > options_.feature_distinct_deg) {
        alias_deg_ = std::min(alias_deg_, apart);
      }
    }
    found.push_back({{newest, earlier, *motion, 1.0}, placed, false, true});
  }
  // Half a period or more from the chain, a loop is as near a copy's view as its own: of
  // registrations that disagree, those nearest the chain are kept.
  std::erase_if(found, [&](const Loop& loop) {
    return TurnDeg(loop.placed, chain) >= options_.feature_alias_share * alias_deg_;
  });
  return found;
}

std::vector<int> KeyframeGraph::LoopCandidates() const {
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  std::vector<std::pair<double, int>> near;
  for (int earlier = 0; earlier + options_.loop_min_gap <= newest; ++earlier) {
    const double turn =
        TurnDeg(keyframes_[newest].cam_from_object, keyframes_[earlier].cam_from_object);
    if (turn <= options_.loop_max_turn_deg) near.emplace_back(turn, earlier);
  }
  std::sort(near.begin(), near.end());
  std::vector<int> candidates;
  for (size_t i = 0; i < near.size() && static_cast<int>(i) < options_.loop_tries; ++i)
    candidates.push_back(near[i].second);
  return candidates;
}

std::vector<int> KeyframeGraph::KeypointCandidates() const {
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  const Keyframe& now = keyframes_[newest];
  std::vector<std::pair<int, int>> matched;  // (-matches, keyframe)
  if (static_cast<int>(now.keypoints.size()) < options_.feature_min_inliers) return {};
  for (int earlier = 0; earlier + options_.loop_min_gap <= newest; ++earlier) {
    const Keyframe& then = keyframes_[earlier];
    if (static_cast<int>(then.keypoints.size()) < options_.feature_min_inliers ||
        TurnDeg(now.cam_from_object, then.cam_from_object) > options_.feature_max_turn_deg) {
      continue;
    }
    SiftOptions sift;
    const int matches = static_cast<int>(MatchKeypoints(now, then, sift.ratio).size());
    if (matches >= options_.feature_min_inliers) matched.emplace_back(-matches, earlier);
  }
  std::sort(matched.begin(), matched.end());
  std::vector<int> candidates;
  for (size_t i = 0; i < matched.size() && static_cast<int>(i) < options_.feature_tries; ++i)
    candidates.push_back(matched[i].second);
  return candidates;
}

std::optional<Rigid3> KeyframeGraph::RegisterByKeypoints(const Keyframe& from, const Keyframe& to) {
  const std::vector<PointMatch> pairs = MatchKeypoints(from, to, SiftOptions{}.ratio);
  PairwiseOptions ransac;
  ransac.min_visual_inliers = options_.feature_min_inliers;
  ransac.inlier_mm = options_.feature_inlier_mm;
  ransac.ransac_iterations = 500;
  int rival = 0;
  const std::vector<PointMatch> inliers =
      ConsistentPairs(pairs, ransac, options_.feature_distinct_deg, &rival);
  if (inliers.empty() || rival > options_.feature_max_rival * inliers.size()) return std::nullopt;
  std::vector<Eigen::Vector3d> a, b;
  for (const PointMatch& pair : inliers) a.push_back(pair.previous), b.push_back(pair.current);
  DrawTarget(to);
  int icp_inliers = 0;
  const std::optional<Rigid3> motion =
      Align(from, FitRigidTransform(a, b), &icp_inliers, /*free_allowed=*/true);
  if (!motion || !Plausible(*motion, from, to)) return std::nullopt;
  return motion;
}

double KeyframeGraph::Travelled(int from, int to) const {
  double travelled = 0;
  for (int k = from; k < to; ++k)
    travelled += TurnDeg(keyframes_[k].cam_from_object, keyframes_[k + 1].cam_from_object);
  return travelled;
}

bool KeyframeGraph::Plausible(const Rigid3& motion, const Keyframe& from,
                              const Keyframe& to) const {
  // Where the registration puts `from`'s object, against where the chain put it.
  const Rigid3 registered = motion.Inverse() * to.cam_from_object;
  return PoseDistanceMm(registered, from.cam_from_object, options_.graph.lever_mm) <=
         options_.max_correction_mm;
}

void KeyframeGraph::DrawTarget(const Keyframe& keyframe) {
  RaycastImage& image = scratch_;
  if (image.width != intrinsics_.width || image.height != intrinsics_.height) {
    image = RaycastImage{};
    image.width = intrinsics_.width;
    image.height = intrinsics_.height;
    image.depth_mm.assign(static_cast<size_t>(image.width) * image.height, 0.0f);
    image.normals.assign(image.depth_mm.size(), Eigen::Vector3f::Zero());
  }
  for (int v = image.written[1]; v < image.written[3]; ++v) {
    for (int u = image.written[0]; u < image.written[2]; ++u) {
      const size_t pixel = static_cast<size_t>(v) * image.width + u;
      image.depth_mm[pixel] = 0;
      image.normals[pixel].setZero();
    }
  }
  // Normals across two pixels each way, where the four neighbours lie on the same surface.
  constexpr int kStep = 2;
  constexpr int kMaxStepMm = 8;
  auto depth_at = [&](int u, int v) -> int {
    if (u < 0 || v < 0 || u >= keyframe.width || v >= keyframe.height) return 0;
    return keyframe.depth_mm[static_cast<size_t>(v) * keyframe.width + u];
  };
  for (int v = 0; v < keyframe.height; ++v) {
    for (int u = 0; u < keyframe.width; ++u) {
      const int depth = depth_at(u, v);
      if (depth == 0) continue;
      const int around[4] = {depth_at(u - kStep, v), depth_at(u + kStep, v), depth_at(u, v - kStep),
                             depth_at(u, v + kStep)};
      bool same_surface = true;
      for (int d : around) same_surface = same_surface && d > 0 && std::abs(d - depth) < kMaxStepMm;
      if (!same_surface) continue;
      const int x = keyframe.u0 + u, y = keyframe.v0 + v;
      const Eigen::Vector3d across = intrinsics_.BackProject(x + kStep, y, around[1]) -
                                     intrinsics_.BackProject(x - kStep, y, around[0]);
      const Eigen::Vector3d down = intrinsics_.BackProject(x, y + kStep, around[3]) -
                                   intrinsics_.BackProject(x, y - kStep, around[2]);
      Eigen::Vector3d normal = across.cross(down);
      if (normal.squaredNorm() == 0) continue;
      normal.normalize();
      const Eigen::Vector3d point = intrinsics_.BackProject(x, y, depth);
      if (normal.dot(point) > 0) normal = -normal;
      const size_t pixel = static_cast<size_t>(y) * image.width + x;
      image.depth_mm[pixel] = static_cast<float>(depth);
      image.normals[pixel] = normal.cast<float>();
    }
  }
  image.written = {keyframe.u0, keyframe.v0, keyframe.u0 + keyframe.width,
                   keyframe.v0 + keyframe.height};
}

std::optional<Rigid3> KeyframeGraph::Register(const Keyframe& from, const Keyframe& to) {
  if (from.points.empty() || to.points.empty()) return std::nullopt;
  DrawTarget(to);
  // From where the chain puts `from`, and from there shifted so that the two views' points
  // share their centroid (a slide's drift is more than ICP's pairing reaches).
  const Rigid3 chained = to.cam_from_object * from.cam_from_object.Inverse();
  const Eigen::Vector3d shift = Centroid(to.points) - chained * Centroid(from.points);
  std::optional<Rigid3> best;
  int best_inliers = 0;
  for (const Rigid3& start : {chained, Rigid3::Translation(shift) * chained}) {
    int inliers = 0;
    std::optional<Rigid3> motion = Align(from, start, &inliers);
    if (motion && inliers > best_inliers) best = motion, best_inliers = inliers;
  }
  if (!best || !Plausible(*best, from, to)) return std::nullopt;
  return best;
}

std::optional<Rigid3> KeyframeGraph::Align(const Keyframe& from, const Rigid3& start, int* inliers,
                                           bool free_allowed) const {
  Rigid3 motion = start;
  IcpOptions options = icp_;
  IcpResult result;
  std::vector<Eigen::Vector3f> moved(from.points.size());
  for (int pass = 0; pass < 3; ++pass) {
    options.max_distance_mm = options_.icp_start_mm / (1 << pass);
    for (size_t i = 0; i < from.points.size(); ++i) moved[i] = motion * from.points[i];
    result = AlignToModel(moved, scratch_, intrinsics_, Rigid3(), options);
    if (!result.ok) return std::nullopt;
    motion = result.cam_from_volume.Inverse() * motion;
  }
  const double min_fraction =
      free_allowed ? options_.feature_min_inlier_fraction : options_.min_inlier_fraction;
  if ((result.free_directions > 0 && !free_allowed) ||
      result.inliers < min_fraction * from.points.size() || result.rms_mm > options_.max_rms_mm) {
    return std::nullopt;
  }
  *inliers = result.inliers;
  return motion;
}

void KeyframeGraph::Solve(KeyframeUpdate* update) {
  std::vector<Rigid3> poses;
  for (const Keyframe& keyframe : keyframes_) poses.push_back(keyframe.cam_from_object);
  const std::vector<Rigid3> solved = SolvePoseGraph(poses, edges_, options_.graph, spin_axis_);
  for (size_t i = 0; i < poses.size(); ++i) {
    update->correction_mm = std::max(update->correction_mm,
                                     PoseDistanceMm(poses[i], solved[i], options_.graph.lever_mm));
  }
  if (update->correction_mm < options_.refuse_min_mm) return;
  update->corrected = true;
  // Loops waiting for a second were placed against the poses that now moved.
  pending_.clear();
  for (size_t i = 0; i < poses.size(); ++i) {
    update->corrections.push_back(poses[i].Inverse() * solved[i]);
    keyframes_[i].cam_from_object = solved[i];
  }
}

}  // namespace ihs::fusion
