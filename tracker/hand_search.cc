#include "tracker/hand_search.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <queue>

#include "core/check.h"
#include "core/parallel_runs.h"
#include "core/point_kd_tree.h"
#include "core/rigid_fit.h"

namespace ihs::tracker {
namespace {

// A model point counts as hidden where the depth image sees something this much nearer, mm.
constexpr double kHiddenMm = 10.0;
// The share of the nearest pairs each placement iteration keeps, in each direction.
constexpr double kKeptShare = 0.8;

// Every `stride`-th of `points`, for at most `count` of them.
template <typename T>
std::vector<T> Thinned(const std::vector<T>& points, int count) {
  std::vector<T> out;
  const size_t stride = std::max<size_t>(1, points.size() / std::max(1, count));
  for (size_t i = 0; i < points.size(); i += stride) out.push_back(points[i]);
  return out;
}

// Rotations spread evenly: `directions` unit vectors on a Fibonacci sphere, each the image of
// the x axis, turned by `rolls` equal steps about itself.
std::vector<Eigen::Matrix3d> EvenRotations(int directions, int rolls) {
  std::vector<Eigen::Matrix3d> rotations;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < directions; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / directions;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const Eigen::Vector3d x(r * std::cos(golden * i), r * std::sin(golden * i), z);
    const Eigen::Vector3d helper =
        std::abs(x.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    Eigen::Matrix3d frame;
    frame.col(0) = x;
    frame.col(1) = helper.cross(x).normalized();
    frame.col(2) = x.cross(frame.col(1));
    for (int k = 0; k < rolls; ++k)
      rotations.push_back(Eigen::AngleAxisd(2 * M_PI * k / rolls, x).toRotationMatrix() * frame);
  }
  return rotations;
}

// Principal axes (columns, by decreasing spread, right-handed) and centroid of points.
void PrincipalAxes(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d* centroid,
                   Eigen::Matrix3d* axes) {
  *centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) *centroid += p;
  *centroid /= static_cast<double>(std::max<size_t>(1, points.size()));
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& p : points) covariance += (p - *centroid) * (p - *centroid).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigen sorts ascending; reverse to largest first.
  for (int k = 0; k < 3; ++k) axes->col(k) = solver.eigenvectors().col(2 - k);
  if (axes->determinant() < 0) axes->col(2) *= -1;
}

std::vector<Eigen::Vector3d> ToDouble(const std::vector<Eigen::Vector3f>& points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const Eigen::Vector3f& p : points) out.push_back(p.cast<double>());
  return out;
}

// One articulation's model points and the hand points, for placing and scoring rigid poses.
class Placement {
 public:
  Placement(const std::vector<Eigen::Vector3f>& model_vertices, const PointKdTree& data_tree,
            const std::vector<Eigen::Vector3d>& data_sample, const Frame& frame,
            const CameraIntrinsics& intrinsics, const HandSearchOptions& options)
      : model_tree_(Thinned(model_vertices, 6 * options.sample_points)),
        model_sample_(ToDouble(Thinned(model_vertices, 3 * options.sample_points))),
        data_tree_(data_tree),
        data_sample_(data_sample),
        frame_(frame),
        intrinsics_(intrinsics),
        options_(options) {}

  // `cam_from_model` moved by `iterations` of rigid ICP onto the hand points; its score in
  // `score` where given. Every `stride`-th point is used (a quick look: 3). A score that would
  // come out above `bound` may be given as infinity instead (Score).
  Rigid3 Place(Rigid3 cam_from_model, int iterations, int stride, double* score,
               double bound = std::numeric_limits<double>::infinity()) const {
    for (int iteration = 0; iteration < iterations; ++iteration) {
      std::vector<Eigen::Vector3d> from, to;
      Pairs(cam_from_model, stride, &from, &to);
      if (from.size() < 3) break;
      cam_from_model = FitRigidTransform(from, to);
    }
    if (score) *score = Score(cam_from_model, stride, bound);
    return cam_from_model;
  }

