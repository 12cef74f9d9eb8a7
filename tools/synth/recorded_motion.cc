#include "tools/synth/recorded_motion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "core/check.h"
#include "core/errors.h"
#include "core/rigid_fit.h"
#include "tools/synth/hand_object.h"
#include "tools/synth/least_squares.h"

namespace ihs::synth {
namespace {

using tracker::HandModel;

constexpr double kReportDistanceMm = 3.0;
// Frames ahead over which the fingertips' turn at the grasp is measured, and the least turn that
// counts.
constexpr int kTurnFrames = 60;
constexpr double kMinTurnRad = 10 * M_PI / 180;

class Placer {
 public:
  Placer(const HandModel& hand, const ObjectShape& object, const RecordedMotionOptions& options)
      : hand_(hand), object_(object), options_(options), geometry_(hand) {
    for (size_t i = 0; i < geometry_.fingertip_bones().size(); ++i) {
      const int finger = hand.FingerOf(geometry_.fingertip_bones()[i]);
      if (finger == 4) thumb_ = static_cast<int>(i);
      if (finger == 3) index_ = static_cast<int>(i);
    }
    if (thumb_ < 0 || index_ < 0)
      throw InputError("the hand model has no thumb or index fingertip");
  }

  int tips() const { return static_cast<int>(geometry_.fingertip_bones().size()); }

  double TipDistance(const TriangleMesh& posed, const Rigid3& object_from_cam, int tip) const {
    double d = std::numeric_limits<double>::infinity();
    for (int v : geometry_.fingertip_vertices()[tip]) {
      d = std::min(d, SignedDistanceInCamera(object_, object_from_cam,
                                             posed.vertices[v].cast<double>(), 30.0));
    }
    return d;
  }

  std::vector<int> Holding(const TriangleMesh& posed, const Rigid3& cam_from_object) const {
    std::vector<int> holding;
    const Rigid3 object_from_cam = cam_from_object.Inverse();
    for (int tip = 0; tip < tips(); ++tip) {
      if (TipDistance(posed, object_from_cam, tip) <= options_.contact_mm) holding.push_back(tip);
    }
    return holding;
  }

  double Penetration(const TriangleMesh& posed, const Rigid3& cam_from_object) const {
    const Rigid3 object_from_cam = cam_from_object.Inverse();
    double deepest = 0;
    for (const auto& v : posed.vertices) {
      deepest = std::max(deepest,
                         -SignedDistanceInCamera(object_, object_from_cam, v.cast<double>(), 0.0));
    }
    return deepest;
  }

  // The rigid motion of the holding fingertips' skin from `before` to `after`.
  Rigid3 CarriedMotion(const TriangleMesh& before, const TriangleMesh& after,
                       const std::vector<int>& holding) const {
    std::vector<Eigen::Vector3d> from, to;
    for (int tip : holding) {
      for (int v : geometry_.fingertip_vertices()[tip]) {
        from.push_back(before.vertices[v].cast<double>());
        to.push_back(after.vertices[v].cast<double>());
      }
    }
    return FitRigidTransform(from, to);
  }

