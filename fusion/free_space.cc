#include "fusion/free_space.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "fusion/triangle_cover.h"

namespace ihs::fusion {
namespace {

constexpr int kMaxMinViews = 8;

// The crop's depth with pixels without depth that have none within `radius` either (in the
// crop) marked as rays that met nothing.
void MarkNothing(int radius, DepthView* view) {
  const int w = view->width, h = view->height;
  std::vector<std::uint8_t> row_valid(view->depth_mm.size(), 0);
  for (int v = 0; v < h; ++v) {
    // The last column with depth up to u: the centre u − radius has depth within the radius
    // when it is at most 2·radius behind.
    int last_valid = -2 * radius - 1;
    for (int u = 0; u < w + radius; ++u) {
      if (u < w && view->depth_mm[v * w + u] != 0) last_valid = u;
      const int centre = u - radius;
      if (centre >= 0) row_valid[v * w + centre] = u - last_valid <= 2 * radius ? 1 : 0;
    }
  }
  for (int u = 0; u < w; ++u) {
    int last_valid = -2 * radius - 1;
    for (int v = 0; v < h + radius; ++v) {
      if (v < h && row_valid[v * w + u]) last_valid = v;
      const int centre = v - radius;
      if (centre < 0) continue;
      std::uint16_t& depth = view->depth_mm[centre * w + u];
      if (depth == 0 && v - last_valid > 2 * radius) depth = DepthView::kNothing;
    }
  }
}

// Where each pixel's ray of `view` runs inside the closed mesh `hand` (camera frame): every
// face that covers a pixel's centre is an entry (facing the camera) or an exit, and each entry
// is paired with the exit after it.
void AddHandSpans(const TriangleMesh& hand, const CameraIntrinsics& intrinsics, DepthView* view) {
  struct Hit {
    std::int32_t pixel;
    float z;
    bool entry;
  };
  std::vector<Hit> hits;
  for (const auto& face : hand.faces) {
    Eigen::Vector3d corner[3];
    Eigen::Vector2d q[3];
    bool in_front = true;
    for (int c = 0; c < 3 && in_front; ++c) {
      corner[c] = hand.vertices[face[c]].cast<double>();
      in_front = corner[c].z() > 1.0;
      if (in_front) q[c] = intrinsics.Project(corner[c]) - Eigen::Vector2d(view->u0, view->v0);
    }
    if (!in_front) continue;
    const Eigen::Vector3d normal = (corner[1] - corner[0]).cross(corner[2] - corner[0]);
    const double offset = normal.dot(corner[0]);
    if (offset == 0) continue;  // Edge-on.
    const bool entry = offset < 0;  // Its outside faces the camera.
    const double area = TwiceSignedArea(q);
    if (area == 0) continue;
    if (area < 0) std::swap(q[1], q[2]);
    const int u0 = std::max(0, static_cast<int>(std::ceil(std::min({q[0].x(), q[1].x(), q[2].x()}))));
    const int u1 = std::min(view->width - 1,
                            static_cast<int>(std::floor(std::max({q[0].x(), q[1].x(), q[2].x()}))));
    const int v0 = std::max(0, static_cast<int>(std::ceil(std::min({q[0].y(), q[1].y(), q[2].y()}))));
    const int v1 = std::min(view->height - 1,
                            static_cast<int>(std::floor(std::max({q[0].y(), q[1].y(), q[2].y()}))));
    for (int v = v0; v <= v1; ++v) {
      for (int u = u0; u <= u1; ++u) {
        double weights[3];
        if (!CoversPoint(q, Eigen::Vector2d(u, v), weights)) continue;
        // The face's plane along the pixel's ray.
        const Eigen::Vector3d ray((u + view->u0 - intrinsics.cx) / intrinsics.fx,
                                  (v + view->v0 - intrinsics.cy) / intrinsics.fy, 1.0);
        const double along = normal.dot(ray);
        if (along == 0) continue;
        hits.push_back({v * view->width + u, static_cast<float>(offset / along), entry});
      }
    }
  }
  std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) {
    return a.pixel != b.pixel ? a.pixel < b.pixel : a.z < b.z;
  });
  view->hand_row_start.assign(view->height + 1, 0);
  float near = 0;
  bool inside = false;
  for (size_t n = 0; n < hits.size(); ++n) {
    const Hit& hit = hits[n];
    if (n > 0 && hit.pixel != hits[n - 1].pixel) inside = false;  // An unclosed entry: dropped.
    if (hit.entry && !inside) {
      inside = true;
      near = hit.z;
    } else if (!hit.entry && inside) {
      inside = false;
      auto to_mm = [](float z) {
        return static_cast<std::uint16_t>(std::clamp(z, 0.0f, DepthView::kNothing - 1.0f));
      };
      view->hand_spans.push_back({static_cast<std::uint16_t>(hit.pixel % view->width),
                                  to_mm(near), to_mm(hit.z)});
      ++view->hand_row_start[hit.pixel / view->width + 1];
    }
  }
  for (int v = 0; v < view->height; ++v) view->hand_row_start[v + 1] += view->hand_row_start[v];
}

}  // namespace

