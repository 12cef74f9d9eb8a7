#include "fusion/closure_bound.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "core/check.h"
#include "core/point_kd_tree.h"
#include "fusion/convex_hull.h"
#include "fusion/marching_cubes.h"
#include "fusion/measure.h"
#include "fusion/surface_mesh.h"
#include "fusion/triangle_cover.h"

namespace ihs::fusion {
namespace {

// The most lattice points a bound uses (a 250 mm cube at 1 mm).
constexpr double kMaxLatticePoints = 16e6;

// A lattice of points `step` apart from `origin`.
struct Lattice {
  Eigen::Vector3f origin;
  float step = 1;
  LatticePoint size = {0, 0, 0};

  std::int64_t Index(int i, int j, int k) const {
    return (static_cast<std::int64_t>(k) * size[1] + j) * size[0] + i;
  }
  std::int64_t Count() const { return Index(0, 0, size[2]); }
  // The point of index `n`.
  Eigen::Vector3f Point(std::int64_t n) const {
    const auto [i, j, k] = Coordinates(n);
    return Point(i, j, k);
  }
  std::array<int, 3> Coordinates(std::int64_t n) const {
    const int i = static_cast<int>(n % size[0]);
    const int j = static_cast<int>((n / size[0]) % size[1]);
    return {i, j, static_cast<int>(n / (static_cast<std::int64_t>(size[0]) * size[1]))};
  }
  // The indices of the six neighbours of point `n` (−1 past the lattice's faces).
  std::array<std::int64_t, 6> Neighbours(std::int64_t n) const {
    const auto [i, j, k] = Coordinates(n);
    const std::int64_t row = size[0], slice = static_cast<std::int64_t>(size[0]) * size[1];
    return {i > 0 ? n - 1 : -1,     i + 1 < size[0] ? n + 1 : -1,
            j > 0 ? n - row : -1,   j + 1 < size[1] ? n + row : -1,
            k > 0 ? n - slice : -1, k + 1 < size[2] ? n + slice : -1};
  }
  Eigen::Vector3f Point(int i, int j, int k) const {
    return origin + step * Eigen::Vector3f(static_cast<float>(i), static_cast<float>(j),
                                           static_cast<float>(k));
  }
  // The lattice range [lo, hi] of coordinate `axis` covering [a, b], clamped.
  void Range(int axis, float a, float b, int* lo, int* hi) const {
    *lo = std::max(0, static_cast<int>(std::ceil((a - origin[axis]) / step)));
    *hi = std::min(size[axis] - 1, static_cast<int>(std::floor((b - origin[axis]) / step)));
  }
};

// Squared distance from p to triangle abc (closest point by the triangle's Voronoi regions,
// as in Ericson's Real-Time Collision Detection, 5.1.5).
float DistanceSqToTriangle(const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                           const Eigen::Vector3f& b, const Eigen::Vector3f& c) {
  const Eigen::Vector3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();
  const Eigen::Vector3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (ap - d1 / (d1 - d3) * ab).squaredNorm();
  const Eigen::Vector3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (ap - d2 / (d2 - d6) * ac).squaredNorm();
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return (bp - (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b)).squaredNorm();
  }
  const float denominator = 1.0f / (va + vb + vc);
  return (ap - (vb * denominator) * ab - (vc * denominator) * ac).squaredNorm();
}

// Per lattice point: −1 inside `mesh` (closed, oriented), +1 outside, by the winding number
// along z below the point: each face crossed facing down counts +1, facing up −1, and a point
// is inside where the sum is not zero (whichever way the faces are oriented). Without
// self-intersections that is the parity of the crossings; where parts of the mesh overlap or
// fold through each other, the inside is their union (parity would hollow out the overlap).
std::vector<std::int8_t> InsideSign(const TriangleMesh& mesh, const Lattice& lattice) {
  // Per column: (height, +1 entering or −1 leaving) of each face crossed.
  std::vector<std::vector<std::pair<float, int>>> crossings(static_cast<size_t>(lattice.size[0]) *
                                                            lattice.size[1]);
  for (const auto& face : mesh.faces) {
    Eigen::Vector3d corner[3];
    for (int c = 0; c < 3; ++c) corner[c] = mesh.vertices[face[c]].cast<double>();
    Eigen::Vector2d q[3] = {corner[0].head<2>(), corner[1].head<2>(), corner[2].head<2>()};
    double area = TwiceSignedArea(q);
    if (area == 0) continue;  // Seen edge-on from z: no column crosses it alone.
    // Counter-clockwise from above: the face's normal points up (a way out going up).
    const int winding = area > 0 ? -1 : 1;
    if (area < 0) {
      std::swap(q[1], q[2]);
      std::swap(corner[1], corner[2]);
      area = -area;
    }
    int i0, i1, j0, j1;
    lattice.Range(0, static_cast<float>(std::min({q[0].x(), q[1].x(), q[2].x()})),
                  static_cast<float>(std::max({q[0].x(), q[1].x(), q[2].x()})), &i0, &i1);
    lattice.Range(1, static_cast<float>(std::min({q[0].y(), q[1].y(), q[2].y()})),
                  static_cast<float>(std::max({q[0].y(), q[1].y(), q[2].y()})), &j0, &j1);
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const Eigen::Vector2d p = lattice.Point(i, j, 0).head<2>().cast<double>();
        double w[3];
        if (!CoversPoint(q, p, w)) continue;
        const double z =
            (w[0] * corner[0].z() + w[1] * corner[1].z() + w[2] * corner[2].z()) / area;
        crossings[static_cast<size_t>(j) * lattice.size[0] + i].emplace_back(static_cast<float>(z),
                                                                             winding);
      }
    }
  }
  std::vector<std::int8_t> sign(static_cast<size_t>(lattice.Count()), 1);
  for (int j = 0; j < lattice.size[1]; ++j) {
    for (int i = 0; i < lattice.size[0]; ++i) {
      auto& column = crossings[static_cast<size_t>(j) * lattice.size[0] + i];
      std::sort(column.begin(), column.end());
      size_t below = 0;
      int winding = 0;
      for (int k = 0; k < lattice.size[2]; ++k) {
        const float z = lattice.Point(i, j, k).z();
        for (; below < column.size() && column[below].first < z; ++below)
          winding += column[below].second;
        if (winding != 0) sign[lattice.Index(i, j, k)] = -1;
      }
    }
  }
  return sign;
}

