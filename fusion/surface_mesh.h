#pragma once
// From the TSDF's raw marching-cubes mesh to the mesh a user gets: small disconnected pieces
// dropped (stray hand or background blobs), HC Laplacian smoothing (Vollmer, Mencl & Müller
// 1999: Laplacian steps pulled back toward the original, so the shape does not shrink), and
// screened Poisson reconstruction (Kazhdan et al., through PCL) into a closed, watertight mesh
// with the colours carried over from the raw one.

#include <cstdint>

#include "core/triangle_mesh.h"
#include "fusion/closure_bound.h"
#include "fusion/free_space.h"

namespace ihs::fusion {

/// Options of the meshing steps.
struct MeshingOptions {
  /// Connected pieces with fewer faces than this share of the largest piece's are dropped.
  double min_component_fraction = 0.05;
  /// HC Laplacian smoothing iterations (0: none) and its two weights: alpha pulls each step
  /// toward the original position, beta spreads the pull-back over the neighbours (Vollmer et
  /// al. use 0 and 0.5).
  int smoothing_iterations = 3;
  double smoothing_alpha = 0.0;
  double smoothing_beta = 0.5;
  /// Poisson reconstruction into a watertight mesh (off: the smoothed mesh is the result).
  bool poisson = true;
  /// Poisson octree depth over the cube around the points (paper: 10). At 9 its cells are
  /// 0.1-1.0 mm over the cube of any object the default TSDF holds (350 mm at most, times
  /// `poisson_scale`): finer than the TSDF's 1.37 mm voxels, the finest detail the fused surface
  /// has; with `poisson_samples_per_node` the octree seldom goes deeper anyway. Depth 10 only
  /// adds PCL's B-spline tables for a level no data fills: 0.6-0.9 s of each export, for the
  /// same mesh.ply within 0.01 mm (Chamfer against the truth, 34 full turns) and 0.03 mm (Table
  /// 1, the four whole paper sessions; docs/fusion.md). A finer TSDF (fusion.tsdf.resolution
  /// 512) wants depth 10.
  int poisson_depth = 9;
  /// Minimum samples per octree node: larger smooths noisy data (Kazhdan et al.: 1–5 clean,
  /// more for noisy scans).
  double poisson_samples_per_node = 2.0;
  /// Edge of Poisson's cube over the points' bounding box (PCL's default 1.1): room for the
  /// implicit surface to close over what was never seen (under the fingers) inside the cube
  /// rather than running into its faces.
  double poisson_scale = 1.5;
  /// Threads of Poisson's octree solve (PCL's OpenMP; 0: one per core). The solve is most of
  /// the export (1.7-2.6 s of 2.0-3.0 s on the paper's whole sessions on one thread); on two
  /// threads it took 0-15 % less, but its sums then run in another order each time and the
  /// mesh is no longer the same bit for bit from run to run (a run's options.conf read back
  /// must make the same mesh): one by default. A build under ThreadSanitizer uses 1 whatever
  /// this says: libgomp is not instrumented, and its threads' work would be reported as races.
  int poisson_threads = 1;
  /// The closed mesh is cut back to the space no view saw empty (closure_bound.h), remeshed on
  /// a lattice of this step (mm; about the TSDF's 1.37 mm voxel, finer than Poisson's detail
  /// on a hand-held object); within `bound_keep_seen_mm` of the seen surface nothing is cut.
  /// The views' part is off when MakeMeshes gets none.
  double bound_voxel_mm = 1.0;
  double bound_keep_seen_mm = 2.0;
  /// The closed mesh is also cut to the convex hull of the seen surface's vertices (a bottle's
  /// unseen base ends flat at the lowest seen ring instead of Poisson's bulge, which no view saw
  /// empty; a convex object's closure never passes the object; a concave one's seen surface is
  /// inside its own hull and stays). Costs a half-seen ball its unseen cap. Works without views.
  bool bound_by_seen_hull = true;
  /// When the seen surface is a body of revolution (its sections fit circles within this share
  /// of their radius, RMS; the paper's objects scanned 0.4-0.9 %, a box 9-10 %), the hull is
  /// that of the seen surface turned all round its axis: the unseen ends are cut, the unseen side
  /// of a round object is left to Poisson (the plain hull cut it along a flat chord). 0: the plain
  /// hull.
  double bound_revolve_max_residual = 0.03;
  /// Otherwise, when at least this share of the seen surface faces along three orthogonal
  /// directions (a box's faces: 0.89-0.96 on the boxes and cubes scanned; 0.10-0.36 on bottles,
  /// pins and spheres), the hull is the box along them that holds the seen surface: a box seen
  /// from one side keeps the corner behind it that the plain hull cut off. 0: never.
  double bound_box_min_face_share = 0.8;
  /// The box leaves out this share of the seen surface's vertices beyond each of its six faces
  /// (ClosureBoundOptions::box_outlier_share): a blob of the hand fused proud of a face is cut
  /// back to the face. On 12 fifth turns of boxes and cubes every side of mesh.ply came closer to
  /// the truth's, 1-4 mm (docs/fusion.md); 0: the box holds every seen vertex.
  double bound_box_outlier_share = 0.005;
  /// A closed mesh whose faces cross (FindSelfIntersections: Poisson folds through itself now
  /// and then) is re-made as the zero set of its own signed distance on the bound's lattice
  /// (RemeshClosed: what it encloses, overlaps joined), and kept when that has no crossings.
  bool repair_self_intersections = true;
  /// Give the result per-vertex colours from the nearest vertex of the input (when it has them).
  bool color = true;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// `mesh` without the connected pieces (through shared vertices) that have fewer faces than
/// `min_fraction` of the largest piece; unused vertices are removed.
TriangleMesh RemoveSmallComponents(const TriangleMesh& mesh, double min_fraction);

/// Smooths `mesh` in place with HC Laplacian steps (Vollmer et al. 1999) over its vertex
/// neighbourhoods; border and isolated vertices move like any other. Normals are recomputed.
void SmoothHcLaplacian(TriangleMesh* mesh, int iterations, double alpha, double beta);

/// Closes each hole of `mesh` (a loop of edges with a face on one side only) with a fan of
/// triangles around a new vertex at the loop's centroid (colour and normal averaged from the
/// loop). Returns the number of holes closed.
int FillHoles(TriangleMesh* mesh);

/// A watertight mesh through the oriented points of `mesh` (its vertices and normals; normals are
/// computed when missing) by Poisson reconstruction at octree `depth`, over a cube `scale` times
/// the points' bounding box. Faces are oriented
/// outward; colours come from the nearest input vertex when `color` and the input has them.
/// PCL's extraction now and then drops a triangle whose edge it cannot match (printing "Vertex
/// pair not in list" to stdout, which is kept out of ours): the small holes left are filled.
/// Returns an empty mesh when `mesh` has too few vertices to reconstruct from. `threads` as
/// MeshingOptions::poisson_threads.
TriangleMesh PoissonReconstruct(const TriangleMesh& mesh, int depth, double samples_per_node,
                                double scale, bool color, int threads = 1);

/// The exported meshes of one raw marching-cubes mesh.
struct MeshingResult {
  /// Cleaned and smoothed: the TSDF's own surface (open where the object was never seen).
  TriangleMesh smoothed;
  /// Watertight (Poisson); empty when Poisson is off or had too few points.
  TriangleMesh watertight;
  /// Share of `watertight`'s surface farther than 2 mm from `smoothed`: what no frame saw and
  /// Poisson made up (UnseenShare); its volume is a guess over that part. 0 without `watertight`.
  double unseen_share = 0;
  /// Share of Poisson's volume cut because views saw that space empty or it lay outside the
  /// seen surface's hull (0: nothing cut), and of it the hull's part.
  double cut_share = 0;
  double hull_cut_share = 0;
  /// Of what the closure's hull was taken: the seen surface, its revolution about its axis (a
  /// body of revolution) or the box along its faces (a box seen in part).
  HullShape hull_shape = HullShape::kSeen;
  /// Pairs of `watertight`'s faces that cross (FindSelfIntersections): Poisson can fold its
  /// surface through itself, and such a mesh is closed and manifold but not watertight.
  std::int64_t self_intersections = 0;
  /// Pairs of crossing faces that the closed mesh had before it was re-made without them
  /// (MeshingOptions::repair_self_intersections; 0: none, or not repaired).
  std::int64_t repaired_intersections = 0;
  /// `watertight` is closed, edge-manifold, oriented and does not cross itself.
  bool IsWatertight() const { return watertight.IsWatertight() && self_intersections == 0; }
  /// Time spent, ms.
  double cleanup_ms = 0;
  double smoothing_ms = 0;
  double poisson_ms = 0;
  double bound_ms = 0;
  double repair_ms = 0;
};

/// Runs the steps above on a raw marching-cubes mesh; Poisson's mesh is bounded by the views of
/// `free_space` (when given) and by the seen surface's hull (`bound_by_seen_hull`).
MeshingResult MakeMeshes(const TriangleMesh& raw, const MeshingOptions& options = {},
                         const FreeSpace* free_space = nullptr);

}  // namespace ihs::fusion
