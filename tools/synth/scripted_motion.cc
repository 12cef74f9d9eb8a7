#include "tools/synth/scripted_motion.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>

#include "core/check.h"
#include "core/errors.h"
#include "core/rigid_fit.h"
#include "tools/synth/hand_object.h"
#include "tools/synth/least_squares.h"
#include "tracker/hand_pose.h"

namespace ihs::synth {
namespace {

using tracker::HandModel;
using tracker::HandPose;

constexpr int kThumb = 4, kIndex = 3, kMiddle = 2;
constexpr int kGraspFingers[3] = {kThumb, kIndex, kMiddle};
// Skin other than the grasping fingertips keeps this far from the object's surface, mm.
constexpr double kClearanceMm = 3.0;

// The pad of a fingertip: the skin point that faces the palm, in the distal bone's frame, and
// the direction it faces.
struct Pad {
  int bone = -1;
  int tip = -1;  // Index into HandObjectGeometry's fingertips.
  Eigen::Vector3d point_in_bone;
  Eigen::Vector3d normal_in_bone;
};

Pad FindPad(const HandModel& hand, const HandObjectGeometry& geometry, int finger) {
  Pad pad;
  for (size_t i = 0; i < geometry.fingertip_bones().size(); ++i) {
    if (hand.FingerOf(geometry.fingertip_bones()[i]) == finger) {
      pad.tip = static_cast<int>(i);
      pad.bone = geometry.fingertip_bones()[i];
    }
  }
  if (pad.bone < 0)
    throw InternalError("the hand model has no fingertip of finger " + std::to_string(finger));
  const tracker::JointLimits& limits = hand.limits[pad.bone];
  const Eigen::Vector3d flexion_axis = limits.axes[1].normalized();
  // Flexing by a negative angle moves the bone's far end along x̂ × axis: toward the palm.
  pad.normal_in_bone = Eigen::Vector3d::UnitX().cross(flexion_axis).normalized();
  const Rigid3 bone_from_model = hand.model_from_bone_rest[pad.bone].Inverse();
  const double length = hand.bones[pad.bone].length_mm;
  double best = -1e9;
  for (int v : geometry.fingertip_vertices()[pad.tip]) {
    const Eigen::Vector3d p =
        bone_from_model * Eigen::Vector3d(hand.rest_mesh.vertices[v].cast<double>());
    if (p.x() < 0.3 * length || p.x() > 0.8 * length) continue;
    if (p.dot(pad.normal_in_bone) > best) best = p.dot(pad.normal_in_bone), pad.point_in_bone = p;
  }
  if (best < -1e8) throw InternalError("fingertip " + hand.bones[pad.bone].name + " has no pad");
  return pad;
}

// The surface point at azimuth `phi` (rad) and height z of the object frame, by bisection on the
// distance from the axis.
Eigen::Vector3d SurfacePoint(const ObjectShape& object, double phi, double z) {
  const Eigen::Vector3d direction(std::cos(phi), std::sin(phi), 0);
  double inside = 0, outside = 2 * object.max_radius_mm() + 10;
  for (int i = 0; i < 60; ++i) {
    const double r = 0.5 * (inside + outside);
    (object.SignedDistance(direction * r + Eigen::Vector3d(0, 0, z)) < 0 ? inside : outside) = r;
  }
  return direction * inside + Eigen::Vector3d(0, 0, z);
}

Eigen::Vector3d SurfaceNormal(const ObjectShape& object, const Eigen::Vector3d& p) {
  const double h = 0.05;
  Eigen::Vector3d g;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    d[k] = h;
    g[k] = object.SignedDistance(p + d) - object.SignedDistance(p - d);
  }
  return g.normalized();
}

double Smooth(double u) { return u * u * (3 - 2 * u); }

// A hand pose relative to the object ("cam" = object frame here).
struct Grasp {
  Rigid3 object_from_root;
  std::vector<double> closed_rad;
  std::vector<double> open_rad;
};

class GraspPlanner {
 public:
  GraspPlanner(const HandModel& hand, const ObjectShape& object, const ScriptedMotionOptions& o)
      : hand_(hand),
        object_(object),
        options_(o),
        geometry_(hand),
        dofs_(tracker::JointDegreesOfFreedom(hand)) {
    for (int finger : kGraspFingers) pads_.push_back(FindPad(hand, geometry_, finger));
    // Skin that must stay clear of the object: everything but the grasping fingertips, thinned
    // to a couple of thousand vertices.
    std::vector<bool> pad_vertex(hand.rest_mesh.vertices.size(), false);
    for (const Pad& pad : pads_) {
      for (int v : geometry_.fingertip_vertices()[pad.tip]) pad_vertex[v] = true;
    }
    std::vector<int> others;
    for (size_t v = 0; v < pad_vertex.size(); ++v) {
      if (!pad_vertex[v]) others.push_back(static_cast<int>(v));
    }
    const size_t stride = std::max<size_t>(1, others.size() / 2000);
    for (size_t i = 0; i < others.size(); i += stride) clearance_vertices_.push_back(others[i]);
  }

