#pragma once
// Small closed meshes with known geometry for tests.

#include <utility>
#include <vector>

#include "core/triangle_mesh.h"

namespace ihs::test {

/// An axis-aligned cube of edge `edge_mm` centred at the origin: 8 vertices, 12 outward faces.
TriangleMesh MakeCube(float edge_mm);

/// A closed UV sphere of radius `radius_mm` centred at `center`: `rings` latitude bands and
/// `segments` longitudes, outward faces, unit normals.
TriangleMesh MakeUvSphere(float radius_mm, int rings, int segments,
                          const Eigen::Vector3f& center = Eigen::Vector3f::Zero());

/// A surface of revolution about z through the (z, radius) pairs of `profile`, from the bottom
/// up, with `segments` longitudes and outward faces: a pair of radius 0 is a pole; open where
/// an end's radius is not 0 (closed when both ends are poles).
TriangleMesh MakeLathe(const std::vector<std::pair<float, float>>& profile, int segments);

/// `a` and `b` moved by `shift` as one mesh of two parts (without normals).
TriangleMesh MergeMeshes(TriangleMesh a, const TriangleMesh& b, const Eigen::Vector3f& shift);

}  // namespace ihs::test
