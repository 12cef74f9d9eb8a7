#include "fusion/measure.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <random>

#include "core/check.h"
#include "core/point_kd_tree.h"

namespace ihs::fusion {
namespace {

// A mesh's faces as centroids with their areas and unit normals.
struct Face {
  Eigen::Vector3d centroid;
  double area;
  Eigen::Vector3d normal;
};

std::vector<Face> Faces(const TriangleMesh& mesh) {
  std::vector<Face> faces;
  faces.reserve(mesh.faces.size());
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
    const Eigen::Vector3d b = mesh.vertices[f[1]].cast<double>();
    const Eigen::Vector3d c = mesh.vertices[f[2]].cast<double>();
    const Eigen::Vector3d cross = (b - a).cross(c - a);
    const double twice_area = cross.norm();
    if (twice_area <= 0) continue;
    faces.push_back({(a + b + c) / 3, 0.5 * twice_area, cross / twice_area});
  }
  return faces;
}

// The distances from each of `from` to the nearest of `to`.
std::vector<double> NearestDistances(const std::vector<Eigen::Vector3f>& from,
                                     const std::vector<Eigen::Vector3f>& to) {
  const PointKdTree tree(to);
  std::vector<double> distances(from.size());
  for (size_t i = 0; i < from.size(); ++i) {
    float distance_sq = 0;
    tree.Nearest(from[i], &distance_sq);
    distances[i] = std::sqrt(distance_sq);
  }
  return distances;
}

double Mean(const std::vector<double>& values) {
  double sum = 0;
  for (double v : values) sum += v;
  return values.empty() ? 0 : sum / values.size();
}

}  // namespace