  // Moves the object from `predicted` so that the `holding` fingertips touch its surface and no
  // skin is inside, staying close to `predicted`.
  Rigid3 Correct(const TriangleMesh& posed, const Rigid3& predicted,
                 const std::vector<int>& holding) const {
    const Rigid3 object_from_predicted = predicted.Inverse();
    std::vector<Eigen::Vector3d> near;
    for (const auto& v : posed.vertices) {
      const Eigen::Vector3d p = v.cast<double>();
      if (SignedDistanceInCamera(object_, object_from_predicted, p, 8.0) < 8.0) near.push_back(p);
    }
    std::vector<std::vector<Eigen::Vector3d>> tip_points;
    for (int tip : holding) {
      std::vector<Eigen::Vector3d> points;
      for (int v : geometry_.fingertip_vertices()[tip]) {
        const Eigen::Vector3d p = posed.vertices[v].cast<double>();
        if (SignedDistanceInCamera(object_, object_from_predicted, p, 15.0) < 15.0)
          points.push_back(p);
      }
      if (!points.empty()) tip_points.push_back(std::move(points));
    }
    const Eigen::Vector3d centre = predicted * Eigen::Vector3d(0, 0, object_.height_mm() / 2);
    auto pose_of = [&](const Eigen::VectorXd& x) {
      return Rigid3::FromRotationVector(x.head<3>(), centre + x.tail<3>()) *
             Rigid3::Translation(-centre) * predicted;
    };
    const int n_tips = static_cast<int>(tip_points.size());
    const int n_near = static_cast<int>(near.size());
    auto residuals = [&](const Eigen::VectorXd& x) {
      const Rigid3 object_from_cam = pose_of(x).Inverse();
      Eigen::VectorXd r(n_tips + n_near + 6);
      for (int i = 0; i < n_tips; ++i) {
        double d = std::numeric_limits<double>::infinity();
        for (const auto& p : tip_points[i])
          d = std::min(d, object_.SignedDistance(object_from_cam * p));
        r[i] = d;
      }
      for (int j = 0; j < n_near; ++j) {
        r[n_tips + j] = std::min(0.0, object_.SignedDistance(object_from_cam * near[j]));
      }
      r.segment<3>(n_tips + n_near) = options_.prior_weight * 50.0 * x.head<3>();
      r.tail<3>() = options_.prior_weight * x.tail<3>();
      return r;
    };
    LeastSquaresOptions solver;
    solver.max_iterations = 15;
    solver.step = 1e-5;
    return pose_of(SolveLeastSquares(residuals, Eigen::VectorXd::Zero(6), solver));
  }

  // The object placed between thumb and index, or nothing when this frame admits no grasp.
  // Mean of a fingertip's skin vertices.
  Eigen::Vector3d TipCentre(const TriangleMesh& posed, int tip) const {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int v : geometry_.fingertip_vertices()[tip]) sum += posed.vertices[v].cast<double>();
    return sum / static_cast<double>(geometry_.fingertip_vertices()[tip].size());
  }

  // The axis (camera frame) about which the thumb and index turn from `posed` to `later`, or
  // zero when they hardly turn.
  Eigen::Vector3d TurnAxis(const TriangleMesh& posed, const TriangleMesh& later) const {
    const Rigid3 motion = CarriedMotion(posed, later, {thumb_, index_});
    if (motion.RotationAngleRad() < kMinTurnRad) return Eigen::Vector3d::Zero();
    return motion.RotationVector().normalized();
  }

