#include "core/mesh_intersections.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace ihs {
namespace {

using Vec = Eigen::Vector3d;

// Six times the signed volume of (a, b, c, d): positive when d is on the side of abc its
// counter-clockwise normal points to.
double Orient(const Vec& a, const Vec& b, const Vec& c, const Vec& d) {
  return (b - a).cross(c - a).dot(d - a);
}

// Whether segment pq passes through triangle abc: p and q strictly on opposite sides of its
// plane, and the line pq within its three edges (on one counts: a crossing through the edge two
// faces share would otherwise be missed by both).
bool SegmentCrossesTriangle(const Vec& p, const Vec& q, const Vec& a, const Vec& b,
                            const Vec& c) {
  const double sp = Orient(a, b, c, p), sq = Orient(a, b, c, q);
  if (!((sp > 0 && sq < 0) || (sp < 0 && sq > 0))) return false;
  const double e0 = Orient(p, q, a, b), e1 = Orient(p, q, b, c), e2 = Orient(p, q, c, a);
  return (e0 >= 0 && e1 >= 0 && e2 >= 0 && (e0 > 0 || e1 > 0 || e2 > 0)) ||
         (e0 <= 0 && e1 <= 0 && e2 <= 0 && (e0 < 0 || e1 < 0 || e2 < 0));
}

struct FacePoints {
  std::array<Vec, 3> p;
};

// Whether faces f and g cross, given their vertex indices and points.
bool FacesCross(const TriangleMesh::Face& f, const FacePoints& fp, const TriangleMesh::Face& g,
                const FacePoints& gp) {
  int shared = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) shared += f[i] == g[j];
  if (shared >= 2) return false;  // Neighbours across an edge: they meet along it.
  // An edge of either through the other. With one shared vertex only the edges opposite it can
  // cross (an edge from the shared vertex leaves the other's plane there).
  for (int k = 0; k < 3; ++k) {
    const int a = k, b = (k + 1) % 3;
    const bool f_edge_free = shared == 0 || (std::find(g.begin(), g.end(), f[a]) == g.end() &&
                                             std::find(g.begin(), g.end(), f[b]) == g.end());
    if (f_edge_free && SegmentCrossesTriangle(fp.p[a], fp.p[b], gp.p[0], gp.p[1], gp.p[2]))
      return true;
    const bool g_edge_free = shared == 0 || (std::find(f.begin(), f.end(), g[a]) == f.end() &&
                                             std::find(f.begin(), f.end(), g[b]) == f.end());
    if (g_edge_free && SegmentCrossesTriangle(gp.p[a], gp.p[b], fp.p[0], fp.p[1], fp.p[2]))
      return true;
  }
  return false;
}

}  // namespace

SelfIntersections FindSelfIntersections(const TriangleMesh& mesh, int max_examples) {
  SelfIntersections found;
  const auto n = static_cast<std::int32_t>(mesh.faces.size());
  if (n < 2) return found;
  std::vector<FacePoints> points(n);
  std::vector<Vec> lo(n), hi(n);
  double extent_sum = 0;
  for (std::int32_t f = 0; f < n; ++f) {
    for (int k = 0; k < 3; ++k) points[f].p[k] = mesh.vertices[mesh.faces[f][k]].cast<double>();
    lo[f] = points[f].p[0].cwiseMin(points[f].p[1]).cwiseMin(points[f].p[2]);
    hi[f] = points[f].p[0].cwiseMax(points[f].p[1]).cwiseMax(points[f].p[2]);
    extent_sum += (hi[f] - lo[f]).maxCoeff();
  }
  const double cell = std::max(1e-6, 2.0 * extent_sum / n);
  auto cell_of = [&](const Vec& p) {
    return Eigen::Vector3i(static_cast<int>(std::floor(p.x() / cell)),
                           static_cast<int>(std::floor(p.y() / cell)),
                           static_cast<int>(std::floor(p.z() / cell)));
  };
  auto key = [](const Eigen::Vector3i& c) {
    return (static_cast<std::uint64_t>(c.x() & 0x1fffff) << 42) |
           (static_cast<std::uint64_t>(c.y() & 0x1fffff) << 21) |
           static_cast<std::uint64_t>(c.z() & 0x1fffff);
  };
  std::unordered_map<std::uint64_t, std::vector<std::int32_t>> grid;
  grid.reserve(static_cast<std::size_t>(n) * 2);
  for (std::int32_t f = 0; f < n; ++f) {
    const Eigen::Vector3i a = cell_of(lo[f]), b = cell_of(hi[f]);
    for (int x = a.x(); x <= b.x(); ++x)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int z = a.z(); z <= b.z(); ++z) grid[key({x, y, z})].push_back(f);
  }
  for (const auto& [cell_key, faces] : grid) {
    for (std::size_t i = 0; i < faces.size(); ++i) {
      for (std::size_t j = i + 1; j < faces.size(); ++j) {
        const std::int32_t f = std::min(faces[i], faces[j]), g = std::max(faces[i], faces[j]);
        const Vec overlap_lo = lo[f].cwiseMax(lo[g]), overlap_hi = hi[f].cwiseMin(hi[g]);
        if ((overlap_lo.array() > overlap_hi.array()).any()) continue;
        // A pair is looked at in the one cell that holds its boxes' overlap's low corner.
        if (key(cell_of(overlap_lo)) != cell_key) continue;
        if (!FacesCross(mesh.faces[f], points[f], mesh.faces[g], points[g])) continue;
        ++found.pairs;
        if (static_cast<int>(found.examples.size()) < max_examples) found.examples.emplace_back(f, g);
      }
    }
  }
  std::sort(found.examples.begin(), found.examples.end());
  return found;
}

bool IsWatertightWithoutSelfIntersections(const TriangleMesh& mesh) {
  return mesh.IsWatertight() && FindSelfIntersections(mesh, 0).pairs == 0;
}

}  // namespace ihs