// The measures of `mesh` taken along `axis` through `centre`; `residual` gets how far the side
// vertices are from their sections' circles (weighted RMS over the mean radius): small when the
// axis is a symmetry axis. `circle_centres`, when given, gets the centre of each section that
// counts, with its weight.
static RevolutionMeasures MeasureAlong(
    const TriangleMesh& mesh, const Eigen::Vector3d& centre, const Eigen::Vector3d& axis,
    double slice_mm, double* residual,
    std::vector<std::pair<Eigen::Vector3d, double>>* circle_centres = nullptr) {
  RevolutionMeasures result;
  result.axis = axis;
  result.centre = centre;
  result.axis_point = centre;
  // Extent along the axis.
  double low = INFINITY, high = -INFINITY;
  for (const auto& v : mesh.vertices) {
    const double h = (v.cast<double>() - centre).dot(result.axis);
    low = std::min(low, h), high = std::max(high, h);
  }
  result.height_mm = high - low;

  // Sections: the vertices of side faces (each with a third of the face's area), binned by
  // height; each bin's centre, then its mean radius. Vertices lie on the surface, where face
  // centroids would cut inside it wherever the profile curves.
  const int bins = std::max(1, static_cast<int>(std::ceil(result.height_mm / slice_mm)));
  std::vector<double> vertex_weight(mesh.vertices.size(), 0.0);
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
    const Eigen::Vector3d cross =
        (mesh.vertices[f[1]].cast<double>() - a).cross(mesh.vertices[f[2]].cast<double>() - a);
    const double twice_area = cross.norm();
    // Faces turned along the axis (flat caps) are not part of any section's outline.
    if (twice_area <= 0 || std::abs(cross.dot(result.axis)) >= 0.7 * twice_area) continue;
    for (int c = 0; c < 3; ++c) vertex_weight[f[c]] += twice_area / 6;
  }
  // Per bin, a weighted least-squares circle (Kåsa's algebraic fit) through the vertices
  // projected onto the plane across the axis: right also where a scan saw only part of a
  // section's circle, where the vertices' centroid would be pulled toward the part seen.
  const Eigen::Vector3d across_u = result.axis.unitOrthogonal();
  const Eigen::Vector3d across_v = result.axis.cross(across_u);
  std::vector<double> weight(bins, 0.0), radius(bins, 0.0);
  std::vector<Eigen::Vector2d> circle_centre(bins, Eigen::Vector2d::Zero());
  std::vector<Eigen::Matrix3d> normal(bins, Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3d> rhs(bins, Eigen::Vector3d::Zero());
  auto bin_of = [&](const Eigen::Vector3d& p) {
    const double h = (p - centre).dot(result.axis) - low;
    return std::clamp(static_cast<int>(h / slice_mm), 0, bins - 1);
  };
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const double w = vertex_weight[i];
    if (w <= 0) continue;
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    const int b = bin_of(p);
    const double x = (p - centre).dot(across_u), y = (p - centre).dot(across_v);
    const Eigen::Vector3d row(x, y, 1.0);
    weight[b] += w;
    normal[b] += w * row * row.transpose();
    rhs[b] -= w * (x * x + y * y) * row;
  }
  for (int b = 0; b < bins; ++b) {
    if (weight[b] <= 0) continue;
    // x² + y² + D·x + E·y + F = 0: centre (−D/2, −E/2), r² = (D² + E²)/4 − F.
    const Eigen::Vector3d def = normal[b].ldlt().solve(rhs[b]);
    const double r_sq = 0.25 * (def[0] * def[0] + def[1] * def[1]) - def[2];
    if (!def.allFinite() || r_sq <= 0) continue;
    radius[b] = std::sqrt(r_sq);
    circle_centre[b] = -0.5 * def.head<2>();
  }
  // How well the circles explain the vertices.
  double misfit = 0, radius_sum = 0, weight_sum = 0;
  for (size_t i = 0; i < mesh.vertices.size(); ++i) {
    const double w = vertex_weight[i];
    if (w <= 0) continue;
    const Eigen::Vector3d p = mesh.vertices[i].cast<double>();
    const int b = bin_of(p);
    if (radius[b] <= 0) continue;
    const Eigen::Vector2d d((p - centre).dot(across_u), (p - centre).dot(across_v));
    const double off = (d - circle_centre[b]).norm() - radius[b];
    misfit += w * off * off;
    radius_sum += w * radius[b], weight_sum += w;
  }
  *residual = weight_sum > 0 && radius_sum > 0
                  ? std::sqrt(misfit / weight_sum) / (radius_sum / weight_sum)
                  : INFINITY;
  result.roundness_residual = *residual;
  // Bins with little surface (an end, a gap) are noise: they need a tenth of the typical bin's.
  std::vector<double> sorted = weight;
  std::sort(sorted.begin(), sorted.end());
  const double min_weight = 0.1 * sorted[sorted.size() / 2];
  Eigen::Vector3d centre_sum = Eigen::Vector3d::Zero();
  double centre_weight = 0;
  for (int b = 0; b < bins; ++b) {
    if (weight[b] <= 0 || weight[b] < min_weight || radius[b] <= 0) continue;
    result.profile.push_back({(b + 0.5) * slice_mm, 2 * radius[b]});
    const Eigen::Vector3d section_centre = centre + (low + (b + 0.5) * slice_mm) * result.axis +
                                           circle_centre[b].x() * across_u +
                                           circle_centre[b].y() * across_v;
    centre_sum += weight[b] * section_centre, centre_weight += weight[b];
    if (circle_centres) circle_centres->push_back({section_centre, weight[b]});
  }
  if (centre_weight > 0) result.axis_point = centre_sum / centre_weight;
  if (result.profile.empty()) return result;

  // Widest section; then, toward the farther end, the narrowest and the widest beyond it.
  const int count = static_cast<int>(result.profile.size());
  int widest = 0;
  for (int i = 1; i < count; ++i) {
    if (result.profile[i].second > result.profile[widest].second) widest = i;
  }
  result.widest_diameter_mm = result.profile[widest].second;
  result.widest_at_mm = result.profile[widest].first;
  const int step = widest < count / 2 ? 1 : -1;
  const int end = step > 0 ? count : -1;
  // A head: a section wider (by 5 %) than the narrowest one between it and the widest, which
  // is a real neck (at most 80 % of the widest). The widest such section.
  double neck = result.widest_diameter_mm;
  for (int i = widest; i != end; i += step) {
    const double d = result.profile[i].second;
    neck = std::min(neck, d);
    if (neck <= 0.8 * result.widest_diameter_mm && d > 1.05 * neck) {
      result.head_diameter_mm = std::max(result.head_diameter_mm, d);
    }
  }
  return result;
}

