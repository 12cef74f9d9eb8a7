#include "tracker/hand_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "core/check.h"
#include "core/levenberg_marquardt.h"
#include "core/point_kd_tree.h"
#include "core/rigid_fit.h"
#include "tracker/hand_fit_cost.h"

namespace ihs::tracker {
namespace {

constexpr double kCoverageMm = 10.0;
// Model vertices used for correspondences, at most (an even subsample).
constexpr size_t kModelSamples = 5000;
// Collision pairs are kept when their capsules are closer than this beyond touching, mm.
constexpr double kCollisionMarginMm = 5.0;
// A model point counts as hidden when the depth image sees something this much nearer, mm.
constexpr double kOccluderMm = 15.0;
// Collision capsules are thinner than the fingers: fingers that touch (as neighbours do) are not
// penalised, only fingers that pass into each other.
constexpr double kCapsuleShrink = 0.7;

// The centroids of `points` in the cubes of a grid of `cell_mm` fixed in their frame, in the
// cubes' order (so that a stride over them is even in space).
std::vector<Eigen::Vector3f> VoxelCentroids(const std::vector<Eigen::Vector3f>& points,
                                            double cell_mm) {
  struct Keyed {
    std::int64_t key;
    int index;
  };
  std::vector<Keyed> keyed(points.size());
  const float inverse = static_cast<float>(1.0 / cell_mm);
  for (size_t i = 0; i < points.size(); ++i) {
    // 21 bits per axis: cubes of a few mm cover ±(2^20 × cell) around the camera.
    const Eigen::Vector3f c = (points[i] * inverse).array().floor();
    auto bits = [](float v) { return static_cast<std::int64_t>(v + (1 << 20)) & 0x1FFFFF; };
    keyed[i] = {(bits(c.z()) << 42) | (bits(c.y()) << 21) | bits(c.x()), static_cast<int>(i)};
  }
  std::sort(keyed.begin(), keyed.end(),
            [](const Keyed& a, const Keyed& b) { return a.key < b.key; });
  std::vector<Eigen::Vector3f> centroids;
  for (size_t begin = 0; begin < keyed.size();) {
    size_t end = begin;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    for (; end < keyed.size() && keyed[end].key == keyed[begin].key; ++end)
      sum += points[keyed[end].index];
    centroids.push_back(sum / static_cast<float>(end - begin));
    begin = end;
  }
  return centroids;
}

// Every n-th of `points`, n chosen to keep at most about `at_most` of them (an even subsample).
std::vector<Eigen::Vector3f> EveryNth(const std::vector<Eigen::Vector3f>& points, size_t at_most) {
  const size_t stride = std::max<size_t>(1, points.size() / at_most);
  std::vector<Eigen::Vector3f> kept;
  for (size_t i = 0; i < points.size(); i += stride) kept.push_back(points[i]);
  return kept;
}

// Closest points of segments [p0, p1] and [q0, q1]: parameters s, t in [0, 1].
void ClosestPointsOfSegments(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                             const Eigen::Vector3d& q0, const Eigen::Vector3d& q1, double* s,
                             double* t) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double c = d1.dot(r), b = d1.dot(d2), denominator = a * e - b * b;
  *s = denominator > 1e-12 ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
  *t = e > 1e-12 ? (b * *s + f) / e : 0.0;
  if (*t < 0) {
    *t = 0;
    *s = a > 1e-12 ? std::clamp(-c / a, 0.0, 1.0) : 0.0;
  } else if (*t > 1) {
    *t = 1;
    *s = a > 1e-12 ? std::clamp((b - c) / a, 0.0, 1.0) : 0.0;
  }
}

// For each pixel of `roi` (x0, y0, x1, y1; exclusive ends) of a width-wide mask, the index of an
// (approximately) nearest set pixel, or −1: nearest sites propagated in two raster passes.
std::vector<int> NearestSetPixels(const std::vector<std::uint8_t>& mask, int width,
                                  const std::array<int, 4>& roi) {
  const auto [x0, y0, x1, y1] = roi;
  const int w = x1 - x0, h = y1 - y0;
  // Per ROI pixel: its current site's ROI coordinates (−1: none yet) and squared distance.
  struct Site {
    int x = -1, y = -1, d2 = std::numeric_limits<int>::max();
  };
  std::vector<Site> sites(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = &mask[static_cast<size_t>(y + y0) * width + x0];
    for (int x = 0; x < w; ++x) {
      if (row[x]) sites[static_cast<size_t>(y) * w + x] = {x, y, 0};
    }
  }
  auto relax = [&](Site& here, int x, int y, const Site& from) {
    if (from.x < 0) return;
    const int dx = from.x - x, dy = from.y - y, d2 = dx * dx + dy * dy;
    if (d2 < here.d2) here = {from.x, from.y, d2};
  };
  for (int y = 0; y < h; ++y) {
    Site* row = &sites[static_cast<size_t>(y) * w];
    const Site* up = y > 0 ? row - w : nullptr;
    for (int x = 0; x < w; ++x) {
      if (x > 0) relax(row[x], x, y, row[x - 1]);
      if (up) {
        if (x > 0) relax(row[x], x, y, up[x - 1]);
        relax(row[x], x, y, up[x]);
        if (x + 1 < w) relax(row[x], x, y, up[x + 1]);
      }
    }
  }
  for (int y = h - 1; y >= 0; --y) {
    Site* row = &sites[static_cast<size_t>(y) * w];
    const Site* down = y + 1 < h ? row + w : nullptr;
    for (int x = w - 1; x >= 0; --x) {
      if (x + 1 < w) relax(row[x], x, y, row[x + 1]);
      if (down) {
        if (x + 1 < w) relax(row[x], x, y, down[x + 1]);
        relax(row[x], x, y, down[x]);
        if (x > 0) relax(row[x], x, y, down[x - 1]);
      }
    }
  }
  std::vector<int> site(sites.size(), -1);
  for (size_t i = 0; i < sites.size(); ++i) {
    if (sites[i].x >= 0) site[i] = (sites[i].y + y0) * width + sites[i].x + x0;
  }
  return site;
}

}  // namespace