  // Skin vertices `indices` of the hand posed by `object_from_bone` (linear blend skinning).
  std::vector<Eigen::Vector3d> PoseVertices(const std::vector<Rigid3>& object_from_bone,
                                            const std::vector<int>& indices) const {
    std::vector<Eigen::Matrix<double, 3, 4>> blend(object_from_bone.size());
    for (size_t b = 0; b < object_from_bone.size(); ++b) {
      blend[b] =
          (object_from_bone[b] * hand_.model_from_bone_rest[b].Inverse()).ToMatrix().topRows<3>();
    }
    std::vector<Eigen::Vector3d> points;
    points.reserve(indices.size());
    for (int v : indices) {
      const Eigen::Vector4d rest(hand_.rest_mesh.vertices[v].x(), hand_.rest_mesh.vertices[v].y(),
                                 hand_.rest_mesh.vertices[v].z(), 1.0);
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (const auto& [bone, weight] : hand_.weights[v].bones) p += weight * (blend[bone] * rest);
      points.push_back(p);
    }
    return points;
  }

  // Inverse kinematics of a grasp: thumb pad at azimuth `azimuth`, index and middle pads side by
  // side along the axis opposite it, each pad facing into the surface. `start`, when given,
  // is the initial guess (else one is made from a pre-shape).
  Grasp Solve(double azimuth, const Grasp* start = nullptr) {
    const double z = GraspHeight(object_);
    const double spacing = 9.0 * hand_scale();
    const double phis[3] = {azimuth, azimuth + M_PI, azimuth + M_PI};
    const double zs[3] = {z, z + spacing, z - spacing};
    std::vector<Eigen::Vector3d> targets, normals;
    for (int i = 0; i < 3; ++i) {
      const Eigen::Vector3d surface = SurfacePoint(object_, phis[i], zs[i]);
      normals.push_back(SurfaceNormal(object_, surface));
      targets.push_back(surface - options_.press_mm * normals.back());
    }
    // Pre-shape: grasping fingers half flexed, ring and pinky curled out of the way.
    std::vector<double> preshape(dofs_.size(), 0.0);
    for (size_t k = 0; k < dofs_.size(); ++k) {
      const auto& [bone, axis] = dofs_[k];
      const int finger = hand_.FingerOf(bone);
      const auto [lo, hi] = hand_.limits[bone].limits_deg[axis];
      if (axis == 1 && lo < 0) {
        const double share = (finger == 0 || finger == 1) ? 0.6 : 0.35;
        preshape[k] = share * lo * M_PI / 180;
      }
    }
    // Initial root: pads and pad normals of the pre-shape onto the targets.
    const HandPose rest_pose{Rigid3(), preshape};
    const std::vector<Rigid3> root_from_bone = tracker::ForwardKinematics(hand_, rest_pose);
    std::vector<Eigen::Vector3d> from, to;
    for (int i = 0; i < 3; ++i) {
      const Rigid3& b = root_from_bone[pads_[i].bone];
      from.push_back(b * pads_[i].point_in_bone);
      from.push_back(b * pads_[i].point_in_bone + 30 * b.RotateVector(pads_[i].normal_in_bone));
      to.push_back(targets[i]);
      to.push_back(targets[i] - 30 * normals[i]);
    }
    const Rigid3 initial = FitRigidTransform(from, to);

    const int n = static_cast<int>(dofs_.size());
    Eigen::VectorXd x(6 + n);
    x.head<3>() = initial.RotationVector();
    x.segment<3>(3) = initial.translation();
    for (int k = 0; k < n; ++k) x[6 + k] = preshape[k];
    if (start) {
      x.head<3>() = start->object_from_root.RotationVector();
      x.segment<3>(3) = start->object_from_root.translation();
      for (int k = 0; k < n; ++k) x[6 + k] = start->closed_rad[k];
    }
    const int m = static_cast<int>(clearance_vertices_.size());
    auto residuals = [&](const Eigen::VectorXd& p) {
      Eigen::VectorXd r(18 + 2 * n + m);
      const HandPose pose{Rigid3::FromRotationVector(p.head<3>(), p.segment<3>(3)),
                          std::vector<double>(p.data() + 6, p.data() + 6 + n)};
      const std::vector<Rigid3> object_from_bone = tracker::ForwardKinematics(hand_, pose);
      for (int i = 0; i < 3; ++i) {
        const Rigid3& b = object_from_bone[pads_[i].bone];
        r.segment<3>(6 * i) = b * pads_[i].point_in_bone - targets[i];
        r.segment<3>(6 * i + 3) = 10.0 * (b.RotateVector(pads_[i].normal_in_bone) + normals[i]);
      }
      for (int k = 0; k < n; ++k) {
        const auto& [bone, axis] = dofs_[k];
        const double min = hand_.limits[bone].limits_deg[axis].first * M_PI / 180;
        const double max = hand_.limits[bone].limits_deg[axis].second * M_PI / 180;
        r[18 + k] = 3.0 * (p[6 + k] - preshape[k]);
        r[18 + n + k] = 100.0 * (std::max(0.0, p[6 + k] - max) + std::max(0.0, min - p[6 + k]));
      }
      const std::vector<Eigen::Vector3d> skin = PoseVertices(object_from_bone, clearance_vertices_);
      for (int j = 0; j < m; ++j) {
        r[18 + 2 * n + j] = 3.0 * std::min(0.0, object_.SignedDistance(skin[j]) - kClearanceMm);
      }
      return r;
    };
    LeastSquaresOptions solver;
    solver.max_iterations = 200;
    x = SolveLeastSquares(residuals, x, solver);
    Grasp grasp;
    grasp.object_from_root = Rigid3::FromRotationVector(x.head<3>(), x.segment<3>(3));
    grasp.closed_rad.assign(x.data() + 6, x.data() + 6 + n);
    const std::vector<Rigid3> object_from_bone =
        tracker::ForwardKinematics(hand_, HandPose{grasp.object_from_root, grasp.closed_rad});
    for (int i = 0; i < 3; ++i) {
      const double miss =
          (object_from_bone[pads_[i].bone] * pads_[i].point_in_bone - targets[i]).norm();
      if (miss > 10) {
        throw InternalError("no grasp of '" + object_.name() + "' for this hand: the " +
                            hand_.bones[pads_[i].bone].name + " pad misses by " +
                            std::to_string(miss) + " mm");
      }
    }
    return grasp;
  }