  bool PlaceAtGrasp(const TriangleMesh& posed, const Eigen::Vector3d& turn_axis,
                    Rigid3* cam_from_object) const {
    // The closest pair of thumb and index skin points: the gap the object fills.
    double gap = std::numeric_limits<double>::infinity();
    Eigen::Vector3d thumb_point = Eigen::Vector3d::Zero(), index_point = Eigen::Vector3d::Zero();
    for (int a : geometry_.fingertip_vertices()[thumb_]) {
      for (int b : geometry_.fingertip_vertices()[index_]) {
        const double d = (posed.vertices[a] - posed.vertices[b]).norm();
        if (d < gap)
          gap = d, thumb_point = posed.vertices[a].cast<double>(),
          index_point = posed.vertices[b].cast<double>();
      }
    }
    if (gap < 5 || gap > 2 * object_.max_radius_mm() + 2) return false;
    // Heights where the object's diameter matches the gap (middle of each matching run).
    std::vector<double> heights;
    double run_start = -1;
    const double step = 0.5;
    for (double z = step; z <= object_.height_mm(); z += step) {
      const bool match = std::abs(2 * object_.RadiusAt(z) - gap) < 2.0 && z < object_.height_mm();
      if (match && run_start < 0) run_start = z;
      if (!match && run_start >= 0) heights.push_back(0.5 * (run_start + z - step)), run_start = -1;
    }
    if (heights.empty()) return false;
    const Eigen::Vector3d u = (index_point - thumb_point).normalized();
    const Eigen::Vector3d middle = 0.5 * (thumb_point + index_point);
    Eigen::Vector3d a0 = u.cross(Eigen::Vector3d::UnitZ());
    if (a0.norm() < 0.1) a0 = u.cross(Eigen::Vector3d::UnitX());
    a0.normalize();
    double best_score = std::numeric_limits<double>::infinity();
    Rigid3 best;
    // The object's axis lies across the gap. When the fingertips turn it, they turn it about its
    // axis: take the turn axis's part across the gap (either way up); else try 24 directions.
    std::vector<Eigen::Vector3d> axes;
    const Eigen::Vector3d across = turn_axis - turn_axis.dot(u) * u;
    if (across.norm() > 0.5) {
      axes = {across.normalized(), -across.normalized()};
    } else {
      for (int k = 0; k < 24; ++k) {
        const double psi = 2 * M_PI * k / 24;
        axes.push_back(std::cos(psi) * a0 + std::sin(psi) * u.cross(a0));
      }
    }
    for (double z : heights) {
      for (const Eigen::Vector3d& axis : axes) {
        Eigen::Matrix3d rotation;
        rotation.col(0) = u;
        rotation.col(1) = axis.cross(u);
        rotation.col(2) = axis;
        const Rigid3 candidate(rotation, middle - rotation * Eigen::Vector3d(0, 0, z));
        const Rigid3 object_from_cam = candidate.Inverse();
        const double score = std::abs(TipDistance(posed, object_from_cam, thumb_)) +
                             std::abs(TipDistance(posed, object_from_cam, index_)) +
                             3 * Penetration(posed, candidate);
        if (score < best_score) best_score = score, best = candidate;
      }
    }
    const Rigid3 placed = Correct(posed, best, {thumb_, index_});
    const Rigid3 object_from_cam = placed.Inverse();
    if (std::abs(TipDistance(posed, object_from_cam, thumb_)) > options_.contact_mm ||
        std::abs(TipDistance(posed, object_from_cam, index_)) > options_.contact_mm ||
        Penetration(posed, placed) > options_.max_penetration_mm) {
      return false;
    }
    *cam_from_object = placed;
    return true;
  }

 private:
  const HandModel& hand_;
  const ObjectShape& object_;
  const RecordedMotionOptions& options_;
  HandObjectGeometry geometry_;
  int thumb_ = -1, index_ = -1;
};

}  // namespace

void RecordedMotionOptions::Check() const {
  IHS_CHECK_ARG(contact_mm > 0 && contact_mm <= 20, "recorded.contact_mm must be in (0, 20]");
  IHS_CHECK_ARG(max_penetration_mm >= 0, "recorded.max_penetration_mm must be >= 0");
  IHS_CHECK_ARG(prior_weight > 0, "recorded.prior_weight must be positive");
  IHS_CHECK_ARG(slip_mm >= 0 && slip_mm <= 20, "recorded.slip_mm must be in [0, 20]");
  IHS_CHECK_ARG(last_frame >= -1, "recorded.last_frame must be >= -1");
}

