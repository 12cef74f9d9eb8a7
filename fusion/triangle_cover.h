#pragma once
// Which points of a plane a 2D triangle covers, with a tie rule for points on an edge: of two
// triangles sharing the edge, exactly one covers them. Rasterising a closed mesh this way
// crosses it an even number of times along every ray (used for inside tests and for spans
// inside a mesh along pixel rays).

#include <Eigen/Core>

namespace ihs::fusion {

/// Whether the counter-clockwise triangle `q` (positive signed area) covers `p`. `weights`
/// gets twice the areas of the sub-triangles opposite each corner (barycentric weights times
/// twice the triangle's area) when `p` is covered.
inline bool CoversPoint(const Eigen::Vector2d q[3], const Eigen::Vector2d& p, double weights[3]) {
  for (int e = 0; e < 3; ++e) {
    const Eigen::Vector2d& p0 = q[(e + 1) % 3];
    const Eigen::Vector2d& p1 = q[(e + 2) % 3];
    weights[e] = (p1 - p0).x() * (p - p0).y() - (p1 - p0).y() * (p - p0).x();
    // On the edge: owned by the triangle that runs it downward (or leftward when level).
    const bool owns = p1.y() < p0.y() || (p1.y() == p0.y() && p1.x() < p0.x());
    if (!(weights[e] > 0 || (weights[e] == 0 && owns))) return false;
  }
  return true;
}

/// Twice the signed area of the 2D triangle `q` (positive: counter-clockwise).
inline double TwiceSignedArea(const Eigen::Vector2d q[3]) {
  return (q[1] - q[0]).x() * (q[2] - q[0]).y() - (q[1] - q[0]).y() * (q[2] - q[0]).x();
}

}  // namespace ihs::fusion