  // Closes each grasping finger until its fingertip presses `press_mm` into the surface, and
  // finds how far to open it to clear the surface by `release_mm`.
  void Close(Grasp& grasp) const {
    grasp.open_rad = grasp.closed_rad;
    for (const Pad& pad : pads_) {
      const int finger = hand_.FingerOf(pad.bone);
      std::vector<int> flexion;
      for (size_t k = 0; k < dofs_.size(); ++k) {
        if (dofs_[k].axis == 1 && hand_.FingerOf(dofs_[k].bone) == finger) flexion.push_back(k);
      }
      const std::vector<double> base = grasp.closed_rad;
      auto scaled = [&](double c) {
        std::vector<double> angles = base;
        for (int k : flexion) angles[k] = c * base[k];
        return angles;
      };
      auto distance = [&](const std::vector<double>& angles) {
        return TipDistance(grasp.object_from_root, angles, pad.tip);
      };
      double lo = 0.2, hi = 1.8;
      if (distance(scaled(lo)) > -options_.press_mm && distance(scaled(hi)) < -options_.press_mm) {
        for (int i = 0; i < 30; ++i) {
          const double c = 0.5 * (lo + hi);
          (distance(scaled(c)) > -options_.press_mm ? lo : hi) = c;
        }
        for (int k : flexion) grasp.closed_rad[k] = lo * base[k];
      }
      // Open: the smallest change of the flexion (either way) that clears the surface.
      double open = 1.0;
      std::vector<double> angles = grasp.closed_rad;
      for (int step = 1; step <= 30 && open == 1.0; ++step) {
        for (double c : {1.0 - 0.05 * step, 1.0 + 0.05 * step}) {
          for (int k : flexion) angles[k] = c * grasp.closed_rad[k];
          if (distance(angles) >= options_.release_mm) {
            open = c;
            break;
          }
        }
      }
      for (int k : flexion) grasp.open_rad[k] = open * grasp.closed_rad[k];
    }
  }