void HandFitOptions::Check() const {
  IHS_CHECK_ARG(collision_weight >= 0, "hand_fit.collision_weight must be >= 0");
  IHS_CHECK_ARG(outer_iterations >= 1 && outer_iterations <= 100 && inner_iterations >= 1 &&
                    inner_iterations <= 100,
                "hand_fit.outer_iterations and inner_iterations must be in [1, 100]");
  IHS_CHECK_ARG(inner_function_tolerance > 0 && inner_function_tolerance < 1,
                "hand_fit.inner_function_tolerance must be in (0, 1)");
  IHS_CHECK_ARG(max_data_points >= 10 && max_data_points <= 100000 && max_model_points >= 10 &&
                    max_model_points <= 100000,
                "hand_fit.max_data_points and max_model_points must be in [10, 100000]");
  IHS_CHECK_ARG(max_correspondence_mm > 0 && robust_scale_mm > 0,
                "hand_fit.max_correspondence_mm and robust_scale_mm must be positive");
  IHS_CHECK_ARG(limit_weight >= 0 && prior_weight >= 0,
                "hand_fit.limit_weight and prior_weight must be >= 0");
  IHS_CHECK_ARG(data_voxel_mm >= 0, "hand_fit.data_voxel_mm must be >= 0");
  IHS_CHECK_ARG(unlabelled_match_mm >= 0, "hand_fit.unlabelled_match_mm must be >= 0");
  IHS_CHECK_ARG(initial_trust_radius > 0, "hand_fit.initial_trust_radius must be positive");
  IHS_CHECK_ARG(data_point_weight >= 0, "hand_fit.data_point_weight must be >= 0");
  IHS_CHECK_ARG(silhouette_weight >= 0 && silhouette_tolerance_px >= 0,
                "hand_fit.silhouette_weight and silhouette_tolerance_px must be >= 0");
  IHS_CHECK_ARG(contact_surface_weight >= 0, "hand_fit.contact_surface_weight must be >= 0");
}

// Precomputed per model: sample vertices and collision capsules.
struct HandFitter::Data {
  std::vector<int> samples;      // Model vertices used for correspondences.
  std::vector<int> sample_bone;  // Dominant bone of each sample (for its normal).
  std::vector<Eigen::Vector3d> rest_normal_in_bone;  // Each sample's normal in that bone's frame.
  struct Capsule {
    int bone;
    int finger;
    double length;
    double radius;
  };
  std::vector<Capsule> capsules;
};

HandFitter::HandFitter(const HandModel& model, const CameraIntrinsics& intrinsics,
                       HandFitOptions options)
    : model_(model),
      intrinsics_(intrinsics),
      options_(std::move(options)),
      data_(std::make_unique<Data>()) {
  options_.Check();
  model_.Check();
  const size_t vertices = model.rest_mesh.vertices.size();
  const size_t stride = std::max<size_t>(1, vertices / kModelSamples);
  std::vector<int> dominant(vertices, 0);
  for (size_t v = 0; v < vertices; ++v) {
    float best = -1;
    for (const auto& [bone, weight] : model.weights[v].bones) {
      if (weight > best) best = weight, dominant[v] = bone;
    }
  }
  // Vertex normals of the rest mesh (loaded meshes may come without).
  TriangleMesh rest = model.rest_mesh;
  if (rest.normals.size() != vertices) rest.ComputeVertexNormals();
  for (size_t v = 0; v < vertices; v += stride) {
    data_->samples.push_back(static_cast<int>(v));
    data_->sample_bone.push_back(dominant[v]);
    const Eigen::Vector3d normal = rest.normals[v].cast<double>();
    data_->rest_normal_in_bone.push_back(
        model.model_from_bone_rest[dominant[v]].Inverse().RotateVector(normal));
  }
  // Capsules on the phalanges and the thumb's metacarpal (the other metacarpals lie in the palm):
  // radius = median distance of the bone's own vertices from its axis.
  for (int b = 1; b < static_cast<int>(model.bones.size()); ++b) {
    const int finger = model.FingerOf(b);
    const std::string& name = model.bones[b].name;
    const bool metacarpal = name.size() >= 4 && name.substr(name.size() - 4) == "Hand";
    if (finger < 0 || (metacarpal && finger != 4)) continue;
    const double length = model.bones[b].length_mm;
    const Rigid3 bone_from_model = model.model_from_bone_rest[b].Inverse();
    std::vector<double> distances;
    for (size_t v = 0; v < vertices; ++v) {
      if (dominant[v] != b) continue;
      const Eigen::Vector3d p =
          bone_from_model * Eigen::Vector3d(model.rest_mesh.vertices[v].cast<double>());
      const double s = std::clamp(p.x(), 0.0, length);
      distances.push_back((p - Eigen::Vector3d(s, 0, 0)).norm());
    }
    if (distances.empty()) continue;
    std::nth_element(distances.begin(), distances.begin() + distances.size() / 2, distances.end());
    data_->capsules.push_back(
        {b, finger, length, kCapsuleShrink * distances[distances.size() / 2]});
  }
}

