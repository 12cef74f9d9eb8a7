#include "tracker/procedural_hand.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>

#include "core/check.h"

namespace ihs::tracker {
namespace {

// How far a fingertip's skin reaches beyond its bone's end point, mm.
constexpr double kTipBeyondEndMm = 1.7;

// A bone frame at `start` whose x axis is `direction` and whose y (flexion) axis lies in the
// palm plane, so that negative flexion bends toward the palm: -y for a right hand (`palm` = -1),
// +y for a left one (`palm` = +1).
Rigid3 BoneFrame(const Eigen::Vector3d& start, const Eigen::Vector3d& direction, double palm) {
  const Eigen::Vector3d x = direction.normalized();
  const Eigen::Vector3d y = (-palm * x.cross(Eigen::Vector3d::UnitY())).normalized();
  Eigen::Matrix3d rotation;
  rotation.col(0) = x;
  rotation.col(1) = y;
  rotation.col(2) = x.cross(y);
  return Rigid3(rotation, start);
}

// `frame` moved by `distance` along its own z axis (into the palm, for a BoneFrame).
Rigid3 Shifted(const Rigid3& frame, double distance) {
  if (distance == 0) return frame;
  return Rigid3(frame.rotation(), frame.translation() + distance * frame.rotation().col(2));
}

// The limits of a right hand's joint, or of the mirrored joint of a left hand: mirroring keeps
// the flexion axis (BoneFrame) but turns twist and spread the other way round their axes.
JointLimits Limits(std::array<std::pair<double, double>, 3> ranges_deg, bool right_hand) {
  if (!right_hand) {
    for (int k : {0, 2}) ranges_deg[k] = {-ranges_deg[k].second, -ranges_deg[k].first};
  }
  JointLimits limits;
  limits.limits_deg = ranges_deg;
  for (int k = 0; k < 3; ++k) limits.active[k] = ranges_deg[k].first != ranges_deg[k].second;
  return limits;
}

// Skinning weights as a function of a vertex's position in the model frame.
using WeightFunction = std::function<VertexWeights(const Eigen::Vector3d& in_model)>;

// Weights of a capsule around `bone`: the bone, blended into its parent over the first quarter.
WeightFunction JointBlendWeights(const HandModel& model, int bone) {
  const int parent = model.bones[bone].parent;
  const double length = model.bones[bone].length_mm;
  const Rigid3 bone_from_model = model.model_from_bone_rest[bone].Inverse();
  return [=](const Eigen::Vector3d& in_model) {
    VertexWeights weights;
    const double s = (bone_from_model * in_model).x() / length;
    const double to_parent =
        parent < 0 ? 0.0 : (s < 0.25 ? 0.5 * (1 - std::max(0.0, s) / 0.25) : 0.0);
    weights.bones.emplace_back(bone, static_cast<float>(1 - to_parent));
    if (to_parent > 0) weights.bones.emplace_back(parent, static_cast<float>(to_parent));
    return weights;
  };
}

// The shape of a capsule's cross-section: `flatten` scales its z extent; `roundness` 2 is an
// ellipse, larger values a superellipse (a rounded rectangle, like a palm's section).
// `taper` is the radius at the capsule's end relative to its start.
struct Section {
  double flatten = 1.0;
  double roundness = 2.0;
  double taper = 1.0;
};

// Appends a closed capsule along the x axis of `model_from_capsule`: a body of `length` and
// `radius` (cross-section `section`) with half-ellipsoid caps reaching `cap` beyond each end,
// skinned by `weights_of`.
void AppendCapsule(HandModel& model, const Rigid3& model_from_capsule, double length, double radius,
                   double cap, Section section, int segments, const WeightFunction& weights_of) {
  TriangleMesh& mesh = model.rest_mesh;
  // Profile along the axis: (x, ring radius) from pole to pole.
  std::vector<std::pair<double, double>> profile;
  const int cap_rings = 4;
  const double end_radius = radius * section.taper;
  for (int i = 1; i <= cap_rings; ++i) {
    const double a = M_PI / 2 * i / cap_rings;  // From the start pole to the equator.
    profile.emplace_back(-cap * std::cos(a), radius * std::sin(a));
  }
  const int body_rings =
      std::max(2, static_cast<int>(std::ceil(length / (std::min(radius, end_radius) * 0.8))));
  for (int i = 1; i < body_rings; ++i) {
    const double t = static_cast<double>(i) / body_rings;
    profile.emplace_back(length * t, radius + (end_radius - radius) * t);
  }
  for (int i = 0; i < cap_rings; ++i) {
    const double a = M_PI / 2 * i / cap_rings;
    profile.emplace_back(length + cap * std::sin(a), end_radius * std::cos(a));
  }
  auto add = [&](const Eigen::Vector3d& in_capsule) {
    const Eigen::Vector3d in_model = model_from_capsule * in_capsule;
    mesh.vertices.push_back(in_model.cast<float>());
    model.weights.push_back(weights_of(in_model));
    return static_cast<std::int32_t>(mesh.vertices.size() - 1);
  };
  const std::int32_t start_pole = add({-cap, 0, 0});
  const auto first_ring = static_cast<std::int32_t>(mesh.vertices.size());
  for (const auto& [x, r] : profile) {
    for (int k = 0; k < segments; ++k) {
      const double phi = 2 * M_PI * k / segments;
      auto power = [&](double v) {
        return std::copysign(std::pow(std::abs(v), 2.0 / section.roundness), v);
      };
      add({x, r * power(std::cos(phi)), section.flatten * r * power(std::sin(phi))});
    }
  }
  const std::int32_t end_pole = add({length + cap, 0, 0});
  const int rings = static_cast<int>(profile.size());
  auto at = [&](int ring, int k) { return first_ring + ring * segments + (k % segments); };
  // Outward orientation: the bone axis runs along +x, rings turn from y toward z.
  for (int k = 0; k < segments; ++k) {
    mesh.faces.push_back({start_pole, at(0, k + 1), at(0, k)});
    mesh.faces.push_back({end_pole, at(rings - 1, k), at(rings - 1, k + 1)});
    for (int ring = 0; ring + 1 < rings; ++ring) {
      mesh.faces.push_back({at(ring, k), at(ring, k + 1), at(ring + 1, k + 1)});
      mesh.faces.push_back({at(ring, k), at(ring + 1, k + 1), at(ring + 1, k)});
    }
  }
}

}  // namespace

void ProceduralHandOptions::Check() const {
  auto norm = [](const std::array<double, 3>& a, const std::array<double, 3>& b) {
    return std::hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
  };
  IHS_CHECK_ARG(norm(wrist_start_mm, {0, 0, 0}) > 1, "hand.wrist_start_mm must not be the wrist");
  for (int f = 0; f < 4; ++f) {
    IHS_CHECK_ARG(norm(metacarpal_start_mm[f], metacarpal_end_mm[f]) > 1,
                  "hand.metacarpal_end_mm must lie away from its metacarpal_start_mm");
  }
  IHS_CHECK_ARG(norm(thumb_direction, {0, 0, 0}) > 1e-6, "hand.thumb_direction must not be 0");
  for (const auto& finger : finger_lengths_mm) {
    for (double length : finger)
      IHS_CHECK_ARG(length > 0, "hand.finger_lengths_mm must be positive");
  }
  for (double length : thumb_lengths_mm)
    IHS_CHECK_ARG(length > 0, "hand.thumb_lengths_mm must be positive");
  for (double radius : finger_radius_mm)
    IHS_CHECK_ARG(radius > 0, "hand.finger_radius_mm must be positive");
  IHS_CHECK_ARG(distal_taper > 0.3 && distal_taper <= 1.5,
                "hand.distal_taper must be in (0.3, 1.5], got " << distal_taper);
  IHS_CHECK_ARG(palm_width_mm > 0 && palm_base_width_mm > 0 && palm_thickness_mm > 0 &&
                    palm_thickness_mm <= palm_base_width_mm,
                "hand.palm_width_mm, palm_base_width_mm and palm_thickness_mm must be positive, "
                "thickness <= base width");
  IHS_CHECK_ARG(
      wrist_width_mm > 0 && wrist_thickness_mm > 0 && wrist_thickness_mm <= wrist_width_mm,
      "hand.wrist_width_mm and wrist_thickness_mm must be positive, thickness <= width");
  IHS_CHECK_ARG(wrist_palmar_offset_mm >= 0 && wrist_palmar_offset_mm < wrist_thickness_mm / 2 &&
                    palm_palmar_offset_mm >= 0 && palm_palmar_offset_mm < palm_thickness_mm / 2,
                "hand.wrist_palmar_offset_mm and palm_palmar_offset_mm must be in [0, half the "
                "thickness)");
  IHS_CHECK_ARG(finger_palmar_offset >= 0 && finger_palmar_offset < 1,
                "hand.finger_palmar_offset must be in [0, 1), got " << finger_palmar_offset);
  IHS_CHECK_ARG(segments >= 6 && segments <= 64,
                "hand.segments must be in [6, 64], got " << segments);
}

HandModel MakeProceduralHand(const ProceduralHandOptions& options) {
  options.Check();
  HandModel model;
  auto add_bone = [&](const std::string& name, int parent, double length, const Rigid3& frame,
                      JointLimits limits) {
    model.bones.push_back({name, parent, length});
    model.model_from_bone_rest.push_back(frame);
    model.limits.push_back(limits);
    return static_cast<int>(model.bones.size() - 1);
  };
  // Root: the wrist, ending where the metacarpals start; a free rigid body.
  JointLimits root;
  root.translation = true;
  root.active = {true, true, true};
  root.limits_deg = {{{-180, 180}, {-180, 180}, {-180, 180}}};
  const bool right = options.right_hand;
  const double palm = right ? -1.0 : 1.0;  // The palm's side along y.
  // The options' places are a right hand's; a left hand's mirror y.
  auto place = [&](const std::array<double, 3>& p) {
    return Eigen::Vector3d(p[0], right ? p[1] : -p[1], p[2]);
  };
  const Eigen::Vector3d wrist_start = place(options.wrist_start_mm);
  std::array<Eigen::Vector3d, 4> starts, knuckles;  // Fingers' metacarpals, pinky to index.
  for (int f = 0; f < 4; ++f) {
    starts[f] = place(options.metacarpal_start_mm[f]);
    knuckles[f] = place(options.metacarpal_end_mm[f]);
  }
  add_bone("Lower Arm R", -1, wrist_start.norm(), BoneFrame(wrist_start, -wrist_start, palm), root);

  // Fingers 0..3 (pinky to index) and the thumb (4): metacarpals fan out from the wrist to the
  // knuckles, the phalanges go on in their metacarpal's direction.
  const JointLimits finger_limits[4] = {
      Limits({{{0, 0}, {-10, 1}, {0, 0}}}, right), Limits({{{0, 0}, {-95, 20}, {-30, 15}}}, right),
      Limits({{{0, 0}, {-100, 10}, {0, 0}}}, right), Limits({{{0, 0}, {-90, 10}, {0, 0}}}, right)};
  const JointLimits thumb_limits[3] = {Limits({{{-20, 20}, {-40, 20}, {-40, 30}}}, right),
                                       Limits({{{0, 0}, {-60, 10}, {-15, 15}}}, right),
                                       Limits({{{0, 0}, {-90, 10}, {0, 0}}}, right)};
  const char* names[4] = {"Hand", "0", "1", "2"};
  for (int f = 0; f < 5; ++f) {
    const bool thumb = f == 4;
    std::vector<double> lengths;
    Rigid3 frame;
    if (thumb) {
      lengths.assign(options.thumb_lengths_mm.begin(), options.thumb_lengths_mm.end());
      frame = BoneFrame(place(options.thumb_start_mm), place(options.thumb_direction), palm);
    } else {
      lengths = {(knuckles[f] - starts[f]).norm()};
      lengths.insert(lengths.end(), options.finger_lengths_mm[f].begin(),
                     options.finger_lengths_mm[f].end());
      frame = BoneFrame(starts[f], knuckles[f] - starts[f], palm);
    }
    int parent = 0;
    for (size_t k = 0; k < lengths.size(); ++k) {
      parent = add_bone("RFing." + std::to_string(f) + "_" + names[k], parent, lengths[k], frame,
                        thumb ? thumb_limits[k] : finger_limits[k]);
      frame = frame * Rigid3::Translation({lengths[k], 0, 0});  // The child starts at the end.
    }
  }

  // Skin. The palm: one flat capsule from the metacarpals' starts to the knuckles, as broad as
  // the knuckles' line is long and turned with it, each point skinned to the metacarpals nearest
  // across the palm (and to the wrist near its start).
  const int segments = options.segments;
  std::array<int, 4> metacarpals;
  Eigen::Vector3d base = Eigen::Vector3d::Zero(), top = Eigen::Vector3d::Zero();
  for (int f = 0; f < 4; ++f) {
    metacarpals[f] = model.BoneIndex("RFing." + std::to_string(f) + "_Hand");
    base += starts[f] / 4;
    top += knuckles[f] / 4;
  }
  const Eigen::Vector3d along = (top - base).normalized();
  // Across the palm, square to `along`: toward the little finger for a right hand, toward the
  // index for a left one (as BoneFrame's y).
  const Eigen::Vector3d knuckle_line = palm * (knuckles[3] - knuckles[0]);
  const Eigen::Vector3d across = (knuckle_line - knuckle_line.dot(along) * along).normalized();
  Eigen::Matrix3d palm_rotation;
  palm_rotation << along, across, along.cross(across);
  // The capsule's body starts 8 mm up from the metacarpals' starts and ends 7.45 mm short of the
  // knuckles (its caps reach 12 mm beyond either end).
  const double palm_start = 8, palm_end_gap = 7.45;
  const double palm_length = (top - base).norm() - palm_start - palm_end_gap;
  const double palm_radius = options.palm_base_width_mm / 2;
  const WeightFunction palm_weights = [&](const Eigen::Vector3d& p) {
    VertexWeights weights;
    const double height = (p - base).dot(along);
    const double to_wrist = 0.5 * std::max(0.0, 1 - height / 20);
    const double t = std::clamp(height / (palm_length + palm_start), 0.0, 1.0);
    double raw[4], sum = 0;
    for (int f = 0; f < 4; ++f) {
      const double off_axis = (p - starts[f] - t * (knuckles[f] - starts[f])).dot(across);
      raw[f] = std::exp(-std::pow(off_axis / 12, 2)) + 1e-6;
      sum += raw[f];
    }
    for (int f = 0; f < 4; ++f) {
      weights.bones.emplace_back(metacarpals[f], static_cast<float>((1 - to_wrist) * raw[f] / sum));
    }
    if (to_wrist > 0) weights.bones.emplace_back(0, static_cast<float>(to_wrist));
    return weights;
  };
  // BoneFrame's z, and the palm frame's third axis, point into the palm.
  const Eigen::Vector3d palm_origin =
      base + palm_start * along + options.palm_palmar_offset_mm * palm_rotation.col(2);
  AppendCapsule(model, Rigid3(palm_rotation, palm_origin), palm_length, palm_radius, 12,
                {options.palm_thickness_mm / options.palm_base_width_mm, 3.0,
                 options.palm_width_mm / options.palm_base_width_mm},
                segments * 2, palm_weights);
  // The wrist: a shorter, flat capsule on the root bone.
  AppendCapsule(model, Shifted(model.model_from_bone_rest[0], options.wrist_palmar_offset_mm),
                model.bones[0].length_mm, options.wrist_width_mm / 2, 10,
                {options.wrist_thickness_mm / options.wrist_width_mm, 2.0}, segments * 2,
                JointBlendWeights(model, 0));
  // Fingers and thumb: round capsules on the phalanges and the thumb's metacarpal.
  // A fingertip's skin ends just beyond its bone's end point, as on a real hand (the scanned
  // hand's end points lie 1.4–1.9 mm inside the tip): its capsule stops short by the radius.
  const std::vector<int> ends = model.EndEffectors();
  for (int bone = 1; bone < static_cast<int>(model.bones.size()); ++bone) {
    const std::string& name = model.bones[bone].name;
    const int finger = name[6] - '0';
    const bool metacarpal = name.size() >= 4 && name.substr(name.size() - 4) == "Hand";
    if (metacarpal && finger < 4) continue;  // Inside the palm.
    const bool distal = std::find(ends.begin(), ends.end(), bone) != ends.end();
    const bool proximal = model.bones[model.bones[bone].parent].name.ends_with("Hand");
    const double taper =
        distal ? options.distal_taper : (proximal ? 1.0 : 0.5 * (1.0 + options.distal_taper));
    const double radius = options.finger_radius_mm[finger] * (metacarpal ? 1.3 : taper);
    double length = model.bones[bone].length_mm;
    if (distal) length = std::max(0.3 * length, length - radius + kTipBeyondEndMm);
    const double flatten = metacarpal ? 0.7 : 0.9;
    // BoneFrame's z points into the palm; the thumb's bones run in their skin's middle.
    const double palmar = finger < 4 ? options.finger_palmar_offset * flatten * radius : 0.0;
    AppendCapsule(model, Shifted(model.model_from_bone_rest[bone], palmar), length, radius, radius,
                  {flatten, 2.0}, segments, JointBlendWeights(model, bone));
  }
  model.rest_mesh.ComputeVertexNormals();
  model.Check();
  return model;
}

}  // namespace ihs::tracker
