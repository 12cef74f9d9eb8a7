#include "tracker/local_surface.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace ihs::tracker {

double LocalSurface::Distance(const Eigen::Vector3d& p) const {
  return radius > 0 ? std::abs((p - centre).norm() - radius) : std::abs(normal.dot(p - centre));
}

Eigen::Vector3d LocalSurface::NormalAt(const Eigen::Vector3d& p) const {
  if (radius <= 0) return normal;
  const Eigen::Vector3d out = p - centre;
  return out.norm() > 1e-9 ? Eigen::Vector3d(out.normalized()) : normal;
}

Eigen::Vector3d LocalSurface::Closest(const Eigen::Vector3d& p) const {
  if (radius <= 0) return p - normal.dot(p - centre) * normal;
  return centre + radius * NormalAt(p);
}

LocalSurface FitLocalSurface(const std::vector<Eigen::Vector3d>& points, double max_radius) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix4d normal_equations = Eigen::Matrix4d::Zero();
  Eigen::Vector4d rhs = Eigen::Vector4d::Zero();
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d q = p - mean;
    const Eigen::Vector4d row(q.x(), q.y(), q.z(), 1.0);
    normal_equations += row * row.transpose();
    rhs -= row * q.squaredNorm();
    scatter += q * q.transpose();
  }
  const Eigen::Vector4d x = normal_equations.ldlt().solve(rhs);
  const Eigen::Vector3d centre = -0.5 * x.head<3>();
  const double radius_sq = centre.squaredNorm() - x(3);
  LocalSurface surface;
  if (x.allFinite() && radius_sq > 0 && radius_sq < max_radius * max_radius) {
    surface.centre = mean + centre;
    surface.radius = std::sqrt(radius_sq);
  } else {
    surface.centre = mean;
    surface.normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0);
    // Toward the camera (the origin), which sees the points: the object lies behind them.
    if (surface.normal.dot(surface.centre) > 0) surface.normal = -surface.normal;
  }
  return surface;
}

namespace {

double Rms(const LocalSurface& surface, const std::vector<Eigen::Vector3d>& points) {
  double sum_sq = 0;
  for (const Eigen::Vector3d& p : points) sum_sq += std::pow(surface.Distance(p), 2);
  return std::sqrt(sum_sq / static_cast<double>(points.size()));
}

}  // namespace

std::optional<LocalSurface> SurfaceAround(const Eigen::Vector3f& centre,
                                          const std::vector<Eigen::Vector3f>& points,
                                          double reach_mm, int min_points, double max_rms_mm,
                                          bool trim) {
  std::vector<Eigen::Vector3d> patch;
  for (const Eigen::Vector3f& p : points) {
    if ((p - centre).squaredNorm() <= reach_mm * reach_mm) patch.push_back(p.cast<double>());
  }
  if (static_cast<int>(patch.size()) < min_points) return std::nullopt;
  LocalSurface surface = FitLocalSurface(patch, 1000.0);
  if (Rms(surface, patch) <= max_rms_mm) return surface;
  if (!trim) return std::nullopt;
  // The surface nearest the centre: fitted to the quarter of the patch nearest it, then to
  // every point of the patch near that fit, a few times.
  const Eigen::Vector3d c = centre.cast<double>();
  const size_t seed = std::max<size_t>(static_cast<size_t>(min_points), patch.size() / 4);
  std::nth_element(patch.begin(), patch.begin() + (seed - 1), patch.end(),
                   [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                     return (a - c).squaredNorm() < (b - c).squaredNorm();
                   });
  surface = FitLocalSurface(std::vector<Eigen::Vector3d>(patch.begin(), patch.begin() + seed),
                            1000.0);
  for (int round = 0; round < 3; ++round) {
    std::vector<Eigen::Vector3d> near;
    for (const Eigen::Vector3d& p : patch) {
      if (surface.Distance(p) <= 2 * max_rms_mm) near.push_back(p);
    }
    if (static_cast<int>(near.size()) < min_points) return std::nullopt;
    surface = FitLocalSurface(near, 1000.0);
    if (Rms(surface, near) <= max_rms_mm) return surface;
  }
  return std::nullopt;
}

}  // namespace ihs::tracker