  const std::vector<tracker::DegreeOfFreedom>& dofs() const { return dofs_; }

 private:
  double hand_scale() const {
    const int index = hand_.BoneIndex("RFing.3_0");
    return index >= 0 ? hand_.bones[index].length_mm / 37.7 : 1.0;
  }

  double TipDistance(const Rigid3& object_from_root, const std::vector<double>& angles,
                     int tip) const {
    const std::vector<Rigid3> object_from_bone =
        tracker::ForwardKinematics(hand_, HandPose{object_from_root, angles});
    const TriangleMesh posed = hand_.Pose(object_from_bone);
    double d = 1e9;
    for (int v : geometry_.fingertip_vertices()[tip]) {
      d = std::min(d, object_.SignedDistance(posed.vertices[v].cast<double>()));
    }
    return d;
  }

  const HandModel& hand_;
  const ObjectShape& object_;
  const ScriptedMotionOptions& options_;
  HandObjectGeometry geometry_;
  std::vector<tracker::DegreeOfFreedom> dofs_;
  std::vector<Pad> pads_;
  std::vector<int> clearance_vertices_;
};

std::vector<double> Blend(const std::vector<double>& a, const std::vector<double>& b, double s) {
  std::vector<double> out(a.size());
  for (size_t k = 0; k < a.size(); ++k) out[k] = a[k] + s * (b[k] - a[k]);
  return out;
}

// Timeline: per grasp close, hold (turning), open, and — between grasps — turn back.
struct Timeline {
  int grasps = 1;
  // The object's turn per grasp, rad.
  double step_rad = 0;
  // Frames to close the fingers (and to open them).
  int close_frames = 2;
  // Frames to turn the hand back between two grasps.
  int back_frames = 2;
  // Frames of holding, all grasps together.
  int hold_total = 0;