float DepthView::DepthInsideHand(int u, int v, float z_mm) const {
  if (hand_row_start.empty()) return -1;
  float deepest = -1;
  const auto begin = hand_spans.begin() + hand_row_start[v];
  const auto end = hand_spans.begin() + hand_row_start[v + 1];
  auto span = std::lower_bound(begin, end, u, [](const HandSpan& s, int column) {
    return s.u < column;
  });
  for (; span != end && span->u == u; ++span) {
    deepest = std::max(deepest, std::min(z_mm - span->near_mm, span->far_mm - z_mm));
  }
  return deepest;
}

void FreeSpaceOptions::Check() const {
  IHS_CHECK_ARG(min_turn_deg >= 0 && min_turn_deg <= 90,
                "free_space.min_turn_deg must be in [0, 90], got " << min_turn_deg);
  IHS_CHECK_ARG(max_views >= 1 && max_views <= 10000,
                "free_space.max_views must be in [1, 10000], got " << max_views);
  IHS_CHECK_ARG(crop_margin >= 0 && crop_margin <= 4,
                "free_space.crop_margin must be in [0, 4], got " << crop_margin);
  IHS_CHECK_ARG(margin_mm >= 0 && margin_mm <= 100,
                "free_space.margin_mm must be in [0, 100], got " << margin_mm);
  IHS_CHECK_ARG(min_views >= 1 && min_views <= kMaxMinViews,
                "free_space.min_views must be in [1, " << kMaxMinViews << "], got " << min_views);
  IHS_CHECK_ARG(no_depth_radius_px >= 0 && no_depth_radius_px <= 32,
                "free_space.no_depth_radius_px must be in [0, 32], got " << no_depth_radius_px);
}

FreeSpace::FreeSpace(const CameraIntrinsics& intrinsics, FreeSpaceOptions options)
    : intrinsics_(intrinsics), options_(options) {
  options_.Check();
}

bool FreeSpace::Observe(const Frame& frame, const std::array<int, 4>& object_box,
                        const Rigid3& cam_from_object, const TriangleMesh* hand, int stamp) {
  if (!options_.enabled || views() >= options_.max_views) return false;
  if (object_box[2] <= object_box[0] || object_box[3] <= object_box[1]) return false;
  // Turned far enough from every kept view: the relative rotation's angle θ has
  // trace = 1 + 2 cos θ.
  const double min_trace = 1 + 2 * std::cos(options_.min_turn_deg * M_PI / 180.0);
  for (const auto& kept : views_) {
    const double trace =
        (cam_from_object.rotation() * kept->cam_from_object.rotation().transpose()).trace();
    if (trace > min_trace) return false;
  }
  auto view = std::make_shared<DepthView>();
  view->stamp = stamp;
  view->cam_from_object = cam_from_object;
  view->rotation = cam_from_object.rotation().cast<float>();
  view->translation = cam_from_object.translation().cast<float>();
  const int grow_u = static_cast<int>(options_.crop_margin * (object_box[2] - object_box[0]));
  const int grow_v = static_cast<int>(options_.crop_margin * (object_box[3] - object_box[1]));
  view->u0 = std::max(0, object_box[0] - grow_u);
  view->v0 = std::max(0, object_box[1] - grow_v);
  view->width = std::min(frame.width, object_box[2] + grow_u) - view->u0;
  view->height = std::min(frame.height, object_box[3] + grow_v) - view->v0;
  view->depth_mm.resize(static_cast<size_t>(view->width) * view->height);
  for (int v = 0; v < view->height; ++v) {
    const std::uint16_t* row = &frame.depth_mm[(view->v0 + v) * frame.width + view->u0];
    std::copy_n(row, view->width, &view->depth_mm[static_cast<size_t>(v) * view->width]);
    // Depth this far is beyond any sensor: a stored value never reads as kNothing.
    for (int u = 0; u < view->width; ++u) {
      std::uint16_t& d = view->depth_mm[static_cast<size_t>(v) * view->width + u];
      d = std::min<std::uint16_t>(d, DepthView::kNothing - 1);
    }
  }
  if (options_.no_depth_is_empty) MarkNothing(options_.no_depth_radius_px, view.get());
  if (hand != nullptr) AddHandSpans(*hand, intrinsics_, view.get());
  views_.push_back(std::move(view));
  return true;
}

