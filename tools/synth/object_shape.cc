#include "tools/synth/object_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace ihs::synth {
namespace {

constexpr int kLatheSegments = 180;

// In scalars: the grasp planner asks millions of times, and unoptimised (sanitizer) builds do
// not inline Eigen's small-vector temporaries.
double SegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                       const Eigen::Vector2d& b) {
  const double abx = b.x() - a.x(), aby = b.y() - a.y();
  const double apx = p.x() - a.x(), apy = p.y() - a.y();
  const double length2 = abx * abx + aby * aby;
  const double s = length2 > 0 ? std::clamp((apx * abx + apy * aby) / length2, 0.0, 1.0) : 0.0;
  const double dx = p.x() - (a.x() + s * abx), dy = p.y() - (a.y() + s * aby);
  return std::sqrt(dx * dx + dy * dy);
}

// A label on a lathe mesh: a disc for every 250 mm² of its side (48-400), 6-18 mm across on the
// surface (arc length about the axis, height along it), at places drawn from `seed`, painted one
// over the other in a dark and a mid shade of the colour and in its channels turned round. Unlike
// the checkerboard it repeats nowhere: every side of the object looks different, as a printed label
// does.
void PaintLabel(std::uint32_t seed, TriangleMesh* mesh) {
  struct Disc {
    double phi, z, radius;
    int shade;
  };
  float z0 = std::numeric_limits<float>::infinity(), z1 = -z0;
  double radius_sum = 0;
  for (const Eigen::Vector3f& p : mesh->vertices) {
    z0 = std::min(z0, p.z()), z1 = std::max(z1, p.z());
    radius_sum += std::hypot(p.x(), p.y());
  }
  const double side_mm2 =
      2 * M_PI * radius_sum / std::max<size_t>(1, mesh->vertices.size()) * (z1 - z0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phi(-M_PI, M_PI), z(z0, z1), radius(3.0, 9.0);
  std::vector<Disc> discs(std::clamp(static_cast<int>(side_mm2 / 250), 48, 400));
  for (size_t i = 0; i < discs.size(); ++i) discs[i] = {phi(rng), z(rng), radius(rng), int(i % 3)};
  for (size_t v = 0; v < mesh->vertices.size(); ++v) {
    const Eigen::Vector3f& p = mesh->vertices[v];
    const double r = std::hypot(p.x(), p.y()), at = std::atan2(p.y(), p.x());
    const std::array<std::uint8_t, 3> base = mesh->colors[v];
    for (const Disc& disc : discs) {
      const double turn = std::remainder(at - disc.phi, 2 * M_PI);
      if (std::hypot(r * turn, p.z() - disc.z) > disc.radius) continue;
      std::array<std::uint8_t, 3>& color = mesh->colors[v];
      for (int c = 0; c < 3; ++c) {
        color[c] = disc.shade == 0   ? static_cast<std::uint8_t>(base[c] / 4)
                   : disc.shade == 1 ? static_cast<std::uint8_t>(base[c] / 2)
                                     : base[(c + 1) % 3];
      }
    }
  }
}

}  // namespace

ObjectShape ObjectShape::FromSpec(const std::string& spec, bool textured,
                                  std::array<std::uint8_t, 3> rgb,
                                  std::optional<std::uint32_t> label_seed) {
  if (label_seed && (spec == "box" || spec == "plain-box" || spec == "cube"))
    throw std::invalid_argument("a label pattern is for lathe objects, not '" + spec + "'");
  if (spec == "box") return Box("box", Eigen::Vector3d(60, 45, 90));
  if (spec == "plain-box") return Box("plain-box", Eigen::Vector3d(60, 45, 90), false, rgb);
  if (spec == "cube") return Box("cube", Eigen::Vector3d(60, 60, 60), textured, rgb);
  if (spec.rfind("lathe:", 0) == 0) {
    const std::string file = spec.substr(6);
    if (file.empty()) throw std::invalid_argument("--object lathe:FILE needs a file name");
    return Lathe(spec, ReadLatheProfile(file), rgb, textured, label_seed);
  }
  const auto names = PaperObjectNames();
  if (std::find(names.begin(), names.end(), spec) == names.end()) {
    throw std::invalid_argument("unknown object '" + spec +
                                "' (sphere, water-bottle, bowling-pin, small-bottle, box, "
                                "plain-box, cube, lathe:FILE)");
  }
  return Lathe(spec, PaperObjectProfile(spec), rgb, textured, label_seed);
}