  // Frames of grasp k's hold (the last one takes the remainder).
  int hold_frames(int k) const {
    return hold_total / grasps + (k == grasps - 1 ? hold_total % grasps : 0);
  }
};

Timeline MakeTimeline(const ScriptedMotionOptions& options) {
  Timeline t;
  t.grasps = std::max(
      1, static_cast<int>(std::ceil(options.turns * 360.0 / options.turn_per_grasp_deg - 1e-9)));
  t.step_rad = options.turns * 2 * M_PI / t.grasps;
  const double per_grasp = static_cast<double>(options.frames) / t.grasps;
  t.close_frames = std::max(2, static_cast<int>(std::lround(0.1 * per_grasp)));
  t.back_frames = std::max(2, static_cast<int>(std::lround(0.22 * per_grasp)));
  t.hold_total = options.frames - t.grasps * 2 * t.close_frames - (t.grasps - 1) * t.back_frames;
  IHS_CHECK_ARG(t.hold_total >= t.grasps * 4,
                "scripted.frames is too small for " << t.grasps << " grasps");
  return t;
}

// Where the object is: its axis leaning toward the camera, its centre `centre` ahead; turned
// about its axis so that the wrist starts on the side of a person facing the camera that the
// hand belongs to (a right hand on the image's left), half a grasp before straight sideways.
Rigid3 StartObjectPose(const HandModel& hand, const ObjectShape& object,
                       const ScriptedMotionOptions& options, const Grasp& first, double step_rad,
                       const Eigen::Vector3d& centre) {
  const double tilt = options.tilt_deg * M_PI / 180;
  const Eigen::Vector3d axis(0, -std::cos(tilt), -std::sin(tilt));
  const bool right_hand = tracker::IsRightHand(hand);
  const Eigen::Vector3d side(right_hand ? -1.0 : 1.0, 0, 0);
  const Eigen::Vector3d wrist = first.object_from_root.translation();
  const double wrist_phi = std::atan2(wrist.y(), wrist.x());
  // About the axis from `side`: toward +z (behind the object) on the right, toward -z on the
  // left. A right hand's wrist passes the mirror images of a left hand's positions (for 90°
  // grasps from 62° behind to 28° in front of straight sideways), in the other order.
  const double start_phi =
      right_hand ? -(std::atan2(0.3, 1.0) + step_rad / 2) : std::atan2(0.3, 1.0) - step_rad / 2;
  // The start azimuth turns the same way round for either hand (a mirror image).
  const double psi = start_phi - wrist_phi +
                     (right_hand ? -1.0 : 1.0) * options.start_azimuth_deg * M_PI / 180;
  const Eigen::Vector3d b = Eigen::AngleAxisd(psi, axis) * side;
  Eigen::Matrix3d rotation;
  rotation.col(0) = b;
  rotation.col(1) = axis.cross(b);
  rotation.col(2) = axis;
  return Rigid3(rotation, centre - rotation * Eigen::Vector3d(0, 0, object.height_mm() / 2));
}

// Object pose at the start of each grasp (and at the end of the last): nominal turn plus a
// seeded sway about its centre.
std::vector<Rigid3> GraspStartPoses(const Rigid3& cam_from_object0, const Eigen::Vector3d& centre,
                                    const Timeline& timeline, const ScriptedMotionOptions& options,
                                    std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Rigid3> grasp_start;
  for (int k = 0; k <= timeline.grasps; ++k) {
    Rigid3 sway;
    if (k > 0 && k < timeline.grasps) {
      const Eigen::Vector3d tilt_axis(unit(rng), 0, unit(rng));
      const double angle = options.sway_deg * M_PI / 180 * unit(rng);
      const Eigen::Vector3d shift(unit(rng), unit(rng), unit(rng));
      const Rigid3 turn = Rigid3::FromAxisAngle(
          tilt_axis.norm() > 1e-6 ? tilt_axis : Eigen::Vector3d::UnitX(), angle);
      sway = Rigid3::Translation(centre + options.sway_mm * shift) * turn *
             Rigid3::Translation(-centre);
    }
    grasp_start.push_back(sway * cam_from_object0 *
                          Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), k * timeline.step_rad));
  }
  return grasp_start;
}