// The signed distance to `mesh` (negative inside) at every lattice point, its magnitude
// clamped to `band`.
std::vector<float> SignedDistance(const TriangleMesh& mesh, const Lattice& lattice, float band) {
  std::vector<float> distance(static_cast<size_t>(lattice.Count()), band * band);
  for (const auto& face : mesh.faces) {
    const Eigen::Vector3f& a = mesh.vertices[face[0]];
    const Eigen::Vector3f& b = mesh.vertices[face[1]];
    const Eigen::Vector3f& c = mesh.vertices[face[2]];
    const Eigen::Vector3f lo = a.cwiseMin(b).cwiseMin(c).array() - band;
    const Eigen::Vector3f hi = a.cwiseMax(b).cwiseMax(c).array() + band;
    int range[3][2];
    for (int axis = 0; axis < 3; ++axis) {
      lattice.Range(axis, lo[axis], hi[axis], &range[axis][0], &range[axis][1]);
    }
    for (int k = range[2][0]; k <= range[2][1]; ++k) {
      for (int j = range[1][0]; j <= range[1][1]; ++j) {
        for (int i = range[0][0]; i <= range[0][1]; ++i) {
          float& d = distance[lattice.Index(i, j, k)];
          d = std::min(d, DistanceSqToTriangle(lattice.Point(i, j, k), a, b, c));
        }
      }
    }
  }
  // A point on a face is not zero but a hair to its side: where faces lie inside what the mesh
  // encloses (overlapping parts), a zero there would start a surface of its own.
  const float hair = 1e-3f * lattice.step;
  const std::vector<std::int8_t> sign = InsideSign(mesh, lattice);
  for (size_t n = 0; n < distance.size(); ++n)
    distance[n] = sign[n] * std::max(hair, std::sqrt(distance[n]));
  return distance;
}

