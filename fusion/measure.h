#pragma once
// Measuring a scanned mesh the way the paper does (Table 1): for a body of revolution, its
// symmetry axis from the principal axes of its surface, its height along the axis and the
// diameters of its sections (the widest; for a bowling pin also the head beyond the neck); and,
// given the true surface, how far the scan is from it (Chamfer distance, completeness).

#include <Eigen/Core>
#include <cmath>
#include <utility>
#include <vector>

#include "core/triangle_mesh.h"

namespace ihs::fusion {

/// The dimensions of a body of revolution.
struct RevolutionMeasures {
  /// A point on the symmetry axis (the surface's centroid) and the axis's direction, mm.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  /// A point on the symmetry axis: the sections' circle centres' mean (on a surface seen from one
  /// side `centre` lies off the axis, toward the side seen), mm.
  Eigen::Vector3d axis_point = Eigen::Vector3d::Zero();
  /// Extent along the axis, mm.
  double height_mm = 0;
  /// Diameter of the widest section, and where it is (height above the lower end), mm.
  double widest_diameter_mm = 0;
  double widest_at_mm = 0;
  /// Where the object narrows and widens again between its widest section and its farther end
  /// (a bowling pin's neck and head): the widest section beyond the narrowest one, mm; 0 unless
  /// that neck is at most 80 % of the widest section and the head 5 % wider than the neck.
  double head_diameter_mm = 0;
  /// Section diameters along the axis: (height above the lower end, diameter), mm.
  std::vector<std::pair<double, double>> profile;
  /// How far the side vertices are from their sections' circles: weighted RMS over the mean
  /// radius (0 for a body of revolution; a box's sections are a tenth of their size off or more).
  double roundness_residual = INFINITY;
};

/// Measures `mesh` as a body of revolution. The axis is first, of the principal axes and the line
/// the surface's normal lines meet best (every normal of a body of revolution meets its axis),
/// the one about which the sections fit circles best (the long axis of a bottle, the short one of
/// a flat disc; any for a sphere), then the line through the sections' circle centres (a surface
/// seen in part tilts its principal axes; the centres stay on the symmetry axis). Each section's
/// diameter is that of the least-squares circle through its vertices (weighted by the area of their
/// side faces; faces turned along the axis, such as flat caps, do not count), so that a section
/// seen only in part still measures right. Throws std::invalid_argument for an empty mesh or a
/// non-positive `slice_mm`.
RevolutionMeasures MeasureRevolution(const TriangleMesh& mesh, double slice_mm = 2.0);

/// How much of a surface is a box's: three orthogonal directions and the share of the surface
/// whose normals lie along one of them (either way).
struct BoxMeasures {
  /// Orthonormal columns: the direction most of the surface faces (either way), then the one
  /// most of the rest faces across it, then their cross product.
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
  /// Share of the surface's area within the tolerance of ±axes (1 for a box seen anywhere, about
  /// 0.3 or less for a sphere or a bottle's side).
  double face_share = 0;
};

/// Measures `mesh` as a box: the directions its faces' normals gather around (within
/// `tolerance_deg`; about 200 faces' normals are the candidates, the best refined to the
/// area-weighted mean of the normals near it). Empty meshes give a share of 0.
BoxMeasures MeasureBox(const TriangleMesh& mesh, double tolerance_deg = 15.0);

/// Where points lie along three directions: per direction the lowest and the highest
/// coordinate.
struct BoxExtent {
  Eigen::Vector3d low = Eigen::Vector3d::Zero();
  Eigen::Vector3d high = Eigen::Vector3d::Zero();
  Eigen::Vector3d Size() const { return high - low; }
};

/// The extent of `points` along `axes` (orthonormal columns), leaving out `outlier_share` of the
/// points at each end of each direction (0: all of them, the box that holds every point; a
/// share in [0, 0.5)). No points: an empty extent at the origin.
BoxExtent MeasureExtent(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3d& axes,
                        double outlier_share = 0.0);

/// How well a scanned surface matches the true one (both in the same frame, mm).
struct SurfaceComparison {
  /// Mean distance from the scan's surface to the truth's (accuracy), from the truth's to the
  /// scan's, and their mean (the symmetric Chamfer distance), mm.
  double scan_to_truth_mm = 0;
  double truth_to_scan_mm = 0;
  double chamfer_mm = 0;
  /// 95th percentile of scan-to-truth distances, mm.
  double scan_to_truth_p95_mm = 0;
  /// Share of the true surface within `within_mm` of the scan (completeness), in [0, 1].
  double completeness = 0;
  double within_mm = 0;
};

/// Compares two surfaces through dense samples (`spacing_mm` apart on average; the distances are
/// biased up by about half of that).
SurfaceComparison CompareSurfaces(const TriangleMesh& scan, const TriangleMesh& truth,
                                  double within_mm = 2.0, double spacing_mm = 0.25);

/// Share of the area of `closed` (a watertight mesh made from `seen`) farther than `within_mm`
/// from `seen`: the part of the closed surface that no frame observed and that Poisson made up.
/// A volume measured on a watertight mesh is only as good as this share is small: where half a
/// sphere was never seen, the closure's volume follows Poisson's bounding cube more than the data
/// (docs/fusion.md). In [0, 1]; 0 for an empty `closed`, 1 for an empty `seen`.
double UnseenShare(const TriangleMesh& closed, const TriangleMesh& seen, double within_mm = 2.0,
                   double spacing_mm = 0.5);

/// Points spread over the surface of `mesh`, one per `spacing_mm`² of area on average
/// (deterministic), but at most about `max_samples`: a larger surface (a scan that lost the object
/// and smeared it over metres) is sampled more sparsely instead of filling the memory.
std::vector<Eigen::Vector3f> SampleSurface(const TriangleMesh& mesh, double spacing_mm,
                                           std::size_t max_samples = 4'000'000);

}  // namespace ihs::fusion
