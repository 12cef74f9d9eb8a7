#include "tests/mesh_fixtures.h"

#include <cmath>

namespace ihs::test {

TriangleMesh MakeCube(float edge_mm) {
  const float h = edge_mm / 2;
  TriangleMesh mesh;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back(i & 1 ? h : -h, i & 2 ? h : -h, i & 4 ? h : -h);
  }
  // Two triangles per side, counter-clockwise seen from outside.
  mesh.faces = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return mesh;
}

TriangleMesh MakeUvSphere(float radius_mm, int rings, int segments, const Eigen::Vector3f& center) {
  TriangleMesh mesh;
  mesh.vertices.push_back(center + Eigen::Vector3f(0, 0, radius_mm));  // North pole.
  for (int r = 1; r < rings; ++r) {
    const double theta = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.vertices.push_back(center + radius_mm * Eigen::Vector3f(std::sin(theta) * std::cos(phi),
                                                                   std::sin(theta) * std::sin(phi),
                                                                   std::cos(theta)));
    }
  }
  mesh.vertices.push_back(center - Eigen::Vector3f(0, 0, radius_mm));  // South pole.
  const int south = static_cast<int>(mesh.vertices.size()) - 1;
  auto ring_vertex = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) {
    mesh.faces.push_back({0, ring_vertex(1, s), ring_vertex(1, s + 1)});
    mesh.faces.push_back({south, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s)});
    for (int r = 1; r + 1 < rings; ++r) {
      mesh.faces.push_back({ring_vertex(r, s), ring_vertex(r + 1, s), ring_vertex(r + 1, s + 1)});
      mesh.faces.push_back({ring_vertex(r, s), ring_vertex(r + 1, s + 1), ring_vertex(r, s + 1)});
    }
  }
  for (const Eigen::Vector3f& v : mesh.vertices) mesh.normals.push_back((v - center).normalized());
  return mesh;
}

TriangleMesh MakeLathe(const std::vector<std::pair<float, float>>& profile, int segments) {
  TriangleMesh mesh;
  std::vector<int> first;  // Each ring's first vertex; a pole has one.
  for (const auto& [z, radius] : profile) {
    first.push_back(static_cast<int>(mesh.vertices.size()));
    const int count = radius > 0 ? segments : 1;
    for (int s = 0; s < count; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.vertices.emplace_back(radius * std::cos(phi), radius * std::sin(phi), z);
    }
  }
  auto vertex = [&](size_t ring, int s) {
    return profile[ring].second > 0 ? first[ring] + s % segments : first[ring];
  };
  for (size_t ring = 0; ring + 1 < profile.size(); ++ring) {
    for (int s = 0; s < segments; ++s) {
      // Counter-clockwise about z from below to above: outward.
      const int a0 = vertex(ring, s), a1 = vertex(ring, s + 1);
      const int b0 = vertex(ring + 1, s), b1 = vertex(ring + 1, s + 1);
      if (a0 != a1) mesh.faces.push_back({a0, a1, b0});
      if (b0 != b1) mesh.faces.push_back({a1, b1, b0});
    }
  }
  return mesh;
}

TriangleMesh MergeMeshes(TriangleMesh a, const TriangleMesh& b, const Eigen::Vector3f& shift) {
  const auto offset = static_cast<std::int32_t>(a.vertices.size());
  for (const Eigen::Vector3f& v : b.vertices) a.vertices.push_back(v + shift);
  for (const TriangleMesh::Face& f : b.faces) {
    a.faces.push_back({f[0] + offset, f[1] + offset, f[2] + offset});
  }
  a.normals.clear();
  return a;
}

}  // namespace ihs::test
