#include "core/triangle_mesh.h"

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <unordered_map>

#include "core/errors.h"

namespace ihs {

void TriangleMesh::Check() const {
  const size_t n = vertices.size();
  if (!normals.empty() && normals.size() != n) {
    throw InputError("mesh has " + std::to_string(normals.size()) + " normals for " +
                     std::to_string(n) + " vertices");
  }
  if (!colors.empty() && colors.size() != n) {
    throw InputError("mesh has " + std::to_string(colors.size()) + " colours for " +
                     std::to_string(n) + " vertices");
  }
  for (size_t i = 0; i < n; ++i) {
    if (!vertices[i].allFinite()) {
      throw InputError("mesh vertex " + std::to_string(i) + " has a non-finite coordinate");
    }
  }
  for (size_t i = 0; i < normals.size(); ++i) {
    if (!normals[i].allFinite()) {
      throw InputError("mesh normal " + std::to_string(i) + " is not finite");
    }
  }
  for (size_t f = 0; f < faces.size(); ++f) {
    for (std::int32_t index : faces[f]) {
      if (index < 0 || static_cast<size_t>(index) >= n) {
        throw InputError("mesh face " + std::to_string(f) + " refers to vertex " +
                         std::to_string(index) + " of " + std::to_string(n));
      }
    }
  }
}

void TriangleMesh::ComputeVertexNormals() {
  std::vector<Eigen::Vector3f> sums(vertices.size(), Eigen::Vector3f::Zero());
  for (const Face& face : faces) {
    const Eigen::Vector3f& a = vertices[face[0]];
    // The cross product's length is twice the area: larger faces weigh more.
    const Eigen::Vector3f area_normal = (vertices[face[1]] - a).cross(vertices[face[2]] - a);
    for (std::int32_t index : face) sums[index] += area_normal;
  }
  normals.resize(vertices.size());
  for (size_t i = 0; i < sums.size(); ++i) {
    const float length = sums[i].norm();
    normals[i] = length > 0 ? Eigen::Vector3f(sums[i] / length) : Eigen::Vector3f::Zero();
  }
}

std::pair<Eigen::Vector3f, Eigen::Vector3f> TriangleMesh::Bounds() const {
  if (vertices.empty()) return {Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
  Eigen::Vector3f lo = vertices.front(), hi = vertices.front();
  for (const Eigen::Vector3f& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  return {lo, hi};
}

double TriangleMesh::SurfaceArea() const {
  double area = 0;
  for (const Face& face : faces) {
    const Eigen::Vector3d a = vertices[face[0]].cast<double>();
    area +=
        0.5 *
        (vertices[face[1]].cast<double>() - a).cross(vertices[face[2]].cast<double>() - a).norm();
  }
  return area;
}

double TriangleMesh::Volume() const {
  double six_volume = 0;
  for (const Face& face : faces) {
    six_volume += vertices[face[0]].cast<double>().dot(
        vertices[face[1]].cast<double>().cross(vertices[face[2]].cast<double>()));
  }
  return six_volume / 6.0;
}

bool TriangleMesh::IsWatertight() const {
  if (faces.empty()) return false;
  // Each directed edge must occur once, and its reverse once.
  std::unordered_map<std::uint64_t, int> directed;
  directed.reserve(faces.size() * 3);
  auto key = [](std::int32_t from, std::int32_t to) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(from)) << 32) |
           static_cast<std::uint32_t>(to);
  };
  for (const Face& face : faces) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = face[k], b = face[(k + 1) % 3];
      if (a == b) return false;
      if (++directed[key(a, b)] > 1) return false;
    }
  }
  for (const auto& [edge, count] : directed) {
    const auto from = static_cast<std::int32_t>(edge >> 32);
    const auto to = static_cast<std::int32_t>(edge & 0xffffffffu);
    if (directed.find(key(to, from)) == directed.end()) return false;
  }
  return true;
}

}  // namespace ihs
