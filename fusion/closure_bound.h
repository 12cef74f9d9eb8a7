#pragma once
// The closure cut back to the evidence: a closed mesh (Poisson's guess over what no frame saw)
// without the space the camera saw through (free_space.h). Inside the result means inside the
// closed mesh and not seen empty; the surface frames saw is never cut. The result is remeshed
// by marching cubes over a lattice holding the larger of the closed mesh's signed distance and
// the emptiness (the intersection of the two insides).

#include "core/triangle_mesh.h"
#include "fusion/free_space.h"

namespace ihs::fusion {

/// What BoundByFreeSpace did.
struct ClosureBound {
  /// The bounded closed mesh: the input itself when nothing inside it was seen empty.
  TriangleMesh mesh;
  /// Whether anything was cut.
  bool changed = false;
  /// Share of the closed mesh's volume that was cut (0 when unchanged).
  double removed_share = 0;
};

/// `closed` (watertight, object frame, mm) without the space `free_space` saw empty, except
/// within `keep_seen_mm` of the vertices of `seen` (the surface frames saw), remeshed on a
/// lattice of `voxel_mm` when anything is cut (coarser when the closed mesh is so large that
/// the lattice would pass 16 million points: a scene rather than a held object); colours come from the nearest vertex of
/// `closed`. Pieces with fewer faces than `min_component_fraction` of the largest one's are
/// dropped (a cut may leave crumbs).
ClosureBound BoundByFreeSpace(const TriangleMesh& closed, const TriangleMesh& seen,
                              const FreeSpace& free_space, double voxel_mm, double keep_seen_mm,
                              double min_component_fraction);

}  // namespace ihs::fusion