  // The mean capped distance of the data to the model and of the visible model to the data;
  // infinity as soon as the sums so far show that it exceeds `bound` (each mean is at least its
  // partial sum over all the points it may average).
  double Score(const Rigid3& cam_from_model, int stride, double bound) const {
    const double cap = options_.score_cap_mm;
    const float cap_sq = static_cast<float>(cap * cap);
    auto capped = [&](const PointKdTree& tree, const Eigen::Vector3d& p) {
      float d2 = 0;
      return tree.NearestWithin(p.cast<float>(), cap_sq, &d2) < 0
                 ? cap
                 : std::min(cap, std::sqrt(static_cast<double>(d2)));
    };
    const Rigid3 model_from_cam = cam_from_model.Inverse();
    const size_t data_count = (data_sample_.size() + stride - 1) / stride;
    const size_t model_count = (model_sample_.size() + stride - 1) / stride;
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    double data_sum = 0;
    int data = 0;
    for (size_t i = 0; i < data_sample_.size(); i += stride, ++data) {
      data_sum += capped(model_tree_, model_from_cam * data_sample_[i]);
      if (data_sum > bound * data_count) return kInfinity;
    }
    if (data == 0) return kInfinity;
    const double data_mean = data_sum / data;
    double model_sum = 0;
    int visible = 0;
    for (size_t i = 0; i < model_sample_.size(); i += stride) {
      const Eigen::Vector3d p = cam_from_model * model_sample_[i];
      if (Hidden(p)) continue;
      model_sum += capped(data_tree_, p);
      ++visible;
      if (data_mean + model_sum / model_count > bound) return kInfinity;
    }
    if (visible == 0) return kInfinity;
    return data_mean + model_sum / visible;
  }

 private:
  // Whether the depth image sees something nearer than camera-frame point `p`.
  bool Hidden(const Eigen::Vector3d& p) const {
    if (p.z() <= 1.0) return true;
    const Eigen::Vector2d uv = intrinsics_.Project(p);
    const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
    if (u < 0 || v < 0 || u >= frame_.width || v >= frame_.height) return false;
    const std::uint16_t depth = frame_.DepthAt(u, v);
    return depth > 0 && depth < p.z() - kHiddenMm;
  }

  // Nearest pairs both ways (model point, data point), the nearest share of each kept. A
  // query is first answered within the score's cap only: when the share kept is found within
  // it, the pairs beyond it are not kept whatever they are (and only otherwise looked for).
  void Pairs(const Rigid3& cam_from_model, int stride, std::vector<Eigen::Vector3d>* from,
             std::vector<Eigen::Vector3d>* to) const {
    struct Pair {
      float distance_sq;
      Eigen::Vector3d model, data;
    };
    const float cap_sq = static_cast<float>(options_.score_cap_mm * options_.score_cap_mm);
    constexpr float kBeyond = std::numeric_limits<float>::infinity();
    // Pairs `query`'s points (placed by `place`) with `tree`'s, `model_side`: whether the
    // queries are the model's points.
    auto pair_up = [&](const std::vector<Eigen::Vector3d>& queries, const PointKdTree& tree,
                       const auto& place, const auto& accept, bool model_side) {
      std::vector<Pair> pairs;
      std::vector<size_t> beyond;  // Indices into pairs of queries with nothing within the cap.
      for (size_t k = 0; k < queries.size(); k += stride) {
        const Eigen::Vector3d p = place(queries[k]);
        if (!accept(p)) continue;
        float d2 = 0;
        const int i = tree.NearestWithin(p.cast<float>(), cap_sq, &d2);
        const Eigen::Vector3d found = i < 0 ? p : tree.points()[i].cast<double>();
        if (i < 0) beyond.push_back(pairs.size()), d2 = kBeyond;
        pairs.push_back(model_side ? Pair{d2, queries[k], found} : Pair{d2, found, queries[k]});
      }
      const size_t kept = static_cast<size_t>(kKeptShare * pairs.size());
      if (kept == 0) return;
      if (pairs.size() - beyond.size() < kept) {
        for (size_t b : beyond) {
          Pair& pair = pairs[b];
          const Eigen::Vector3d p = place(model_side ? pair.model : pair.data);
          const int i = tree.Nearest(p.cast<float>(), &pair.distance_sq);
          (model_side ? pair.data : pair.model) = tree.points()[i].cast<double>();
        }
      }
      std::nth_element(pairs.begin(), pairs.begin() + (kept - 1), pairs.end(),
                       [](const Pair& a, const Pair& b) { return a.distance_sq < b.distance_sq; });
      for (size_t k = 0; k < kept; ++k)
        from->push_back(pairs[k].model), to->push_back(pairs[k].data);
    };
    const Rigid3 model_from_cam = cam_from_model.Inverse();
    pair_up(
        data_sample_, model_tree_, [&](const Eigen::Vector3d& p) { return model_from_cam * p; },
        [](const Eigen::Vector3d&) { return true; }, false);
    pair_up(
        model_sample_, data_tree_, [&](const Eigen::Vector3d& m) { return cam_from_model * m; },
        [&](const Eigen::Vector3d& p) { return !Hidden(p); }, true);
  }

