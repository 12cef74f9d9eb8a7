#pragma once
// An indexed triangle mesh in millimetres, with optional per-vertex normals and colours.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace ihs {

/// Triangles over a shared vertex list. Faces are counter-clockwise seen from outside, so that
/// normals point outwards. `normals` and `colors` are either empty or one per vertex.
struct TriangleMesh {
  using Color = std::array<std::uint8_t, 3>;
  using Face = std::array<std::int32_t, 3>;

  /// Vertex positions, mm.
  std::vector<Eigen::Vector3f> vertices;
  /// Unit vertex normals (empty or one per vertex).
  std::vector<Eigen::Vector3f> normals;
  /// RGB8 vertex colours (empty or one per vertex).
  std::vector<Color> colors;
  /// Triangles as vertex indices.
  std::vector<Face> faces;

  bool HasNormals() const { return !normals.empty(); }
  bool HasColors() const { return !colors.empty(); }
  bool Empty() const { return vertices.empty(); }

  /// Throws ihs::InputError describing the first inconsistency: attribute counts that differ
  /// from the vertex count, a face index out of range, or a non-finite coordinate or normal.
  void Check() const;

  /// Sets `normals` to area-weighted averages of the adjacent face normals.
  void ComputeVertexNormals();

  /// Axis-aligned bounds (min, max), mm; both zero for an empty mesh.
  std::pair<Eigen::Vector3f, Eigen::Vector3f> Bounds() const;
  /// Total triangle area, mm².
  double SurfaceArea() const;
  /// Enclosed volume (mm³) by the divergence theorem: exact for a closed, consistently oriented
  /// mesh, meaningless otherwise (see IsWatertight).
  double Volume() const;
  /// Whether every edge is shared by exactly two faces that traverse it in opposite directions
  /// (closed, edge-manifold, consistently oriented).
  bool IsWatertight() const;
};

}  // namespace ihs