// A lattice over `closed` with two steps of room on every side (all outside), of step `step`
// or coarser for a closed mesh so large (a scene, not a held object) that the lattice would pass
// kMaxLatticePoints (about 100 MB of lattice).
Lattice LatticeAround(const TriangleMesh& closed, float step) {
  Eigen::Vector3f lo = closed.vertices[0], hi = closed.vertices[0];
  for (const auto& v : closed.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  Lattice lattice;
  const double box_volume = static_cast<double>((hi - lo).array().prod());
  lattice.step = std::max(step, static_cast<float>(std::cbrt(box_volume / kMaxLatticePoints)));
  lattice.origin = lo.array() - 2 * lattice.step;
  for (int axis = 0; axis < 3; ++axis) {
    lattice.size[axis] = static_cast<int>(std::ceil((hi[axis] - lo[axis]) / lattice.step)) + 5;
  }
  return lattice;
}

// What says a point is outside the object: the views' emptiness (except near the seen surface)
// and the seen surface's hull.
class Evidence {
 public:
  Evidence(const TriangleMesh& seen, const FreeSpace& free_space, const ConvexHull& hull,
           double keep_seen_mm)
      : seen_(seen),
        tree_(seen.vertices),
        free_space_(free_space),
        hull_(hull),
        keep_sq_(static_cast<float>(keep_seen_mm * keep_seen_mm)) {}

  bool Any() const { return free_space_.views() > 0 || !hull_.Empty(); }
  // How deep `point` lies in seen-empty space (−limit without views).
  float Emptiness(const Eigen::Vector3f& point, float limit) const {
    return free_space_.views() > 0 ? free_space_.Emptiness(point, limit) : -limit;
  }
  std::vector<float> Emptiness(const std::vector<Eigen::Vector3f>& points, float limit) const {
    if (free_space_.views() == 0) return std::vector<float>(points.size(), -limit);
    return free_space_.Emptiness(points, limit);
  }
  // How far `point` lies outside the object by the evidence, clamped to `limit`: the larger of
  // its distance outside the hull (`by_hull`) and `emptiness` (read off the views), which counts
  // only where it passes `floor` and not near the seen surface (a misregistered view may have
  // seen through it; the seen surface lies inside its hull, which needs no such care).
  float Outside(const Eigen::Vector3f& point, float emptiness, float floor, float limit,
                bool* by_hull) const {
    const float outside_hull = hull_.Empty() ? -limit : hull_.SignedDistance(point, limit);
    *by_hull = !(emptiness > std::max(outside_hull, floor) && !NearSeen(point));
    return *by_hull ? outside_hull : emptiness;
  }

 private:
  bool NearSeen(const Eigen::Vector3f& point) const {
    float distance_sq = 0;
    return !seen_.vertices.empty() && tree_.Nearest(point, &distance_sq) >= 0 &&
           distance_sq < keep_sq_;
  }

  const TriangleMesh& seen_;
  const PointKdTree tree_;
  const FreeSpace& free_space_;
  const ConvexHull& hull_;
  const float keep_sq_;
};

// What Carve cut: whether any point inside the closed mesh went, and how many of those went
// for lying outside the hull (more than in empty space).
struct Carving {
  bool cut_inside = false;
  std::int64_t hull_points = 0;
};

// Points inside (or next to) the closed mesh that the evidence puts outside move outside: the
// field takes the evidence where larger. Carved from the outside in: first the points next to
// the surface, then the inside neighbours of those found outside, and so on (space seen empty
// inside the mesh was seen through its surface, and what lies outside a convex hull reaches
// the closed mesh's surface; a deep inside that no such path reaches is never evaluated, which
// keeps a large object's export fast).
Carving Carve(const Lattice& lattice, const Evidence& evidence, float band,
              std::vector<float>* field) {
  std::vector<std::uint8_t> visited(field->size(), 0);
  std::vector<std::int64_t> frontier;
  for (std::int64_t n = 0; n < lattice.Count(); ++n) {
    if (std::abs((*field)[n]) < band) {
      frontier.push_back(n);
      visited[n] = 1;
    }
  }
  Carving carving;
  std::vector<Eigen::Vector3f> points;
  while (!frontier.empty()) {
    points.clear();
    for (const std::int64_t n : frontier) points.push_back(lattice.Point(n));
    const std::vector<float> emptiness = evidence.Emptiness(points, band);
    std::vector<std::int64_t> next;
    for (size_t f = 0; f < frontier.size(); ++f) {
      float& value = (*field)[frontier[f]];
      bool by_hull = false;
      const float outside = evidence.Outside(points[f], emptiness[f], value, band, &by_hull);
      if (outside <= value) continue;
      if (value < 0 && outside > 0) {
        carving.cut_inside = true;
        if (by_hull) ++carving.hull_points;
      }
      value = outside;
      if (outside <= 0) continue;
      for (const std::int64_t neighbour : lattice.Neighbours(frontier[f])) {
        if (neighbour < 0 || visited[neighbour] || (*field)[neighbour] >= band) continue;
        visited[neighbour] = 1;
        next.push_back(neighbour);
      }
    }
    frontier = std::move(next);
  }
  return carving;
}

// The zero set of `field` on `lattice` by marching cubes, without crumbs, with the colours of
// the nearest vertex of `closed`.
TriangleMesh Remesh(const Lattice& lattice, const std::vector<float>& field,
                    const TriangleMesh& closed, double min_component_fraction) {
  TriangleMesh mesh;
  auto value = [&](int i, int j, int k, float* sample) {
    *sample = field[lattice.Index(i, j, k)];
    return true;
  };
  auto add_vertex = [&](const LatticePoint& a, const LatticePoint& b, float s) {
    const Eigen::Vector3f pa = lattice.Point(a[0], a[1], a[2]);
    const Eigen::Vector3f pb = lattice.Point(b[0], b[1], b[2]);
    mesh.vertices.push_back(pa + s * (pb - pa));
    return static_cast<std::int32_t>(mesh.vertices.size() - 1);
  };
  MarchingCubes(lattice.size, value, add_vertex, &mesh.faces);
  mesh = RemoveSmallComponents(mesh, min_component_fraction);
  mesh.ComputeVertexNormals();
  if (closed.HasColors() && !mesh.Empty()) {
    const PointKdTree tree(closed.vertices);
    mesh.colors.resize(mesh.vertices.size());
    for (size_t n = 0; n < mesh.vertices.size(); ++n) {
      float distance_sq = 0;
      mesh.colors[n] = closed.colors[tree.Nearest(mesh.vertices[n], &distance_sq)];
    }
  }
  return mesh;
}

// The eight corners of the box along `axes` (orthonormal columns) that holds `points` but
// `outlier_share` of them beyond each face.
std::vector<Eigen::Vector3f> BoxCorners(const std::vector<Eigen::Vector3f>& points,
                                        const Eigen::Matrix3d& axes, double outlier_share) {
  const BoxExtent extent = MeasureExtent(points, axes, outlier_share);
  const Eigen::Vector3d &low = extent.low, &high = extent.high;
  std::vector<Eigen::Vector3f> corners;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d along((k & 1) ? high.x() : low.x(), (k & 2) ? high.y() : low.y(),
                                (k & 4) ? high.z() : low.z());
    corners.push_back((axes * along).cast<float>());
  }
  return corners;
}