// Each grasp's fingers, closed onto the object at its turned-back relative pose.
// A body of revolution looks the same turned, so the first grasp turned back serves every
// grasp; any other shape gets its grasp solved again where the hand now meets it.
std::vector<Grasp> PlanHolds(GraspPlanner& planner, const Grasp& first, const ObjectShape& object,
                             const Timeline& timeline) {
  const double step_rad = timeline.step_rad;
  std::vector<Grasp> holds;
  for (int k = 0; k < timeline.grasps; ++k) {
    Grasp grasp = first;
    grasp.object_from_root =
        Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), -k * step_rad) * first.object_from_root;
    if (k > 0 && !object.rotationally_symmetric()) grasp = planner.Solve(-k * step_rad, &grasp);
    planner.Close(grasp);
    holds.push_back(grasp);
  }
  return holds;
}

// Emits a scripted motion's frames grasp by grasp; while the object is held its contacts slip
// (a seeded random walk about its axis).
class MotionEmitter {
 public:
  MotionEmitter(const HandModel& hand, const ObjectShape& object,
                const ScriptedMotionOptions& options, const Timeline& timeline,
                const std::vector<Rigid3>& grasp_start, const std::vector<Grasp>& holds,
                std::mt19937& rng)
      : hand_(hand),
        options_(options),
        timeline_(timeline),
        grasp_start_(grasp_start),
        holds_(holds),
        rng_(rng),
        slip_radius_(std::max(5.0, object.RadiusAt(GraspHeight(object)))) {}

  // Grasp k: close, hold (turning), open, and — unless it is the last — turn back.
  void EmitGrasp(int k) {
    const Grasp& g = holds_[k];
    EmitFingers(grasp_start_[k], g, g.open_rad, g.closed_rad);
    EmitHold(k);
    EmitFingers(grasp_start_[k + 1], g, g.closed_rad, g.open_rad);
    if (k + 1 < timeline_.grasps) EmitTurnBack(k);
  }

  Motion Take() { return std::move(motion_); }

 private:
  void Emit(const Rigid3& cam_from_object_nominal, const Rigid3& object_from_root,
            const std::vector<double>& angles, bool held) {
    if (held && options_.slip_mm > 0)
      slip_rad_ += options_.slip_mm / slip_radius_ * slip_step_(rng_);
    MotionFrame frame;
    frame.cam_from_object =
        cam_from_object_nominal * Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), slip_rad_);
    frame.cam_from_bone = tracker::ForwardKinematics(
        hand_, HandPose{cam_from_object_nominal * object_from_root, angles});
    frame.held = held;
    motion_.frames.push_back(std::move(frame));
  }

  // Closes or opens grasp g's fingers from angles `from` to `to`, the object still at
  // `cam_from_object`.
  void EmitFingers(const Rigid3& cam_from_object, const Grasp& g, const std::vector<double>& from,
                   const std::vector<double>& to) {
    const int frames = timeline_.close_frames;
    for (int i = 0; i < frames; ++i)
      Emit(cam_from_object, g.object_from_root, Blend(from, to, Smooth((i + 1.0) / frames)), false);
  }

  // Grasp k holds the object while it turns from one grasp start to the next.
  void EmitHold(int k) {
    const Grasp& g = holds_[k];
    const double step_rad = timeline_.step_rad;
    const int hold_frames = timeline_.hold_frames(k);
    for (int i = 0; i < hold_frames; ++i) {
      const double s = Smooth((i + 1.0) / hold_frames);
      const Rigid3& start = grasp_start_[k];
      const Rigid3& end = grasp_start_[k + 1];
      // Interpolate the turn about the object's own axis separately from the sway, so a turn of
      // up to 180° follows the axis rather than the shortest rotation.
      const Rigid3 sway_start =
          start * Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), -k * step_rad);
      const Rigid3 sway_end =
          end * Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), -(k + 1) * step_rad);
      const Rigid3 nominal = sway_start.Interpolate(sway_end, s) *
                             Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), (k + s) * step_rad);
      Emit(nominal, g.object_from_root, g.closed_rad, true);
    }
  }

  // The open hand turns back from grasp k to grasp k + 1.
  void EmitTurnBack(int k) {
    const Grasp& g = holds_[k];
    const Grasp& next = holds_[k + 1];
    const double step_rad = timeline_.step_rad;
    const int back_frames = timeline_.back_frames;
    for (int i = 0; i < back_frames; ++i) {
      const double s = Smooth((i + 1.0) / back_frames);
      const Rigid3 turned_next =
          Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), step_rad) * next.object_from_root;
      const Rigid3 object_from_root =
          Rigid3::FromAxisAngle(Eigen::Vector3d::UnitZ(), -s * step_rad) *
          g.object_from_root.Interpolate(turned_next, s);
      Emit(grasp_start_[k + 1], object_from_root, Blend(g.open_rad, next.open_rad, s), false);
    }
  }

  const HandModel& hand_;
  const ScriptedMotionOptions& options_;
  const Timeline& timeline_;
  const std::vector<Rigid3>& grasp_start_;
  const std::vector<Grasp>& holds_;
  std::mt19937& rng_;
  std::normal_distribution<double> slip_step_{0.0, 1.0};
  double slip_rad_ = 0.0;
  const double slip_radius_;
  Motion motion_;
};

}  // namespace