void FreeSpace::Repose(const std::function<Rigid3(int stamp)>& correction) {
  for (auto& view : views_) {
    auto moved = std::make_shared<DepthView>(*view);
    moved->cam_from_object = view->cam_from_object * correction(view->stamp);
    moved->rotation = moved->cam_from_object.rotation().cast<float>();
    moved->translation = moved->cam_from_object.translation().cast<float>();
    view = std::move(moved);
  }
}

// The votes of the views on one point so far.
struct FreeSpace::Tally {
  // The k largest signed distances in front of the measured depth (or inside the hand),
  // descending.
  float top[kMaxMinViews];
  int kept = 0;
  EmptinessVotes votes;
};

void FreeSpace::Vote(const DepthView& view, const Eigen::Vector3f& point, float limit,
                     Tally* tally) const {
  const Eigen::Vector3f p = view.rotation * point + view.translation;
  if (p.z() <= 1.0f) return;
  // Rounded to the nearest pixel (std::lround is a library call; this runs millions of times).
  const float column = static_cast<float>(intrinsics_.fx) * p.x() / p.z() +
                       static_cast<float>(intrinsics_.cx) - view.u0 + 0.5f;
  const float row = static_cast<float>(intrinsics_.fy) * p.y() / p.z() +
                    static_cast<float>(intrinsics_.cy) - view.v0 + 0.5f;
  if (!(column >= 0 && row >= 0 && column < view.width && row < view.height)) return;
  const int u = static_cast<int>(column), v = static_cast<int>(row);
  const float margin = static_cast<float>(options_.margin_mm);
  const std::uint16_t depth = view.depth_mm[static_cast<size_t>(v) * view.width + u];
  float in_front =
      depth == DepthView::kNothing ? limit : static_cast<float>(depth) - p.z() - margin;
  const float inside_hand = view.DepthInsideHand(u, v, p.z()) - margin;
  in_front = std::max(in_front, inside_hand);
  if (depth == 0 && in_front <= 0) return;  // No evidence either way.
  if (in_front > 0) {
    ++tally->votes.through;
    if (inside_hand > 0) ++tally->votes.in_hand;
  } else if (in_front >= -2 * margin) {
    ++tally->votes.at_surface;  // Within the margin of the measured depth, on either side.
  }
  // Insert into the descending top k.
  const int k = options_.min_views;
  int slot = std::min(tally->kept, k - 1);
  if (tally->kept < k) {
    ++tally->kept;
  } else if (in_front <= tally->top[slot]) {
    return;
  }
  while (slot > 0 && tally->top[slot - 1] < in_front) {
    tally->top[slot] = tally->top[slot - 1];
    --slot;
  }
  tally->top[slot] = in_front;
}

float FreeSpace::Result(const Tally& tally, float limit) const {
  const int k = options_.min_views;
  if (tally.kept < k || tally.votes.through <= tally.votes.at_surface) return -limit;
  return std::clamp(tally.top[k - 1], -limit, limit);
}

float FreeSpace::Emptiness(const Eigen::Vector3f& point, float limit,
                           EmptinessVotes* votes) const {
  Tally tally;
  for (const auto& view : views_) Vote(*view, point, limit, &tally);
  if (votes != nullptr) *votes = tally.votes;
  return Result(tally, limit);
}

std::vector<float> FreeSpace::Emptiness(const std::vector<Eigen::Vector3f>& points,
                                        float limit) const {
  std::vector<Tally> tallies(points.size());
  for (const auto& view : views_) {
    for (size_t n = 0; n < points.size(); ++n) Vote(*view, points[n], limit, &tallies[n]);
  }
  std::vector<float> emptiness(points.size());
  for (size_t n = 0; n < points.size(); ++n) emptiness[n] = Result(tallies[n], limit);
  return emptiness;
}

}  // namespace ihs::fusion