ObjectShape ObjectShape::Lathe(const std::string& name, const LatheProfile& profile,
                               std::array<std::uint8_t, 3> rgb, bool textured,
                               std::optional<std::uint32_t> label_seed) {
  ObjectShape shape;
  shape.name_ = name;
  shape.textured_ = textured;
  if (!textured) {
    shape.mesh_ = MakeLatheMesh(profile, kLatheSegments, rgb);
  } else {
    // A profile sampled every 2 mm, so the pattern's edges stay sharp, then a checkerboard.
    const LatheProfile dense = ResampleProfile(profile, 2.0);
    shape.mesh_ = MakeLatheMesh(dense, kLatheSegments, rgb);
    if (label_seed) PaintLabel(*label_seed, &shape.mesh_);
    for (size_t v = 0; !label_seed && v < shape.mesh_.vertices.size(); ++v) {
      const Eigen::Vector3f& p = shape.mesh_.vertices[v];
      const double phi = std::atan2(p.y(), p.x()) + M_PI;
      const int sector = static_cast<int>(phi / (2 * M_PI) * 12) % 12;
      const int band = static_cast<int>(std::floor(p.z() / 12.0));
      if ((sector + band) % 2 == 0) {
        for (int c = 0; c < 3; ++c)
          shape.mesh_.colors[v][c] = static_cast<std::uint8_t>(rgb[c] / 3);
      }
    }
  }
  shape.height_mm_ = profile.back().first - profile.front().first;
  // The outline runs up the axis side closed by the end discs: (0, z0) … profile … (0, zn).
  shape.outline_.emplace_back(0.0, profile.front().first);
  for (const auto& [z, r] : profile) {
    shape.outline_.emplace_back(r, z);
    shape.max_radius_mm_ = std::max(shape.max_radius_mm_, r);
  }
  shape.outline_.emplace_back(0.0, profile.back().first);
  for (const Eigen::Vector2d& point : shape.outline_) shape.outline_z_.push_back(point.y());
  for (size_t i = 0; i + 1 < shape.outline_.size(); ++i) {
    const double a = shape.outline_[i].x(), b = shape.outline_[i + 1].x();
    shape.segment_r_.push_back({std::min(a, b), std::max(a, b)});
  }
  return shape;
}

ObjectShape ObjectShape::Box(const std::string& name, const Eigen::Vector3d& size, bool textured,
                             std::array<std::uint8_t, 3> rgb) {
  ObjectShape shape;
  shape.name_ = name;
  shape.mesh_ = MakeTexturedBox(size);
  if (!textured) shape.mesh_.colors.assign(shape.mesh_.vertices.size(), rgb);
  shape.height_mm_ = size.z();
  shape.max_radius_mm_ = size.head<2>().norm() / 2;
  shape.textured_ = textured;
  shape.box_ = true;
  shape.box_size_ = size;
  return shape;
}

double ObjectShape::SignedDistance(const Eigen::Vector3d& p) const {
  if (box_) {
    const Eigen::Vector3d half = box_size_ / 2;
    const Eigen::Vector3d q =
        (p - Eigen::Vector3d(0, 0, half.z())).cwiseAbs() - half;  // Box centred at mid-height.
    const double outside = q.cwiseMax(0.0).norm();
    const double inside = std::min(q.maxCoeff(), 0.0);
    return outside + inside;
  }
  // Distance to the outline in the (r, z) half-plane, skipping the segment along the axis (the
  // last point back to the first), which is not a surface. The outline's heights never
  // decrease (the profile's do not), so a segment is at least its height gap from the point:
  // the search starts at the segment level with the point and stops each way where the gap
  // exceeds the nearest distance found (the same minimum as over every segment; the grasp
  // planner asks millions of times, and this was 91 % of the generator's time).
  const Eigen::Vector2d q(p.head<2>().norm(), p.z());
  const int segments = static_cast<int>(outline_.size()) - 1;
  const auto level = std::upper_bound(outline_z_.begin(), outline_z_.end(), q.y());
  // The segment whose height range holds q (z_i <= q.z < z_i+1), clamped to the outline's.
  const int at = std::clamp(static_cast<int>(level - outline_z_.begin()) - 1, 0, segments - 1);
  // A segment is also at least its radius gap from the point: segments farther by that bound
  // than the nearest found are skipped without their square root (most, for the hand's points
  // far from the object).
  double distance = std::numeric_limits<double>::infinity();
  auto visit = [&](int i) {
    const double gap = std::max({0.0, q.x() - segment_r_[i][1], segment_r_[i][0] - q.x()});
    if (gap < distance)
      distance = std::min(distance, SegmentDistance(q, outline_[i], outline_[i + 1]));
  };
  for (int i = at; i < segments && outline_z_[i] - q.y() < distance; ++i) visit(i);
  for (int i = at - 1; i >= 0 && q.y() - outline_z_[i + 1] < distance; --i) visit(i);
  // Inside: a ray toward +r crosses the closed polygon once, at the segment that spans q's
  // height (the axis segment, at r = 0, never: q's r is not negative).
  bool inside = false;
  if (level != outline_z_.begin() && level != outline_z_.end()) {
    const int i = static_cast<int>(level - outline_z_.begin()) - 1;
    const Eigen::Vector2d& a = outline_[i];
    const Eigen::Vector2d& b = outline_[i + 1];
    const double r = a.x() + (q.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    inside = q.x() < r;
  }
  return inside ? -distance : distance;
}

double ObjectShape::RadiusAt(double z) const {
  if (box_) return std::min(box_size_.x(), box_size_.y()) / 2;
  double radius = 0;
  for (size_t i = 1; i + 2 < outline_.size(); ++i) {
    const Eigen::Vector2d& a = outline_[i];
    const Eigen::Vector2d& b = outline_[i + 1];
    if (z >= a.y() && z <= b.y()) {
      const double s = b.y() > a.y() ? (z - a.y()) / (b.y() - a.y()) : 1.0;
      radius = std::max(radius, a.x() + s * (b.x() - a.x()));
    }
  }
  return radius;
}

}  // namespace ihs::synth
