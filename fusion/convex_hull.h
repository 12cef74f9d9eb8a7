#pragma once
// The convex hull of a point set (qhull, Barber, Dobkin & Huhdanpaa 1996) as the planes of its
// faces: its inside is the intersection of their half-spaces, so a point's signed distance to it
// is the largest of its distances to the planes (exact inside; outside, at most the true
// distance). The closure bound (closure_bound.h) cuts what Poisson guessed beyond the hull of the
// surface the views saw.

#include <Eigen/Core>
#include <vector>

namespace ihs::fusion {

/// A convex polytope as the planes of its faces.
class ConvexHull {
 public:
  /// The hull of `points`; faces within `merge_mm` of coplanar are merged into one (qhull's
  /// centrum pre-merge, 'C-n': far fewer planes on a noisy or finely tessellated surface), then
  /// each plane is moved out to the farthest point, so every point lies inside. Empty (no
  /// planes) for fewer than four points or points that span no volume (all on a plane or line).
  static ConvexHull Of(const std::vector<Eigen::Vector3f>& points, double merge_mm);

  /// Whether the hull has no planes (it bounds nothing).
  bool Empty() const { return planes_.empty(); }
  int planes() const { return static_cast<int>(planes_.size()); }

  /// Signed distance of `point` to the hull's planes: the largest n·x − d over them (negative
  /// inside), clamped to [−limit, limit]; stops at the first plane `limit` or more outside.
  float SignedDistance(const Eigen::Vector3f& point, float limit) const;

 private:
  // Outward unit normal n and offset d of each face: inside is n·x ≤ d.
  std::vector<Eigen::Vector4f> planes_;
};

/// Points whose convex hull holds every one of `points` turned about the axis through `centre`
/// along `axis` (unit), by any angle: per `slice_mm` along the axis, two circumscribed
/// `segments`-gons, at the slice's lowest and highest point, as wide as its point farthest from
/// the axis. The hull of a body of revolution seen from one side, completed all round.
std::vector<Eigen::Vector3f> RevolvedEnvelope(const std::vector<Eigen::Vector3f>& points,
                                              const Eigen::Vector3d& centre,
                                              const Eigen::Vector3d& axis, double slice_mm,
                                              int segments);

}  // namespace ihs::fusion