  const PointKdTree model_tree_;
  const std::vector<Eigen::Vector3d> model_sample_;
  const PointKdTree& data_tree_;
  const std::vector<Eigen::Vector3d>& data_sample_;
  const Frame& frame_;
  const CameraIntrinsics& intrinsics_;
  const HandSearchOptions& options_;
};

}  // namespace

HandPose CurledHand(const HandModel& model, double fraction) {
  HandPose pose = HandPose::Rest(model);
  pose.cam_from_root = Rigid3();
  const std::vector<DegreeOfFreedom> dofs = JointDegreesOfFreedom(model);
  for (size_t k = 0; k < dofs.size(); ++k) {
    const double min_deg = model.limits[dofs[k].bone].limits_deg[dofs[k].axis].first;
    if (dofs[k].axis == 1 && model.bones[dofs[k].bone].parent >= 0 && min_deg < 0)
      pose.angles_rad[k] = fraction * min_deg * M_PI / 180.0;
  }
  return pose;
}

HandPose TurnedOver(const HandModel& model, const HandPose& pose) {
  const PalmAxes palm = PalmAxesOf(model, model.JointPositions(ForwardKinematics(model, pose)));
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(M_PI, palm.along.normalized()).toRotationMatrix();
  HandPose out = pose;
  out.cam_from_root = Rigid3(turn, palm.centre - turn * palm.centre) * pose.cam_from_root;
  return out;
}

std::vector<HandPose> ThumbVariants(const HandModel& model, const HandPose& pose) {
  const std::vector<DegreeOfFreedom> dofs = JointDegreesOfFreedom(model);
  // The thumb's first bone with active axes: its metacarpal.
  int bone = -1;
  for (const DegreeOfFreedom& dof : dofs) {
    if (model.FingerOf(dof.bone) == 4) {
      bone = dof.bone;
      break;
    }
  }
  std::vector<size_t> indices;
  for (size_t k = 0; k < dofs.size(); ++k)
    if (dofs[k].bone == bone) indices.push_back(k);
  std::vector<HandPose> variants;
  if (indices.empty()) return variants;
  size_t combinations = 1;
  for (size_t k = 0; k < indices.size(); ++k) combinations *= 3;
  for (size_t c = 0; c < combinations; ++c) {
    HandPose variant = pose;
    size_t code = c;
    for (size_t index : indices) {
      const auto [low, high] = model.limits[bone].limits_deg[dofs[index].axis];
      const double fraction = (1.0 + 2.0 * static_cast<double>(code % 3)) / 6.0;
      code /= 3;
      variant.angles_rad[index] = (low + fraction * (high - low)) * M_PI / 180.0;
    }
    variants.push_back(std::move(variant));
  }
  return variants;
}

std::vector<Rigid3> GraspStarts(const PalmAxes& palm, bool right_hand,
                                const Eigen::Vector3d& object, const Eigen::Vector3d& hand,
                                const HandSearchOptions& options) {
  std::vector<Rigid3> starts;
  const Eigen::Vector3d away = hand - object;
  if (away.norm() < 1e-6) return starts;
  const Eigen::Vector3d normal_model = ((right_hand ? 1.0 : -1.0) * palm.Normal()).normalized();
  const Eigen::Vector3d along_model =
      (palm.along - palm.along.dot(normal_model) * normal_model).normalized();
  Eigen::Matrix3d model_basis;
  model_basis << normal_model, along_model, normal_model.cross(along_model);
  const Eigen::Vector3d u = away.normalized();
  const Eigen::Vector3d side_a = u.unitOrthogonal(), side_b = u.cross(side_a);
  const double tilt = options.grasp_tilt_deg * M_PI / 180.0;
  std::vector<Eigen::Vector3d> directions = {u};
  for (const Eigen::Vector3d& axis :
       {side_a, Eigen::Vector3d(-side_a), side_b, Eigen::Vector3d(-side_b)})
    directions.push_back(Eigen::AngleAxisd(tilt, axis) * u);
  for (const Eigen::Vector3d& direction : directions) {
    const Eigen::Vector3d normal = -direction;  // The palm faces the object.
    const Eigen::Vector3d palm_centre = object + away.norm() * direction;
    const Eigen::Vector3d reference = normal.unitOrthogonal();
    for (int k = 0; k < options.grasp_rolls; ++k) {
      const Eigen::Vector3d along =
          Eigen::AngleAxisd(2 * M_PI * k / options.grasp_rolls, normal) * reference;
      Eigen::Matrix3d basis;
      basis << normal, along, normal.cross(along);
      const Eigen::Matrix3d rotation = basis * model_basis.transpose();
      starts.emplace_back(rotation, palm_centre - rotation * palm.centre);
    }
  }
  return starts;
}