// The convex hull of `seen`'s vertices; of their revolution about its axis when `seen` is a
// body of revolution; of the box along its faces when it is a box's (`shape` says which); faces
// within `merge_mm` of coplanar merged. A seen surface without volume (flat) has no hull.
ConvexHull SeenHull(const TriangleMesh& seen, const ClosureBoundOptions& options, double merge_mm,
                    HullShape* shape) {
  *shape = HullShape::kSeen;
  ConvexHull hull = ConvexHull::Of(seen.vertices, merge_mm);
  if (hull.Empty()) return hull;
  if (options.revolve_max_residual > 0) {
    const RevolutionMeasures round = MeasureRevolution(seen);
    // At least a few sections: the axis is a line through their centres.
    if (round.roundness_residual <= options.revolve_max_residual && round.profile.size() >= 3) {
      *shape = HullShape::kRevolved;
      return ConvexHull::Of(RevolvedEnvelope(seen.vertices, round.axis_point, round.axis, 2.0, 64),
                            merge_mm);
    }
  }
  if (options.box_min_face_share > 0) {
    const BoxMeasures box = MeasureBox(seen);
    if (box.face_share >= options.box_min_face_share) {
      *shape = HullShape::kBox;
      return ConvexHull::Of(BoxCorners(seen.vertices, box.axes, options.box_outlier_share),
                            merge_mm);
    }
  }
  return hull;
}

}  // namespace

