#pragma once
// An object of the synthetic benchmark as the generator needs it: its mesh in the object frame
// (symmetry axis +z, base at z = 0, mm) and an exact signed distance to its surface, used to
// close fingers onto it, to decide which fingertips touch it and to measure penetration.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "core/triangle_mesh.h"
#include "tools/synth/objects.h"

namespace ihs::synth {

/// A closed object with a signed distance. Build with FromSpec, Lathe or Box.
class ObjectShape {
 public:
  /// "sphere", "water-bottle", "bowling-pin", "small-bottle" (the paper's objects), "box" (a
  /// textured 60 × 45 × 90 mm box), "plain-box" (the same box in one colour, `rgb`), "cube" (a
  /// 60 mm cube) or "lathe:FILE" (a profile file of "height radius" lines).
  /// Throws std::invalid_argument for an unknown name and ihs::InputError for a bad file.
  /// `textured`: lathe objects and the cube get a colour pattern (lathe objects in `rgb`; the
  /// cube the box's); "box" always has its pattern, "plain-box" never. `label_seed`: a lathe
  /// object's pattern is a label drawn from that seed (LabelPattern) instead of the checkerboard.
  static ObjectShape FromSpec(const std::string& spec, bool textured = false,
                              std::array<std::uint8_t, 3> rgb = {235, 235, 235},
                              std::optional<std::uint32_t> label_seed = std::nullopt);
  /// A surface of revolution about +z, uniform colour `rgb`; textured: a checkerboard of 12
  /// sectors around and 12 mm bands along the axis in `rgb` and a darker shade of it (it repeats
  /// every 60° about the axis), or with `label_seed` a label (LabelPattern).
  static ObjectShape Lathe(const std::string& name, const LatheProfile& profile,
                           std::array<std::uint8_t, 3> rgb = {235, 235, 235}, bool textured = false,
                           std::optional<std::uint32_t> label_seed = std::nullopt);
  /// A box of `size` (x, y, z) mm standing on z = 0, centred on the axis; textured: a
  /// checkerboard with a hue per face (MakeTexturedBox), else one uniform colour `rgb`.
  static ObjectShape Box(const std::string& name, const Eigen::Vector3d& size, bool textured = true,
                         std::array<std::uint8_t, 3> rgb = {235, 235, 235});

  const std::string& name() const { return name_; }
  /// The mesh in the object frame (mm), with vertex colours.
  const TriangleMesh& mesh() const { return mesh_; }
  /// Height along +z, mm.
  double height_mm() const { return height_mm_; }
  /// Largest distance of the surface from the z axis, mm.
  double max_radius_mm() const { return max_radius_mm_; }
  /// Whether the surface carries a colour pattern (visual features can lock onto it).
  bool textured() const { return textured_; }
  /// Whether the shape is a surface of revolution about +z (turning about the axis maps its
  /// surface onto itself).
  bool rotationally_symmetric() const { return !box_; }

  /// Signed distance (mm) from a point in the object frame to the surface: negative inside.
  double SignedDistance(const Eigen::Vector3d& in_object) const;
  /// Radius of the surface of revolution at height z (mm); for the box, the smaller half-width.
  double RadiusAt(double z_mm) const;

 private:
  ObjectShape() = default;
  std::string name_;
  TriangleMesh mesh_;
  double height_mm_ = 0;
  double max_radius_mm_ = 0;
  bool textured_ = false;
  bool box_ = false;
  Eigen::Vector3d box_size_ = Eigen::Vector3d::Zero();
  // Closed profile polygon in the (r, z) half-plane, from the bottom axis point to the top one.
  std::vector<Eigen::Vector2d> outline_;
  std::vector<double> outline_z_;  // Its heights, which never decrease.
  // Each outline segment's radius range (lowest, highest).
  std::vector<std::array<double, 2>> segment_r_;
};

}  // namespace ihs::synth