// The direction of the line that the surface's normal lines meet best (every normal of a body of
// revolution meets its axis): with the axis's Plücker coordinates (a, q × a), q a point on it,
// the normal n at p meets it when n·(q × a) + (p × n)·a = 0. The area-weighted least squares
// over the faces (p taken from `origin`, for conditioning), with |a| = 1, is the smallest
// eigenvector of the system reduced to a. None for a degenerate surface (a sphere's normals meet
// every line through its centre; then any axis will do anyway).
static std::optional<Eigen::Vector3d> NormalsMeet(const std::vector<Face>& faces,
                                                  const Eigen::Vector3d& origin) {
  Eigen::Matrix<double, 6, 6> system = Eigen::Matrix<double, 6, 6>::Zero();
  for (const Face& f : faces) {
    Eigen::Matrix<double, 6, 1> row;
    row << (f.centroid - origin).cross(f.normal), f.normal;
    system += f.area * row * row.transpose();
  }
  const Eigen::Matrix3d turn = system.topLeftCorner<3, 3>();
  const Eigen::Matrix3d mixed = system.topRightCorner<3, 3>();
  const Eigen::Matrix3d shift = system.bottomRightCorner<3, 3>();
  if (!(shift.trace() > 0)) return std::nullopt;
  const Eigen::Matrix3d reduced =
      turn - mixed * (shift + 1e-9 * shift.trace() * Eigen::Matrix3d::Identity())
                         .ldlt()
                         .solve(mixed.transpose());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(reduced);
  const Eigen::Vector3d values = solver.eigenvalues();
  // A clear smallest direction (a sphere's three are alike).
  if (!values.allFinite() || values[0] > 0.1 * values[1]) return std::nullopt;
  return solver.eigenvectors().col(0).normalized();
}

namespace {

// Of the faces whose normals are within the tolerance of perpendicular to `across` (all faces
// when `across` is zero), the direction the most area faces (either way) within
// `cos_tolerance`, refined to the area-weighted mean of those normals (in the plane across
// `across`); zero when there is none.
Eigen::Vector3d DominantDirection(const std::vector<Face>& faces, const Eigen::Vector3d& across,
                                  double cos_tolerance) {
  const double max_along = std::sqrt(std::max(0.0, 1.0 - cos_tolerance * cos_tolerance));
  const auto usable = [&](const Eigen::Vector3d& n) {
    return across.isZero() || std::abs(n.dot(across)) <= max_along;
  };
  const auto flat = [&](Eigen::Vector3d n) {
    return across.isZero() ? n : (n - n.dot(across) * across).normalized();
  };
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  double best_area = 0;
  // About 200 candidates, spread over the faces.
  const size_t stride = std::max<size_t>(1, faces.size() / 200);
  for (size_t c = 0; c < faces.size(); c += stride) {
    if (!usable(faces[c].normal)) continue;
    const Eigen::Vector3d candidate = flat(faces[c].normal);
    double area = 0;
    for (size_t f = 0; f < faces.size(); ++f) {
      if (usable(faces[f].normal) && std::abs(candidate.dot(faces[f].normal)) >= cos_tolerance)
        area += faces[f].area;
    }
    if (area > best_area) best_area = area, best = candidate;
  }
  if (best.isZero()) return best;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (size_t f = 0; f < faces.size(); ++f) {
    const double along = best.dot(faces[f].normal);
    if (usable(faces[f].normal) && std::abs(along) >= cos_tolerance)
      sum += (along < 0 ? -1.0 : 1.0) * faces[f].area * faces[f].normal;
  }
  return sum.isZero() ? best : flat(sum.normalized());
}

}  // namespace

BoxMeasures MeasureBox(const TriangleMesh& mesh, double tolerance_deg) {
  BoxMeasures box;
  const std::vector<Face> faces = Faces(mesh);
  double total = 0;
  for (const Face& face : faces) total += face.area;
  if (!(total > 0)) return box;
  const double cos_tolerance = std::cos(tolerance_deg * M_PI / 180.0);
  const Eigen::Vector3d first = DominantDirection(faces, Eigen::Vector3d::Zero(), cos_tolerance);
  if (first.isZero()) return box;
  Eigen::Vector3d second = DominantDirection(faces, first, cos_tolerance);
  if (second.isZero()) second = first.unitOrthogonal();
  second = (second - second.dot(first) * first).normalized();
  box.axes.col(0) = first;
  box.axes.col(1) = second;
  box.axes.col(2) = first.cross(second);
  double along = 0;
  for (const Face& face : faces) {
    const Eigen::Vector3d n = box.axes.transpose() * face.normal;
    if (n.cwiseAbs().maxCoeff() >= cos_tolerance) along += face.area;
  }
  box.face_share = along / total;
  return box;
}

