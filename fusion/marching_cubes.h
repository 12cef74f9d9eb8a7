#pragma once
// Marching cubes (Lorensen & Cline 1987) over a lattice of samples, with the case tables PCL
// ships (Bourke's: neighbouring cells split an ambiguous face alike, so a closed zero set gives
// a closed mesh). The lattice is read through a callback, so the TSDF's voxels and a plain grid
// of floats mesh with the same code.

#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include "core/triangle_mesh.h"

namespace ihs::fusion {
namespace marching_cubes {

/// Cell corners as lattice offsets, and cell edges as corner pairs, in the tables' order.
inline constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                      {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
inline constexpr int kEdge[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                     {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
/// The edges the zero set crosses in a cell whose case is `case_index` (bit c set: corner c is
/// negative), one bit per edge.
int EdgeMask(int case_index);
/// The case's triangles as edge indices, three per triangle, ended by −1.
const int* Triangles(int case_index);

}  // namespace marching_cubes

/// A lattice point (i, j, k).
using LatticePoint = std::array<int, 3>;

/// The zero set of the samples on an `size[0]`×`size[1]`×`size[2]` lattice, negative inside.
/// `value(i, j, k, &v)` reads a sample and returns false where there is none (cells with such a
/// corner are skipped). `add_vertex(a, b, s)` adds the vertex at the fraction `s` of the way
/// from lattice point `a` to `b` (the caller places and colours it) and returns its index; each
/// lattice edge gets one vertex, shared by the cells around it. The faces are appended to
/// `faces`, counter-clockwise seen from the positive side (outward normals).
template <typename ValueFn, typename VertexFn>
void MarchingCubes(const LatticePoint& size, ValueFn&& value, VertexFn&& add_vertex,
                   std::vector<TriangleMesh::Face>* faces) {
  using marching_cubes::kCorner;
  using marching_cubes::kEdge;
  std::unordered_map<std::int64_t, std::int32_t> vertex_of_edge;
  auto key = [&](int i, int j, int k, int axis) {
    return ((static_cast<std::int64_t>(k) * size[1] + j) * size[0] + i) * 3 + axis;
  };
  for (int k = 0; k + 1 < size[2]; ++k) {
    for (int j = 0; j + 1 < size[1]; ++j) {
      for (int i = 0; i + 1 < size[0]; ++i) {
        float sample[8];
        int case_index = 0;
        bool observed = true;
        for (int c = 0; c < 8 && observed; ++c) {
          observed = value(i + kCorner[c][0], j + kCorner[c][1], k + kCorner[c][2], &sample[c]);
          if (sample[c] < 0) case_index |= 1 << c;
        }
        const int edges = observed ? marching_cubes::EdgeMask(case_index) : 0;
        if (edges == 0) continue;
        std::int32_t edge_vertex[12];
        for (int e = 0; e < 12; ++e) {
          if (!(edges & (1 << e))) continue;
          const int a = kEdge[e][0], b = kEdge[e][1];
          int axis = 0;
          while (kCorner[a][axis] == kCorner[b][axis]) ++axis;
          // The edge's key: its lower lattice point and its axis.
          const std::int64_t edge_key = key(i + std::min(kCorner[a][0], kCorner[b][0]),
                                            j + std::min(kCorner[a][1], kCorner[b][1]),
                                            k + std::min(kCorner[a][2], kCorner[b][2]), axis);
          const auto found = vertex_of_edge.find(edge_key);
          if (found != vertex_of_edge.end()) {
            edge_vertex[e] = found->second;
            continue;
          }
          const LatticePoint pa = {i + kCorner[a][0], j + kCorner[a][1], k + kCorner[a][2]};
          const LatticePoint pb = {i + kCorner[b][0], j + kCorner[b][1], k + kCorner[b][2]};
          edge_vertex[e] = add_vertex(pa, pb, sample[a] / (sample[a] - sample[b]));
          vertex_of_edge.emplace(edge_key, edge_vertex[e]);
        }
        const int* triangles = marching_cubes::Triangles(case_index);
        for (int t = 0; triangles[t] != -1; t += 3) {
          // The tables wind clockwise seen from the positive side: reversed.
          faces->push_back({edge_vertex[triangles[t]], edge_vertex[triangles[t + 2]],
                            edge_vertex[triangles[t + 1]]});
        }
      }
    }
  }
}

}  // namespace ihs::fusion