void HandSearchOptions::Check() const {
  IHS_CHECK_ARG(directions >= 1 && directions <= 1000,
                "tracker.search.directions must be in [1, 1000]");
  IHS_CHECK_ARG(rolls >= 1 && rolls <= 360, "tracker.search.rolls must be in [1, 360]");
  IHS_CHECK_ARG(placement_iterations >= 0 && placement_iterations <= 100,
                "tracker.search.placement_iterations must be in [0, 100]");
  IHS_CHECK_ARG(sample_points >= 10 && sample_points <= 100000,
                "tracker.search.sample_points must be in [10, 100000]");
  IHS_CHECK_ARG(score_cap_mm > 0, "tracker.search.score_cap_mm must be positive");
  IHS_CHECK_ARG(grasp_rolls >= 0 && grasp_rolls <= 360,
                "tracker.search.grasp_rolls must be in [0, 360]");
  IHS_CHECK_ARG(grasp_tilt_deg >= 0 && grasp_tilt_deg <= 90,
                "tracker.search.grasp_tilt_deg must be in [0, 90]");
  IHS_CHECK_ARG(threads >= 0 && threads <= 256, "tracker.search.threads must be in [0, 256]");
}

HandSearch::HandSearch(const HandModel& model, const CameraIntrinsics& intrinsics,
                       HandSearchOptions options)
    : model_(model),
      intrinsics_(intrinsics),
      options_((options.Check(), options)),
      orientations_(EvenRotations(options_.directions, options_.rolls)) {}

