#include "fusion/keyframe_graph.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "core/check.h"

namespace ihs::fusion {
namespace {

// The angle between two poses' views of the object, degrees.
double TurnDeg(const Rigid3& a, const Rigid3& b) { return a.RotationAngleToRad(b) * 180.0 / M_PI; }

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
                                      int stamp, double kept_pairs) {
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
  keyframes_.push_back(Keep(frame, mask, box, cam_from_object, stamp));
  update.added = true;
  if (keyframes_.size() == 1) return update;
  AddChainEdge();
  update.loops = AddConfirmedLoops();
  if (update.loops > 0) Solve(&update);
  return update;
}

void KeyframeGraph::AddChainEdge() {
  // The tracked motion from the previous keyframe, trusted less where a frame in between
  // may have slid.
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  const double trust =
      std::clamp((chain_kept_ - 0.5) / (options_.chain_trusted_kept - 0.5), 0.1, 1.0);
  chain_kept_ = 1.0;
  edges_.push_back(
      {newest - 1, newest,
       keyframes_[newest].cam_from_object * keyframes_[newest - 1].cam_from_object.Inverse(),
       std::pow(trust, 4)});
}

int KeyframeGraph::AddConfirmedLoops() {
  // Loops with the earlier keyframes. One counts only where another agrees with it — of this
  // keyframe or of one of the last `loop_pending_keyframes`, carried along the chain — on
  // where this keyframe's object is, within `loop_agreement_mm`: a view that registers where
  // it is not (a cube's faces are alike) rarely does so twice alike.
  const int newest = static_cast<int>(keyframes_.size()) - 1;
  std::vector<Loop> found;
  for (int earlier : LoopCandidates()) {
    if (std::optional<Rigid3> motion = Register(keyframes_[newest], keyframes_[earlier])) {
      found.push_back({{newest, earlier, *motion, 1.0},
                       motion->Inverse() * keyframes_[earlier].cam_from_object});
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
  std::vector<Loop> still_pending;
  for (const Loop* loop : all) {
    if (loop->confirmed) {
      edges_.push_back(loop->edge);
      ++added;
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
  if (!best) return std::nullopt;
  // Where the registration puts `from`'s object, against where the chain put it.
  const Rigid3 registered = best->Inverse() * to.cam_from_object;
  if (PoseDistanceMm(registered, from.cam_from_object, options_.graph.lever_mm) >
      options_.max_correction_mm) {
    return std::nullopt;
  }
  return best;
}

std::optional<Rigid3> KeyframeGraph::Align(const Keyframe& from, const Rigid3& start,
                                           int* inliers) const {
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
  if (result.free_directions > 0 ||
      result.inliers < options_.min_inlier_fraction * from.points.size() ||
      result.rms_mm > options_.max_rms_mm) {
    return std::nullopt;
  }
  *inliers = result.inliers;
  return motion;
}

void KeyframeGraph::Solve(KeyframeUpdate* update) {
  std::vector<Rigid3> poses;
  for (const Keyframe& keyframe : keyframes_) poses.push_back(keyframe.cam_from_object);
  const std::vector<Rigid3> solved = SolvePoseGraph(poses, edges_, options_.graph);
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