HandFitter::~HandFitter() = default;

// The state of one Fit call: the data fitted to, the pose being fitted, the model's samples
// posed at it and the silhouette around its image; one method per step of the fit.
class HandFitter::FitState {
 public:
  FitState(const HandFitter& fitter, const std::vector<Eigen::Vector3f>& hand_points,
           const Frame* frame, const HandPose& initial, const Segmentation* segmentation,
           const std::vector<SurfaceContact>& contacts);

  /// One correspondence update (`first`: the fit's first): pairs the model at the current pose
  /// with the data and solves the inner problem from there. False, with the pose left as it
  /// was, when there is no pair to fit.
  bool Iterate(bool first);
  /// The current pose and how well it explains the data, and the data the model.
  HandFitResult Result();

 private:
  void PoseSamples();
  std::vector<int> FindVisible() const;
  bool OutsideCrop(const Eigen::Vector3d& p) const;
  double HuberWeight(double distance) const;
  PointKdTree FacingTree() const;
  std::vector<PointPair> ModelToDataPairs(const std::vector<int>& visible_samples) const;
  double NearestUnlabelled(const Eigen::Vector3f& point, Eigen::Vector3d* out) const;
  std::vector<PlanePair> DataToModelPairs() const;
  std::vector<PlanePair> ContactPairs() const;
  void WeighPairs(std::vector<PointPair>* model_pairs, std::vector<PlanePair>* data_pairs) const;
  std::vector<CollisionPair> CloseCollisions() const;
  void PrepareSilhouette();
  std::array<int, 4> ModelImageRoi() const;
  void AddUnlabelledToSilhouette();
  std::vector<SilhouettePair> SilhouettePairs() const;
  void Solve(HandFitTerms terms);

  const HandModel& model_;
  const CameraIntrinsics& intrinsics_;
  const HandFitOptions& options_;
  const Data& precomputed_;  // The fitter's samples and capsules.
  const Frame* const frame_;
  const Segmentation* const segmentation_;
  const std::vector<SurfaceContact>& contacts_;

  // Data: an even subsample for data → model (of the cubes' centroids, or of the points), a
  // denser one for the tree. How well the pose explains the data is measured on the points
  // themselves (every n-th), a share of the hand's pixels whichever data the fit used.
  const std::vector<Eigen::Vector3f> measured_;
  const std::vector<Eigen::Vector3f> data_;
  const PointKdTree data_tree_;

  PoseDerivatives kinematics_;
  const std::vector<double> prior_;
  HandPose pose_;
  const int samples_;
  std::vector<Eigen::Vector3f> posed_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<int> facing_;  // Samples facing the camera.

  // The silhouette (hand and object pixels) and, around the model's image, each pixel's
  // nearest silhouette pixel.
  const bool use_silhouette_;
  std::vector<std::uint8_t> silhouette_;
  std::vector<int> nearest_silhouette_;
  std::array<int, 4> roi_ = {0, 0, 0, 0};
};

HandFitter::FitState::FitState(const HandFitter& fitter,
                               const std::vector<Eigen::Vector3f>& hand_points, const Frame* frame,
                               const HandPose& initial, const Segmentation* segmentation,
                               const std::vector<SurfaceContact>& contacts)
    : model_(fitter.model_),
      intrinsics_(fitter.intrinsics_),
      options_(fitter.options_),
      precomputed_(*fitter.data_),
      frame_(frame),
      segmentation_(segmentation),
      contacts_(contacts),
      measured_(EveryNth(hand_points, static_cast<size_t>(options_.max_data_points))),
      data_(options_.data_voxel_mm > 0
                ? EveryNth(VoxelCentroids(hand_points, options_.data_voxel_mm),
                           static_cast<size_t>(options_.max_data_points))
                : measured_),
      data_tree_(EveryNth(hand_points, 4000)),
      kinematics_(model_),
      prior_(initial.angles_rad),
      pose_(initial),
      samples_(static_cast<int>(precomputed_.samples.size())),
      posed_(samples_),
      normals_(samples_),
      use_silhouette_(segmentation != nullptr && options_.silhouette_weight > 0 &&
                      segmentation->width > 0 &&
                      segmentation->hand_mask.size() == segmentation->object_mask.size()) {}