Motion MakeRecordedMotion(const tracker::RecordedHand& recorded, const ObjectShape& object,
                          const RecordedMotionOptions& options, RecordedMotionReport* report) {
  options.Check();
  const int session_frames = static_cast<int>(recorded.cam_from_bone.size());
  if (session_frames == 0) throw InputError("the recorded motion has no frames");
  const int frames =
      options.last_frame < 0 ? session_frames : std::min(session_frames, options.last_frame + 1);
  const HandModel& hand = recorded.model;
  const Placer placer(hand, object, options);
  auto posed = [&](int t) { return hand.Pose(recorded.cam_from_bone[t]); };

  std::vector<Rigid3> cam_from_object(frames);
  int grasp = -1;
  for (int t = 0; t < frames && grasp < 0; ++t) {
    const TriangleMesh now = posed(t);
    const Eigen::Vector3d turn_axis =
        placer.TurnAxis(now, posed(std::min(t + kTurnFrames, session_frames - 1)));
    if (placer.PlaceAtGrasp(now, turn_axis, &cam_from_object[t])) grasp = t;
  }
  if (grasp < 0) {
    throw InputError("the recorded motion never holds '" + object.name() +
                     "' between thumb and index (its diameter never matches their gap)");
  }

  RecordedMotionReport stats;
  stats.frames = frames;
  stats.grasp_frame = grasp;
  std::vector<double> penetration(frames, 0.0);
  std::vector<bool> held(frames, false);
  int carried_ok = 0, placed_ok = 0;
  std::mt19937 rng(options.seed);
  std::normal_distribution<double> slip_step(0.0, 1.0);
  const double slip_radius = std::max(5.0, object.max_radius_mm());

  // Walks from the grasp frame to one end of the session.
  auto walk = [&](int direction) {
    TriangleMesh previous = posed(grasp);
    penetration[grasp] = placer.Penetration(previous, cam_from_object[grasp]);
    for (int t = grasp + direction; t >= 0 && t < frames; t += direction) {
      const TriangleMesh current = posed(t);
      const Rigid3& before = cam_from_object[t - direction];
      const std::vector<int> holding = placer.Holding(previous, before);
      // Not pinched: it keeps its orientation (supported while fingers re-grasp) and moves with a
      // single fingertip still touching it; with none it stays where it is.
      Rigid3 predicted = before;
      if (holding.size() == 1) {
        predicted = Rigid3::Translation(placer.TipCentre(current, holding[0]) -
                                        placer.TipCentre(previous, holding[0])) *
                    before;
      }
      if (holding.size() >= 2) {
        predicted = placer.CarriedMotion(previous, current, holding) * before;
        const Rigid3 object_from_cam = predicted.Inverse();
        double worst = 0;
        for (int tip : holding)
          worst = std::max(worst, std::abs(placer.TipDistance(current, object_from_cam, tip)));
        if (worst <= kReportDistanceMm) ++carried_ok;
      }
      const std::vector<int> touching = placer.Holding(current, predicted);
      Rigid3 placed = placer.Correct(current, predicted, touching);
      held[t] = holding.size() >= 2;
      if (held[t]) {
        const Rigid3 object_from_cam = placed.Inverse();
        double worst = 0;
        for (int tip : holding)
          worst = std::max(worst, std::abs(placer.TipDistance(current, object_from_cam, tip)));
        if (worst <= kReportDistanceMm) ++placed_ok;
        if (options.slip_mm > 0) {
          placed = placed * Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(),
                                                  options.slip_mm / slip_radius * slip_step(rng));
        }
      }
      cam_from_object[t] = placed;
      penetration[t] = placer.Penetration(current, placed);
      previous = current;
    }
  };
  walk(+1);
  walk(-1);
  held[grasp] = true;

  Motion motion;
  for (int t = 0; t < frames; ++t) {
    motion.frames.push_back({recorded.cam_from_bone[t], cam_from_object[t], held[t]});
  }
  stats.held_frames = static_cast<int>(std::count(held.begin(), held.end(), true));
  const int held_steps = std::max(1, stats.held_frames - 1);
  stats.carried_within_3mm_share = static_cast<double>(carried_ok) / held_steps;
  stats.placed_within_3mm_share = static_cast<double>(placed_ok) / held_steps;
  std::vector<double> sorted = penetration;
  std::sort(sorted.begin(), sorted.end());
  stats.penetration_max_mm = sorted.back();
  stats.penetration_p95_mm = sorted[static_cast<size_t>(0.95 * (frames - 1))];
  if (report) *report = stats;
  return motion;
}

}  // namespace ihs::synth
