#pragma once
// The closure cut back to the evidence: a closed mesh (Poisson's guess over what no frame saw)
// without the space the camera saw through (free_space.h) and, optionally, without what lies
// beyond the convex hull of the surface frames saw (convex_hull.h: where no view looked, e.g.
// under a bottle's base, Poisson bulges past the object and no ray saw that space empty).
// Inside the result means inside the closed mesh, not seen empty and inside the seen surface's
// hull; the surface frames saw is never cut. The result is remeshed by marching cubes over a
// lattice holding the largest of the closed mesh's signed distance, the emptiness and the
// hull's signed distance (the intersection of the insides).

#include "core/triangle_mesh.h"
#include "fusion/free_space.h"

namespace ihs::fusion {

/// How BoundClosure cuts (MeshingOptions holds the user's choices).
struct ClosureBoundOptions {
  /// Lattice step, mm (coarser when the closed mesh is so large that the lattice would pass 16
  /// million points: a scene rather than a held object).
  double voxel_mm = 1.0;
  /// Nothing within this distance (mm) of the seen surface's vertices is cut for the views'
  /// emptiness (misregistered views may have seen through it).
  double keep_seen_mm = 2.0;
  /// Also cut what lies outside the convex hull of the seen surface's vertices.
  bool seen_hull = true;
  /// When the seen surface is a body of revolution (MeasureRevolution: its sections fit circles
  /// within this share of their radius, RMS), the hull is that of the surface turned all round
  /// its axis (RevolvedEnvelope): what was not seen of its round side is not cut, only its
  /// unseen ends (0: never).
  double revolve_max_residual = 0.03;
  /// Otherwise, when at least this share of the seen surface faces along three orthogonal
  /// directions (MeasureBox: a box's faces, seen from anywhere, 0.89-0.96; bottles, pins and
  /// spheres 0.10-0.36), the hull is the box along those directions that holds the seen
  /// surface: a box seen from one side shows its extent along each of its axes (its faces'
  /// widths), but not the corner behind it that the plain hull would cut off (0: never).
  double box_min_face_share = 0.8;
  /// The box leaves out this share of the seen surface's vertices beyond each of its six faces
  /// (MeasureExtent): what the box then cuts off the seen surface is a few vertices proud of a
  /// face — the hand's edge or a finger fused with the object — not the box.
  double box_outlier_share = 0.005;
  /// Pieces with fewer faces than this share of the largest one's are dropped (a cut may leave
  /// crumbs).
  double min_component_fraction = 0.05;
};

/// Of what the closure's hull was taken (ClosureBoundOptions).
enum class HullShape { kSeen, kRevolved, kBox };

/// What BoundClosure did.
struct ClosureBound {
  /// The bounded closed mesh: the input itself when nothing was cut.
  TriangleMesh mesh;
  /// Whether anything was cut.
  bool changed = false;
  /// Share of the closed mesh's volume that was cut (0 when unchanged).
  double removed_share = 0;
  /// Share of the closed mesh's volume cut because it lay outside the seen surface's hull (more
  /// than it lay in empty space; counted on the lattice).
  double hull_share = 0;
  /// Planes of the seen surface's hull (0: no hull: off, or a seen surface without volume).
  int hull_planes = 0;
  /// The seen surface's own hull, its revolution's about its axis or its box's.
  HullShape hull_shape = HullShape::kSeen;
};

/// The surface that bounds what `closed` (closed and oriented, mm) encloses — the points its
/// faces wind round (a winding number not zero), the union of parts that overlap — as the zero
/// set of its signed distance on a lattice of step `voxel_mm`, by marching cubes: a closed mesh
/// that folds through itself (Poisson's, now and then) re-made without crossing faces, its
/// colours from the nearest vertex of `closed`; pieces under `min_component_fraction` of the
/// largest dropped.
TriangleMesh RemeshClosed(const TriangleMesh& closed, double voxel_mm,
                          double min_component_fraction);

/// `closed` (watertight, object frame, mm) without the space `free_space` saw empty, except
/// within `options.keep_seen_mm` of the vertices of `seen` (the surface frames saw), and, with
/// `options.seen_hull`, without what lies outside the convex hull of those vertices (or of their
/// revolution; `seen` lies inside it and is never cut); remeshed on the lattice when anything is
/// cut. Colours come from the nearest vertex of `closed`.
ClosureBound BoundClosure(const TriangleMesh& closed, const TriangleMesh& seen,
                          const FreeSpace& free_space, const ClosureBoundOptions& options);

}  // namespace ihs::fusion