bool HandFitter::FitState::Iterate(bool first) {
  PoseSamples();
  if (first && use_silhouette_) PrepareSilhouette();
  const std::vector<int> visible_samples = FindVisible();
  std::vector<PointPair> model_pairs = ModelToDataPairs(visible_samples);
  std::vector<PlanePair> data_pairs = DataToModelPairs();
  if (model_pairs.empty() && data_pairs.empty()) return false;
  WeighPairs(&model_pairs, &data_pairs);
  const std::vector<PlanePair> contact_pairs = ContactPairs();
  data_pairs.insert(data_pairs.end(), contact_pairs.begin(), contact_pairs.end());
  Solve({std::move(model_pairs), std::move(data_pairs), SilhouettePairs(), CloseCollisions()});
  return true;
}

// Poses the samples at the current pose: their points, normals and which face the camera.
void HandFitter::FitState::PoseSamples() {
  const PoseParameters parameters(pose_);
  kinematics_.Evaluate(parameters.reference_rotation(), parameters.values().data());
  const auto& cam_from_bone = kinematics_.cam_from_bone();
  facing_.clear();
  for (int i = 0; i < samples_; ++i) {
    const int v = precomputed_.samples[i];
    const int bone = precomputed_.sample_bone[i];
    posed_[i] = kinematics_.SkinnedPoint(model_.weights[v], model_.rest_mesh.vertices[v], nullptr)
                    .cast<float>();
    normals_[i] = cam_from_bone[bone].RotateVector(precomputed_.rest_normal_in_bone[i]);
    if (normals_[i].dot(posed_[i].cast<double>()) < 0) facing_.push_back(i);
  }
}

// Visible samples: facing the camera, in front in a coarse depth buffer of the model (8 px
// cells), and — with a depth image — not hidden behind something nearer (the object).
std::vector<int> HandFitter::FitState::FindVisible() const {
  const int cw = (intrinsics_.width + 7) / 8, ch = (intrinsics_.height + 7) / 8;
  std::vector<float> nearest(static_cast<size_t>(cw) * ch, std::numeric_limits<float>::infinity());
  std::vector<int> cell(samples_, -1);
  std::vector<Eigen::Vector2d> pixel(samples_);
  for (int i : facing_) {
    const Eigen::Vector3d p = posed_[i].cast<double>();
    if (p.z() <= 1) continue;
    pixel[i] = intrinsics_.Project(p);
    const int cu = static_cast<int>(std::floor(pixel[i].x() / 8));
    const int cv = static_cast<int>(std::floor(pixel[i].y() / 8));
    if (cu < 0 || cv < 0 || cu >= cw || cv >= ch) continue;
    cell[i] = cv * cw + cu;
    nearest[cell[i]] = std::min(nearest[cell[i]], posed_[i].z());
  }
  std::vector<int> out;
  for (int i : facing_) {
    if (cell[i] < 0 || posed_[i].z() > nearest[cell[i]] + 8.0f) continue;
    if (OutsideCrop(posed_[i].cast<double>())) continue;
    if (frame_) {
      const int u = static_cast<int>(std::lround(pixel[i].x()));
      const int v = static_cast<int>(std::lround(pixel[i].y()));
      // Outside the image, or behind something nearer: hidden. Where the image has no depth
      // (background) the point stays: the model must not leave the hand's silhouette.
      if (u < 0 || v < 0 || u >= frame_->width || v >= frame_->height) continue;
      const std::uint16_t z = frame_->depth_mm[static_cast<size_t>(v) * frame_->width + u];
      if (z != 0 && z < posed_[i].z() - kOccluderMm) continue;
    }
    out.push_back(i);
  }
  return out;
}

// Whether `p` lies outside the crop volume (HandFitOptions::crop_min_mm, crop_max_mm).
bool HandFitter::FitState::OutsideCrop(const Eigen::Vector3d& p) const {
  return (p.array() < options_.crop_min_mm.array()).any() ||
         (p.array() > options_.crop_max_mm.array()).any();
}

// The weight of a pair `distance` apart: 1 up to robust_scale_mm, Huber's beyond.
double HandFitter::FitState::HuberWeight(double distance) const {
  return distance <= options_.robust_scale_mm ? 1.0
                                              : std::sqrt(options_.robust_scale_mm / distance);
}

// A k-d tree of the posed samples facing the camera (its indices index facing_).
PointKdTree HandFitter::FitState::FacingTree() const {
  std::vector<Eigen::Vector3f> facing_points;
  for (int i : facing_) facing_points.push_back(posed_[i]);
  return PointKdTree(std::move(facing_points));
}