void ScriptedMotionOptions::Check() const {
  IHS_CHECK_ARG(frames >= 10 && frames <= 100000, "scripted.frames must be in [10, 100000]");
  IHS_CHECK_ARG(turns > 0 && turns <= 20, "scripted.turns must be in (0, 20]");
  IHS_CHECK_ARG(turn_per_grasp_deg >= 10 && turn_per_grasp_deg <= 180,
                "scripted.turn_per_grasp_deg must be in [10, 180]");
  IHS_CHECK_ARG(distance_mm >= 300 && distance_mm <= 3000,
                "scripted.distance_mm must be in [300, 3000]");
  IHS_CHECK_ARG(std::abs(tilt_deg) <= 80, "scripted.tilt_deg must be in [-80, 80]");
  IHS_CHECK_ARG(std::abs(start_azimuth_deg) <= 180,
                "scripted.start_azimuth_deg must be in [-180, 180]");
  IHS_CHECK_ARG(sway_mm >= 0 && sway_deg >= 0 && sway_deg <= 45,
                "scripted.sway_mm must be >= 0 and sway_deg in [0, 45]");
  IHS_CHECK_ARG(press_mm >= 0 && press_mm <= 3, "scripted.press_mm must be in [0, 3]");
  IHS_CHECK_ARG(release_mm > 0 && release_mm <= 40, "scripted.release_mm must be in (0, 40]");
  IHS_CHECK_ARG(slip_mm >= 0 && slip_mm <= 20, "scripted.slip_mm must be in [0, 20]");
}

double GraspHeight(const ObjectShape& object) {
  const double height = object.height_mm();
  double best_z = height / 2, best_cost = 1e9;
  for (int i = 0; i <= 100; ++i) {
    const double z = height * (0.2 + 0.6 * i / 100);
    const double cost = std::abs(object.RadiusAt(z) - 30.0) + 0.25 * std::abs(z - height / 2);
    if (cost < best_cost) best_cost = cost, best_z = z;
  }
  return best_z;
}

Motion MakeScriptedMotion(const HandModel& hand, const ObjectShape& object,
                          const ScriptedMotionOptions& options) {
  options.Check();
  GraspPlanner planner(hand, object, options);
  const Grasp first = planner.Solve(0.0);
  const Timeline timeline = MakeTimeline(options);
  const Eigen::Vector3d centre(0, 0, options.distance_mm);
  const Rigid3 cam_from_object0 =
      StartObjectPose(hand, object, options, first, timeline.step_rad, centre);
  std::mt19937 rng(options.seed);
  const std::vector<Rigid3> grasp_start =
      GraspStartPoses(cam_from_object0, centre, timeline, options, rng);
  const std::vector<Grasp> holds = PlanHolds(planner, first, object, timeline);
  MotionEmitter emitter(hand, object, options, timeline, grasp_start, holds, rng);
  for (int k = 0; k < timeline.grasps; ++k) emitter.EmitGrasp(k);
  return emitter.Take();
}

}  // namespace ihs::synth