BoxExtent MeasureExtent(const std::vector<Eigen::Vector3f>& points, const Eigen::Matrix3d& axes,
                        double outlier_share) {
  IHS_CHECK_ARG(outlier_share >= 0 && outlier_share < 0.5,
                "the extent's outlier share must be in [0, 0.5), got " << outlier_share);
  BoxExtent extent;
  if (points.empty()) return extent;
  const size_t left_out = static_cast<size_t>(outlier_share * static_cast<double>(points.size()));
  std::vector<double> along(points.size());
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d direction = axes.col(axis);
    for (size_t k = 0; k < points.size(); ++k) along[k] = direction.dot(points[k].cast<double>());
    std::nth_element(along.begin(), along.begin() + left_out, along.end());
    extent.low[axis] = along[left_out];
    const size_t top = along.size() - 1 - left_out;
    std::nth_element(along.begin(), along.begin() + top, along.end());
    extent.high[axis] = along[top];
  }
  return extent;
}

RevolutionMeasures MeasureRevolution(const TriangleMesh& mesh, double slice_mm) {
  IHS_CHECK_ARG(slice_mm > 0, "slice_mm must be positive, got " << slice_mm);
  const std::vector<Face> faces = Faces(mesh);
  IHS_CHECK_ARG(!faces.empty(), "cannot measure an empty mesh");
  RevolutionMeasures result;

  // Principal axes of the surface.
  double total_area = 0;
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Face& f : faces) centre += f.area * f.centroid, total_area += f.area;
  centre /= total_area;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const Face& f : faces) {
    const Eigen::Vector3d d = f.centroid - centre;
    covariance += f.area * d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance / total_area);
  // The axis: of the three principal axes and the line the surface's normals meet, the one about
  // which the surface is most nearly a body of revolution (its sections fit circles best). The
  // spread alone misleads on squat objects and on surfaces seen in part.
  std::vector<Eigen::Vector3d> candidates;
  for (int k = 0; k < 3; ++k) candidates.push_back(solver.eigenvectors().col(k).normalized());
  if (const auto normals_meet = NormalsMeet(faces, centre)) candidates.push_back(*normals_meet);
  double best = INFINITY;
  for (const Eigen::Vector3d& axis : candidates) {
    double residual = INFINITY;
    RevolutionMeasures candidate = MeasureAlong(mesh, centre, axis, slice_mm, &residual);
    if (residual < best) best = residual, result = std::move(candidate);
  }
  // The principal axis of a surface seen in part (or of a squat body) can be tilted by a degree
  // or more from the symmetry axis, which lengthens the height by about the width times the
  // tilt. The sections' circle centres lie on the symmetry axis whatever the tilt (a tilted cut
  // through a body of revolution is centred on its axis), so the line through them is a better
  // axis: iterate to a fixed point, as long as the sections stay as round.
  for (int iteration = 0; iteration < 10 && std::isfinite(best); ++iteration) {
    std::vector<std::pair<Eigen::Vector3d, double>> centres;
    double residual = INFINITY;
    MeasureAlong(mesh, result.centre, result.axis, slice_mm, &residual, &centres);
    if (centres.size() < 5) break;
    double total = 0;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& [point, weight] : centres) mean += weight * point, total += weight;
    mean /= total;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const auto& [point, weight] : centres)
      scatter += weight * (point - mean) * (point - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> line(scatter / total);
    // The centres must spread along a line (a sphere's or a disc's do not).
    const Eigen::Vector3d spread = line.eigenvalues();
    if (spread[2] < 25.0 || spread[1] > 0.05 * spread[2]) break;
    Eigen::Vector3d axis = line.eigenvectors().col(2);
    if (axis.dot(result.axis) < 0) axis = -axis;
    // The refinement corrects a small tilt; a large one means the centres are not on a line.
    if (axis.dot(result.axis) < std::cos(10.0 * M_PI / 180.0)) break;
    RevolutionMeasures candidate = MeasureAlong(mesh, centre, axis, slice_mm, &residual);
    if (residual > 1.05 * best) break;
    const double change = std::acos(std::min(1.0, axis.dot(result.axis)));
    best = std::min(best, residual), result = std::move(candidate);
    if (change < 1e-4) break;
  }
  return result;
}