// Model → data: visible samples to their nearest data point.
std::vector<PointPair> HandFitter::FitState::ModelToDataPairs(
    const std::vector<int>& visible_samples) const {
  const size_t model_stride =
      std::max<size_t>(1, visible_samples.size() / static_cast<size_t>(options_.max_model_points));
  std::vector<PointPair> model_pairs;
  for (size_t k = 0; k < visible_samples.size(); k += model_stride) {
    const int i = visible_samples[k];
    float d2 = 0;
    const int j = data_tree_.Nearest(posed_[i], &d2);
    const double d = j >= 0 ? std::sqrt(d2) : std::numeric_limits<double>::infinity();
    // A nearer surface that the segmentation left out instead (HandFitOptions).
    if (d > options_.unlabelled_match_mm) {
      Eigen::Vector3d unlabelled;
      const double du = NearestUnlabelled(posed_[i], &unlabelled);
      if (du < d) {
        model_pairs.push_back({precomputed_.samples[i], unlabelled, HuberWeight(du)});
        continue;
      }
    }
    if (d > options_.max_correspondence_mm) continue;
    model_pairs.push_back(
        {precomputed_.samples[i], data_tree_.points()[j].cast<double>(), HuberWeight(d)});
  }
  return model_pairs;
}

// The nearest point, within unlabelled_match_mm, of the depth pixels around a model point's
// image that neither mask holds (see HandFitOptions).
double HandFitter::FitState::NearestUnlabelled(const Eigen::Vector3f& point,
                                               Eigen::Vector3d* out) const {
  if (options_.unlabelled_match_mm <= 0 || frame_ == nullptr || segmentation_ == nullptr ||
      segmentation_->hand_mask.size() != frame_->depth_mm.size() ||
      segmentation_->object_mask.size() != frame_->depth_mm.size()) {
    return std::numeric_limits<double>::infinity();
  }
  constexpr int kRadiusPx = 2;
  const Eigen::Vector3d p = point.cast<double>();
  const Eigen::Vector2d pixel = intrinsics_.Project(p);
  const int u0 = static_cast<int>(std::lround(pixel.x()));
  const int v0 = static_cast<int>(std::lround(pixel.y()));
  double best = options_.unlabelled_match_mm;
  bool found = false;
  for (int v = std::max(0, v0 - kRadiusPx); v <= std::min(frame_->height - 1, v0 + kRadiusPx);
       ++v) {
    for (int u = std::max(0, u0 - kRadiusPx); u <= std::min(frame_->width - 1, u0 + kRadiusPx);
         ++u) {
      const size_t at = static_cast<size_t>(v) * frame_->width + u;
      const std::uint16_t z = frame_->depth_mm[at];
      if (z == 0 || segmentation_->hand_mask[at] != 0 || segmentation_->object_mask[at] != 0) {
        continue;
      }
      const Eigen::Vector3d q = intrinsics_.BackProject(u, v, z);
      const double d = (q - p).norm();
      if (d < best) {
        best = d;
        *out = q;
        found = true;
      }
    }
  }
  return found ? best : std::numeric_limits<double>::infinity();
}

// Data → model: data points to the tangent plane of their nearest sample facing the camera.
std::vector<PlanePair> HandFitter::FitState::DataToModelPairs() const {
  const PointKdTree model_tree = FacingTree();
  std::vector<PlanePair> data_pairs;
  for (const Eigen::Vector3f& point : data_) {
    float d2 = 0;
    const int k = model_tree.Nearest(point, &d2);
    const double d = std::sqrt(d2);
    if (k < 0 || d > options_.max_correspondence_mm) continue;
    const int i = facing_[k];
    data_pairs.push_back(
        {precomputed_.samples[i], point.cast<double>(), normals_[i], HuberWeight(d)});
  }
  return data_pairs;
}

// Fingertips held on the object: each one's vertices nearest its surface (at the current pose)
// to their nearest points there, point to plane, as a mean over them.
std::vector<PlanePair> HandFitter::FitState::ContactPairs() const {
  std::vector<PlanePair> pairs;
  if (options_.contact_surface_weight <= 0) return pairs;
  std::vector<std::pair<double, size_t>> by_depth;  // Signed distance outside, which vertex.
  std::vector<Eigen::Vector3d> posed;
  for (const SurfaceContact& contact : contacts_) {
    const LocalSurface& surface = contact.surface;
    by_depth.clear();
    posed.clear();
    for (int v : contact.vertices) {
      const Eigen::Vector3d p =
          kinematics_.SkinnedPoint(model_.weights[v], model_.rest_mesh.vertices[v], nullptr);
      by_depth.push_back({surface.NormalAt(p).dot(p - surface.Closest(p)), posed.size()});
      posed.push_back(p);
    }
    const size_t pulled = std::min(by_depth.size(), static_cast<size_t>(contact.pulled));
    std::partial_sort(by_depth.begin(), by_depth.begin() + pulled, by_depth.end());
    for (size_t k = 0; k < pulled; ++k) {
      const Eigen::Vector3d& p = posed[by_depth[k].second];
      pairs.push_back({contact.vertices[by_depth[k].second], surface.Closest(p),
                       surface.NormalAt(p), 1.0, 0.0});
    }
  }
  const double scale =
      pairs.empty() ? 0 : options_.contact_surface_weight / std::sqrt(double(pairs.size()));
  for (PlanePair& pair : pairs) pair.weight *= scale;
  return pairs;
}