TriangleMesh RemeshClosed(const TriangleMesh& closed, double voxel_mm,
                          double min_component_fraction) {
  IHS_CHECK_ARG(voxel_mm > 0, "the lattice's step must be positive, got " << voxel_mm);
  if (closed.faces.empty()) return closed;
  const Lattice lattice = LatticeAround(closed, static_cast<float>(voxel_mm));
  const std::vector<float> field = SignedDistance(closed, lattice, 1.5f * lattice.step);
  return Remesh(lattice, field, closed, min_component_fraction);
}

ClosureBound BoundClosure(const TriangleMesh& closed, const TriangleMesh& seen,
                          const FreeSpace& free_space, const ClosureBoundOptions& options) {
  IHS_CHECK_ARG(options.voxel_mm > 0,
                "the bound's voxel must be positive, got " << options.voxel_mm);
  ClosureBound result;
  result.mesh = closed;
  if (closed.faces.empty()) return result;
  const float step = static_cast<float>(options.voxel_mm);
  // Faces of the hull within a quarter step of coplanar merge: the lattice cannot place a cut
  // finer, and a noisy surface's hull has a thousand faces rather than a hundred.
  const ConvexHull hull =
      options.seen_hull ? SeenHull(seen, options, 0.25 * step, &result.hull_shape) : ConvexHull();
  result.hull_planes = hull.planes();
  const Evidence evidence(seen, free_space, hull, options.keep_seen_mm);
  if (!evidence.Any()) return result;
  // Space outside inside the closed mesh is reached through its surface: when none of its
  // vertices (away from the seen surface) lies deeper than a lattice step in it, nothing is cut
  // (a step is what the lattice could place a cut to).
  const bool any_outside = std::any_of(
      closed.vertices.begin(), closed.vertices.end(), [&](const Eigen::Vector3f& vertex) {
        bool by_hull = false;
        const float emptiness = evidence.Emptiness(vertex, 2 * step);
        return evidence.Outside(vertex, emptiness, step, 2 * step, &by_hull) > step;
      });
  if (!any_outside) return result;

  const Lattice lattice = LatticeAround(closed, step);
  // Distances beyond 1.5 steps never place a vertex; the evidence is clamped alike.
  const float band = 1.5f * lattice.step;
  std::vector<float> field = SignedDistance(closed, lattice, band);
  const Carving carving = Carve(lattice, evidence, band, &field);
  if (!carving.cut_inside) return result;

  TriangleMesh bounded = Remesh(lattice, field, closed, options.min_component_fraction);
  const double volume = closed.Volume();
  if (volume > 0) {
    result.removed_share = std::max(0.0, 1.0 - bounded.Volume() / volume);
    result.hull_share =
        std::min(result.removed_share, carving.hull_points * std::pow(lattice.step, 3.0) / volume);
  }
  result.mesh = std::move(bounded);
  result.changed = true;
  return result;
}

}  // namespace ihs::fusion
