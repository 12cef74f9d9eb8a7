#pragma once
// Small closed meshes with known geometry for tests.

#include "core/triangle_mesh.h"

namespace ihs::test {

/// An axis-aligned cube of edge `edge_mm` centred at the origin: 8 vertices, 12 outward faces.
TriangleMesh MakeCube(float edge_mm);

/// A closed UV sphere of radius `radius_mm` centred at `center`: `rings` latitude bands and
/// `segments` longitudes, outward faces, unit normals.
TriangleMesh MakeUvSphere(float radius_mm, int rings, int segments,
                          const Eigen::Vector3f& center = Eigen::Vector3f::Zero());

/// `a` and `b` moved by `shift` as one mesh of two parts (without normals).
TriangleMesh MergeMeshes(TriangleMesh a, const TriangleMesh& b, const Eigen::Vector3f& shift);

}  // namespace ihs::test