std::vector<SearchHypothesis> HandSearch::Best(const std::vector<Eigen::Vector3f>& hand_points,
                                               const Frame& frame,
                                               const std::vector<HandPose>& articulations,
                                               const std::vector<HandPose>& tracked, int count,
                                               const GraspSide* side, bool right_hand) const {
  std::vector<SearchHypothesis> found;
  if (hand_points.empty() || count <= 0) return found;
  const PointKdTree data_tree(Thinned(hand_points, 6 * options_.sample_points));
  std::vector<Eigen::Vector3d> data;
  for (const Eigen::Vector3f& p : Thinned(hand_points, options_.sample_points))
    data.push_back(p.cast<double>());
  Eigen::Vector3d data_centre;
  Eigen::Matrix3d data_axes;
  PrincipalAxes(data, &data_centre, &data_axes);
  // The points are the hand's near surface: its middle lies a little farther along the ray.
  const Eigen::Vector3d centre = data_centre + 8.0 * data_centre.normalized();

  // Every articulation's placement and starts.
  struct Start {
    int articulation;
    Rigid3 cam_from_model;
    double score = 0;
  };
  std::vector<PalmAxes> palms;  // Per articulation, in the model's frame.
  std::vector<std::unique_ptr<Placement>> placements;
  std::vector<HandPose> poses;
  std::vector<Start> starts;
  std::vector<std::pair<HandPose, bool>> sources;  // An articulation; whether it was tracked.
  for (const HandPose& pose : articulations) sources.emplace_back(pose, false);
  for (const HandPose& pose : tracked) sources.emplace_back(pose, true);
  for (auto& [articulation, was_tracked] : sources) {
    const Rigid3 held = articulation.cam_from_root;
    articulation.cam_from_root = Rigid3();
    const std::vector<Eigen::Vector3f> vertices =
        model_.Pose(ForwardKinematics(model_, articulation)).vertices;
    const std::vector<Eigen::Vector3d> model_points =
        ToDouble(Thinned(vertices, 3 * options_.sample_points));
    Eigen::Vector3d model_centre;
    Eigen::Matrix3d model_axes;
    PrincipalAxes(model_points, &model_centre, &model_axes);
    // The even rotations, and the model's principal axes onto the cloud's, eight ways round.
    std::vector<Eigen::Matrix3d> rotations = orientations_;
    for (int sign : {1, -1}) {
      for (int quarter = 0; quarter < 4; ++quarter) {
        Eigen::Matrix3d axes;
        axes.col(0) = sign * data_axes.col(0);
        axes.col(1) = data_axes.col(1);
        axes.col(2) = axes.col(0).cross(axes.col(1));
        axes = Eigen::AngleAxisd(quarter * M_PI / 2, axes.col(0)).toRotationMatrix() * axes;
        rotations.push_back(axes * model_axes.transpose());
      }
    }
    const int index = static_cast<int>(poses.size());
    placements.push_back(
        std::make_unique<Placement>(vertices, data_tree, data, frame, intrinsics_, options_));
    poses.push_back(articulation);
    palms.push_back(
        PalmAxesOf(model_, model_.JointPositions(ForwardKinematics(model_, articulation))));
    for (const Eigen::Matrix3d& rotation : rotations)
      starts.push_back({index, Rigid3(rotation, centre - rotation * model_centre)});
    if (side != nullptr && options_.grasp_rolls > 0) {
      for (const Rigid3& start :
           GraspStarts(palms.back(), right_hand, side->centre(), data_centre, options_))
        starts.push_back({index, start});
    }
    // A tracked pose is also placed from where it was.
    if (was_tracked) starts.push_back({index, held});
  }
  // The grasp side's penalty of articulation `index` placed at `cam_from_model`.
  auto side_penalty = [&](int index, const Rigid3& cam_from_model) {
    if (side == nullptr) return 0.0;
    const PalmAxes& palm = palms[static_cast<size_t>(index)];
    const PalmAxes placed{cam_from_model.rotation() * palm.across,
                          cam_from_model.rotation() * palm.along, cam_from_model * palm.centre};
    return side->Penalty(placed, right_hand);
  };

  // Every start placed roughly (one ICP iteration) and scored, on as many threads as the search
  // is given. A run of starts keeps its best `to_place` coarse scores (the worst of them on top):
  // a start scored above them cannot be among the best `to_place` overall, and its score is cut
  // short (infinity). Those that are among them are never cut short, however the starts are
  // split, so the result does not depend on the split.
  constexpr double kInfinity = std::numeric_limits<double>::infinity();
  const size_t to_place = 4 * static_cast<size_t>(count);
  auto score_starts = [&](size_t begin, size_t end) {
    std::priority_queue<double> best_kept;
    for (size_t s = begin; s < end; ++s) {
      Start& start = starts[s];
      const Placement& placement = *placements[static_cast<size_t>(start.articulation)];
      start.cam_from_model = placement.Place(start.cam_from_model, 1, 3, nullptr);
      const double penalty = side_penalty(start.articulation, start.cam_from_model);
      const double bound = best_kept.size() < to_place ? kInfinity : best_kept.top();
      start.score = placement.Score(start.cam_from_model, 3, bound - penalty) + penalty;
      if (best_kept.size() < to_place || start.score < best_kept.top()) {
        best_kept.push(start.score);
        if (best_kept.size() > to_place) best_kept.pop();
      }
    }
  };
  ParallelRuns(starts.size(), options_.threads, score_starts);

  // The best of them placed fully (ties in start order, whatever the threads).
  std::vector<size_t> order(starts.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  const size_t placed = std::min<size_t>(starts.size(), to_place);
  std::partial_sort(order.begin(), order.begin() + placed, order.end(), [&](size_t a, size_t b) {
    return starts[a].score < starts[b].score || (starts[a].score == starts[b].score && a < b);
  });
  found.resize(placed);
  ParallelRuns(placed, options_.threads, [&](size_t begin, size_t end) {
    for (size_t k = begin; k < end; ++k) {
      const Start& start = starts[order[k]];
      SearchHypothesis& hypothesis = found[k];
      hypothesis.pose = poses[static_cast<size_t>(start.articulation)];
      hypothesis.pose.cam_from_root = placements[static_cast<size_t>(start.articulation)]->Place(
          start.cam_from_model, options_.placement_iterations, 1, &hypothesis.score);
      hypothesis.score += side_penalty(start.articulation, hypothesis.pose.cam_from_root);
    }
  });
  const size_t kept = std::min<size_t>(found.size(), count);
  std::vector<size_t> best(found.size());
  for (size_t k = 0; k < best.size(); ++k) best[k] = k;
  std::partial_sort(best.begin(), best.begin() + kept, best.end(), [&](size_t a, size_t b) {
    return found[a].score < found[b].score || (found[a].score == found[b].score && a < b);
  });
  std::vector<SearchHypothesis> out;
  for (size_t k = 0; k < kept; ++k) out.push_back(std::move(found[best[k]]));
  return out;
}

}  // namespace ihs::tracker