// Weighs each direction's pairs as a mean over them, and gives the data → model pairs their
// point weight.
void HandFitter::FitState::WeighPairs(std::vector<PointPair>* model_pairs,
                                      std::vector<PlanePair>* data_pairs) const {
  // Each direction is a mean over its pairs.
  const double model_scale =
      model_pairs->empty() ? 0 : 1.0 / std::sqrt(double(model_pairs->size()));
  for (PointPair& pair : *model_pairs) pair.weight *= model_scale;
  const double data_scale = data_pairs->empty() ? 0 : 1.0 / std::sqrt(double(data_pairs->size()));
  for (PlanePair& pair : *data_pairs) pair.weight *= data_scale;
  // The data → model pairs also as points: a plane lets a finger slide along its axis.
  for (PlanePair& pair : *data_pairs) pair.point_weight = options_.data_point_weight * pair.weight;
}

// Collisions between capsules of different fingers that are close now.
std::vector<CollisionPair> HandFitter::FitState::CloseCollisions() const {
  const auto& cam_from_bone = kinematics_.cam_from_bone();
  const auto& capsules = precomputed_.capsules;
  std::vector<CollisionPair> collisions;
  for (size_t a = 0; a < capsules.size(); ++a) {
    for (size_t b = a + 1; b < capsules.size(); ++b) {
      const auto& ca = capsules[a];
      const auto& cb = capsules[b];
      if (ca.finger == cb.finger) continue;
      const Rigid3& ta = cam_from_bone[ca.bone];
      const Rigid3& tb = cam_from_bone[cb.bone];
      double s, t;
      ClosestPointsOfSegments(ta.translation(), ta * Eigen::Vector3d(ca.length, 0, 0),
                              tb.translation(), tb * Eigen::Vector3d(cb.length, 0, 0), &s, &t);
      const Eigen::Vector3d pa(s * ca.length, 0, 0), pb(t * cb.length, 0, 0);
      if ((ta * pa - tb * pb).norm() > ca.radius + cb.radius + kCollisionMarginMm) continue;
      collisions.push_back({ca.bone, pa, ca.radius, cb.bone, pb, cb.radius});
    }
  }
  return collisions;
}

// Once the samples are posed at the initial pose: the silhouette, the region around the
// model's image, and each of its pixels' nearest silhouette pixel.
void HandFitter::FitState::PrepareSilhouette() {
  // Only the region around the model's image is read (the nearest pixels are looked for there).
  roi_ = ModelImageRoi();
  silhouette_.assign(segmentation_->hand_mask.size(), 0);
  for (int v = roi_[1]; v < roi_[3]; ++v) {
    for (int u = roi_[0]; u < roi_[2]; ++u) {
      const size_t p = static_cast<size_t>(v) * segmentation_->width + u;
      silhouette_[p] = segmentation_->hand_mask[p] | segmentation_->object_mask[p];
    }
  }
  if (options_.unlabelled_match_mm > 0 && frame_ != nullptr &&
      frame_->depth_mm.size() == silhouette_.size()) {
    AddUnlabelledToSilhouette();
  }
  if (roi_[2] > roi_[0] && roi_[3] > roi_[1])
    nearest_silhouette_ = NearestSetPixels(silhouette_, segmentation_->width, roi_);
}

// The region around the posed samples' image (x0, y0, x1, y1; exclusive ends), clipped to the
// segmentation's image.
std::array<int, 4> HandFitter::FitState::ModelImageRoi() const {
  constexpr int kMarginPx = 40;
  std::array<int, 4> roi = {segmentation_->width, segmentation_->height, 0, 0};
  for (const Eigen::Vector3f& p : posed_) {
    if (p.z() <= 1) continue;
    const Eigen::Vector2d pixel = intrinsics_.Project(p.cast<double>());
    roi[0] = std::min(roi[0], static_cast<int>(pixel.x()) - kMarginPx);
    roi[1] = std::min(roi[1], static_cast<int>(pixel.y()) - kMarginPx);
    roi[2] = std::max(roi[2], static_cast<int>(pixel.x()) + kMarginPx);
    roi[3] = std::max(roi[3], static_cast<int>(pixel.y()) + kMarginPx);
  }
  return {std::max(0, roi[0]), std::max(0, roi[1]), std::min(segmentation_->width, roi[2]),
          std::min(segmentation_->height, roi[3])};
}

