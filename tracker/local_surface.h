#pragma once
// The object's surface around a fingertip: a sphere, or a plane, fitted to the object points
// the camera sees around it. A touching pad hides the surface it rests on; fitted to the points
// around the finger's outline, the surface is continued under it (ContactOptions::surface_mm,
// HandFitOptions::contact_surface_weight).

#include <Eigen/Core>
#include <optional>
#include <vector>

namespace ihs::tracker {

/// A sphere, or (radius 0) a plane, through points near a fingertip.
struct LocalSurface {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();   ///< The sphere's; a point of the plane.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< The plane's (unit, out of the object).
  double radius = 0;

  /// Unsigned distance of `p` to the surface, mm.
  double Distance(const Eigen::Vector3d& p) const;
  /// The surface's point nearest `p`, and there its unit normal (out of the sphere; the plane's
  /// own for a plane).
  Eigen::Vector3d Closest(const Eigen::Vector3d& p) const;
  Eigen::Vector3d NormalAt(const Eigen::Vector3d& p) const;
};

/// The sphere fitted algebraically to `points` (at least 4; |x|² + a·x + d = 0 in least
/// squares, about their mean), or the plane of their least spread where that is no sphere of
/// at most `max_radius` mm, its normal toward the camera at the origin (the points were seen
/// from there: the object lies behind them).
LocalSurface FitLocalSurface(const std::vector<Eigen::Vector3d>& points, double max_radius);

/// The surface through the `points` within `reach_mm` of `centre` (a surface curved more
/// gently than a 1 m sphere taken as flat), or none where fewer than `min_points` lie there
/// or they lie farther than `max_rms_mm` (RMS) from it: a patch across an edge or two surfaces.
/// With `trim`, such a patch gives the surface nearest `centre`: fitted to the quarter of the
/// patch nearest it, then to the patch's points within 2 `max_rms_mm` of that fit (three times
/// at most) — a box's face the fingertip rests on, beside the edge.
std::optional<LocalSurface> SurfaceAround(const Eigen::Vector3f& centre,
                                          const std::vector<Eigen::Vector3f>& points,
                                          double reach_mm, int min_points, double max_rms_mm,
                                          bool trim = false);

}  // namespace ihs::tracker