std::vector<Eigen::Vector3f> SampleSurface(const TriangleMesh& mesh, double spacing_mm,
                                           std::size_t max_samples) {
  IHS_CHECK_ARG(spacing_mm > 0, "spacing_mm must be positive, got " << spacing_mm);
  IHS_CHECK_ARG(max_samples > 0, "max_samples must be positive");
  std::mt19937 random(12345);
  std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
  std::vector<Eigen::Vector3f> samples;
  double area = 0;
  for (const auto& f : mesh.faces) {
    area += 0.5 * (mesh.vertices[f[1]] - mesh.vertices[f[0]])
                      .cross(mesh.vertices[f[2]] - mesh.vertices[f[0]])
                      .norm();
  }
  const double per_mm2 =
      std::min(1.0 / (spacing_mm * spacing_mm), static_cast<double>(max_samples) / area);
  samples.reserve(static_cast<std::size_t>(area * per_mm2) + 1);
  double carry = 0;
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3f a = mesh.vertices[f[0]], b = mesh.vertices[f[1]], c = mesh.vertices[f[2]];
    carry += 0.5 * (b - a).cross(c - a).norm() * per_mm2;
    // Every face gets its share; fractions carry over to the next.
    for (; carry >= 1; carry -= 1) {
      float s = uniform(random), t = uniform(random);
      if (s + t > 1) s = 1 - s, t = 1 - t;
      samples.push_back(a + s * (b - a) + t * (c - a));
    }
  }
  return samples;
}

SurfaceComparison CompareSurfaces(const TriangleMesh& scan, const TriangleMesh& truth,
                                  double within_mm, double spacing_mm) {
  const std::vector<Eigen::Vector3f> scan_samples = SampleSurface(scan, spacing_mm);
  const std::vector<Eigen::Vector3f> truth_samples = SampleSurface(truth, spacing_mm);
  IHS_CHECK_ARG(!scan_samples.empty() && !truth_samples.empty(), "cannot compare an empty surface");
  SurfaceComparison result;
  std::vector<double> to_truth = NearestDistances(scan_samples, truth_samples);
  const std::vector<double> to_scan = NearestDistances(truth_samples, scan_samples);
  result.scan_to_truth_mm = Mean(to_truth);
  result.truth_to_scan_mm = Mean(to_scan);
  result.chamfer_mm = 0.5 * (result.scan_to_truth_mm + result.truth_to_scan_mm);
  std::nth_element(to_truth.begin(), to_truth.begin() + to_truth.size() * 95 / 100, to_truth.end());
  result.scan_to_truth_p95_mm = to_truth[to_truth.size() * 95 / 100];
  result.within_mm = within_mm;
  result.completeness =
      static_cast<double>(
          std::count_if(to_scan.begin(), to_scan.end(), [&](double d) { return d <= within_mm; })) /
      to_scan.size();
  return result;
}

double UnseenShare(const TriangleMesh& closed, const TriangleMesh& seen, double within_mm,
                   double spacing_mm) {
  IHS_CHECK_ARG(within_mm > 0 && spacing_mm > 0,
                "UnseenShare needs positive distances, got " << within_mm << " and " << spacing_mm);
  const std::vector<Eigen::Vector3f> closed_samples = SampleSurface(closed, spacing_mm);
  if (closed_samples.empty()) return 0;
  const std::vector<Eigen::Vector3f> seen_samples = SampleSurface(seen, spacing_mm);
  if (seen_samples.empty()) return 1;
  const std::vector<double> to_seen = NearestDistances(closed_samples, seen_samples);
  return static_cast<double>(std::count_if(to_seen.begin(), to_seen.end(),
                                           [&](double d) { return d > within_mm; })) /
         to_seen.size();
}

}  // namespace ihs::fusion