// With unlabelled_match_mm, what the segmentation left out (depth in the crop volume) is
// inside the silhouette too.
void HandFitter::FitState::AddUnlabelledToSilhouette() {
  for (int v = roi_[1]; v < roi_[3]; ++v) {
    for (int u = roi_[0]; u < roi_[2]; ++u) {
      const size_t at = static_cast<size_t>(v) * segmentation_->width + u;
      if (silhouette_[at] || frame_->depth_mm[at] == 0) continue;
      const Eigen::Vector3d x = intrinsics_.BackProject(u, v, frame_->depth_mm[at]);
      silhouette_[at] = (x.array() >= options_.crop_min_mm.array()).all() &&
                        (x.array() <= options_.crop_max_mm.array()).all();
    }
  }
}

// Silhouette pairs: model points (seen or not) in the crop volume whose image lies outside
// the silhouette, pulled to within the tolerance of its nearest pixel. The wrist's points are
// left out: where a scan of the forearm ends (sleeve, crop) says nothing about the hand.
std::vector<SilhouettePair> HandFitter::FitState::SilhouettePairs() const {
  std::vector<SilhouettePair> pairs;
  if (nearest_silhouette_.empty()) return pairs;
  int considered = 0;
  const int roi_width = roi_[2] - roi_[0];
  for (int i = 0; i < samples_; ++i) {
    if (precomputed_.sample_bone[i] == 0) continue;
    const Eigen::Vector3d p = posed_[i].cast<double>();
    if (p.z() <= 1 || OutsideCrop(p)) continue;
    ++considered;
    const Eigen::Vector2d pixel = intrinsics_.Project(p);
    const int u = static_cast<int>(std::lround(pixel.x()));
    const int v = static_cast<int>(std::lround(pixel.y()));
    if (u < roi_[0] || v < roi_[1] || u >= roi_[2] || v >= roi_[3]) continue;
    const int site = nearest_silhouette_[(v - roi_[1]) * roi_width + (u - roi_[0])];
    if (site < 0 || silhouette_[site] == 0) continue;
    const Eigen::Vector2d target(site % segmentation_->width, site / segmentation_->width);
    const double distance = (pixel - target).norm();
    if (distance <= options_.silhouette_tolerance_px) continue;
    const Eigen::Vector2d inside =
        target + options_.silhouette_tolerance_px * (pixel - target) / distance;
    pairs.push_back({precomputed_.samples[i], inside, p.z() / intrinsics_.fx});
  }
  const double scale =
      considered == 0 ? 0 : options_.silhouette_weight / std::sqrt(double(considered));
  for (SilhouettePair& pair : pairs) pair.weight *= scale;
  return pairs;
}

// Solves the inner problem with `terms` from the current pose, which it then replaces.
void HandFitter::FitState::Solve(HandFitTerms terms) {
  PoseParameters parameters(pose_);
  const HandFitCost cost(model_, parameters.reference_rotation(), intrinsics_, std::move(terms),
                         options_.collision_weight, options_.limit_weight, options_.prior_weight,
                         prior_);
  // A few hundred residual rows, ≈ 30 parameters, each row moved by a third of them or fewer:
  // the normal equations accumulated row by row over those (Ceres formed the dense Jacobian and
  // multiplied it out: most of the hand fit's time).
  LevenbergMarquardtOptions solver;
  solver.max_iterations = options_.inner_iterations;
  solver.function_tolerance = options_.inner_function_tolerance;
  // Correspondences hold only near the current pose: start with modest steps.
  solver.initial_radius = options_.initial_trust_radius;
  Eigen::VectorXd x = Eigen::Map<const Eigen::VectorXd>(
      parameters.values().data(), static_cast<Eigen::Index>(parameters.values().size()));
  MinimiseLevenbergMarquardt(
      [&](const Eigen::VectorXd& at, Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr) {
        return cost.NormalEquations(at.data(), jtj, jtr);
      },
      &x, solver);
  std::copy(x.data(), x.data() + x.size(), parameters.values().data());
  pose_ = parameters.ToPose();
}

HandFitResult HandFitter::FitState::Result() {
  // How well the final pose explains the data, and the data the model.
  PoseSamples();
  const std::vector<int> visible_samples = FindVisible();
  const PointKdTree model_tree = FacingTree();
  double sum = 0;
  int covered = 0;
  for (const Eigen::Vector3f& point : measured_) {
    float d2 = 0;
    if (model_tree.Nearest(point, &d2) < 0) d2 = 1e6f;
    sum += std::sqrt(d2);
    covered += std::sqrt(d2) <= kCoverageMm;
  }
  int visible_covered = 0;
  double model_sum = 0;
  for (int i : visible_samples) {
    float d2 = 0;
    data_tree_.Nearest(posed_[i], &d2);
    visible_covered += std::sqrt(d2) <= kCoverageMm;
    model_sum += std::sqrt(d2);
  }
  HandFitResult result;
  result.pose = pose_;
  result.data_points = static_cast<int>(data_.size());
  result.model_error_mm = visible_samples.empty() ? 0 : model_sum / visible_samples.size();
  result.data_error_mm = sum / measured_.size();
  result.data_coverage = static_cast<double>(covered) / measured_.size();
  result.model_coverage =
      visible_samples.empty() ? 0 : static_cast<double>(visible_covered) / visible_samples.size();
  return result;
}

HandFitResult HandFitter::Fit(const std::vector<Eigen::Vector3f>& hand_points, const Frame* frame,
                              const HandPose& initial, const Segmentation* segmentation,
                              const std::vector<SurfaceContact>& contacts) const {
  if (hand_points.empty()) {
    HandFitResult result;
    result.pose = initial;
    return result;
  }
  FitState state(*this, hand_points, frame, initial, segmentation, contacts);
  for (int outer = 0; outer < options_.outer_iterations; ++outer) {
    if (!state.Iterate(outer == 0)) break;
  }
  return state.Result();
}

namespace {

// Residuals: joint positions minus targets (3 per joint), soft limits, a weak pull to zero angles.
class JointCost : public ceres::CostFunction {
 public:
  JointCost(const HandModel& model, const Eigen::Matrix3d& reference,
            std::vector<Eigen::Vector3d> targets)
      : model_(model),
        reference_(reference),
        targets_(std::move(targets)),
        dofs_(JointDegreesOfFreedom(model)),
        derivatives_(model) {
    set_num_residuals(static_cast<int>(3 * targets_.size() + 2 * dofs_.size()));
    mutable_parameter_block_sizes()->push_back(derivatives_.size());
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* x = parameters[0];
    const int n = derivatives_.size();
    derivatives_.Evaluate(reference_, x);
    double* jacobian = jacobians ? jacobians[0] : nullptr;
    if (jacobian) std::fill(jacobian, jacobian + static_cast<size_t>(num_residuals()) * n, 0.0);
    std::vector<double> point_jacobian(3 * n);
    for (size_t j = 0; j < targets_.size(); ++j) {
      const int bone = j == 0 ? 0 : static_cast<int>(j) - 1;
      const Eigen::Vector3d local(j == 0 ? 0.0 : model_.bones[bone].length_mm, 0, 0);
      const Eigen::Vector3d p =
          derivatives_.BonePoint(bone, local, jacobian ? point_jacobian.data() : nullptr);
      for (int r = 0; r < 3; ++r) {
        residuals[3 * j + r] = p[r] - targets_[j][r];
        if (jacobian) {
          std::copy(point_jacobian.begin() + r * n, point_jacobian.begin() + (r + 1) * n,
                    jacobian + (3 * j + r) * n);
        }
      }
    }
    int row = static_cast<int>(3 * targets_.size());
    for (size_t k = 0; k < dofs_.size(); ++k) {
      const auto [lo_deg, hi_deg] = model_.limits[dofs_[k].bone].limits_deg[dofs_[k].axis];
      const double angle = x[6 + k], lo = lo_deg * M_PI / 180, hi = hi_deg * M_PI / 180;
      const double excess = angle > hi ? angle - hi : (angle < lo ? angle - lo : 0.0);
      residuals[row] = 30.0 * excess;
      if (jacobian && excess != 0) jacobian[row * n + 6 + k] = 30.0;
      ++row;
      residuals[row] = 0.5 * angle;
      if (jacobian) jacobian[row * n + 6 + k] = 0.5;
      ++row;
    }
    return true;
  }

 private:
  const HandModel& model_;
  const Eigen::Matrix3d reference_;
  const std::vector<Eigen::Vector3d> targets_;
  const std::vector<DegreeOfFreedom> dofs_;
  mutable PoseDerivatives derivatives_;
};

}  // namespace

HandPose FitPoseToJoints(const HandModel& model, const std::vector<Eigen::Vector3d>& joints_mm) {
  IHS_CHECK_ARG(
      joints_mm.size() == model.bones.size() + 1,
      "FitPoseToJoints needs " << model.bones.size() + 1 << " joints, got " << joints_mm.size());
  // Start: the rest pose placed by the best rigid fit of its joints to the targets.
  const HandPose rest = HandPose::Rest(model);
  const Rigid3 cam_from_model =
      FitRigidTransform(model.JointPositions(ForwardKinematics(model, rest)), joints_mm);
  HandPose start = HandPose::Rest(model, cam_from_model);

  HandPose pose = start;
  for (int round = 0; round < 3; ++round) {  // Re-centre ω between rounds.
    PoseParameters parameters(pose);
    ceres::Problem problem;
    problem.AddResidualBlock(new JointCost(model, parameters.reference_rotation(), joints_mm),
                             nullptr, parameters.values().data());
    ceres::Solver::Options solver;
    solver.linear_solver_type = ceres::DENSE_QR;
    solver.max_num_iterations = 50;
    solver.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver, &problem, &summary);
    pose = parameters.ToPose();
  }
  return pose;
}

}  // namespace ihs::tracker
