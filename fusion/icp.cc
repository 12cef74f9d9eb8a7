#include "fusion/icp.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/check.h"

namespace ihs::fusion {

void IcpOptions::Check() const {
  IHS_CHECK_ARG(iterations >= 1 && iterations <= 100, "icp.iterations must be in [1, 100]");
  IHS_CHECK_ARG(max_distance_mm > 0, "icp.max_distance_mm must be positive");
  IHS_CHECK_ARG(min_inlier_fraction >= 0 && min_inlier_fraction <= 1,
                "icp.min_inlier_fraction must be in [0, 1]");
  IHS_CHECK_ARG(anchor_share >= 0, "icp.anchor_share must be >= 0");
  IHS_CHECK_ARG(min_constraint_over_noise >= 0, "icp.min_constraint_over_noise must be >= 0");
}

namespace {

// The part of a step in the directions `free` (columns of `basis`) that best meets the anchors
// (normal equations `anchor_matrix`·x = `anchor_rhs`) given the rest of the step, `fixed`;
// directions the anchors hardly know (under a millionth of their strongest) stay at zero.
Eigen::Matrix<double, 6, 1> AnchorStep(const Eigen::Matrix<double, 6, 6>& basis,
                                       const std::vector<int>& free,
                                       const Eigen::Matrix<double, 6, 6>& anchor_matrix,
                                       const Eigen::Matrix<double, 6, 1>& anchor_rhs,
                                       const Eigen::Matrix<double, 6, 1>& fixed) {
  const int k = static_cast<int>(free.size());
  Eigen::MatrixXd directions(6, k);
  for (int c = 0; c < k; ++c) directions.col(c) = basis.col(free[c]);
  const Eigen::MatrixXd reduced = directions.transpose() * anchor_matrix * directions;
  const Eigen::VectorXd wanted = directions.transpose() * (anchor_rhs - anchor_matrix * fixed);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(reduced);
  const double strongest = anchor_matrix.trace();
  Eigen::VectorXd y = Eigen::VectorXd::Zero(k);
  for (int i = 0; i < k; ++i) {
    const double value = eigen.eigenvalues()[i];
    if (!(value > 1e-6 * strongest)) continue;
    const auto direction = eigen.eigenvectors().col(i);
    y += direction * (direction.dot(wanted) / value);
  }
  return directions * y;
}

}  // namespace

IcpResult AlignToModel(const std::vector<Eigen::Vector3f>& points, const RaycastImage& model,
                       const CameraIntrinsics& intrinsics, const Rigid3& predicted,
                       const IcpOptions& options, const std::vector<IcpAnchor>& anchors) {
  options.Check();
  IHS_CHECK_ARG(model.width == intrinsics.width && model.height == intrinsics.height,
                "the raycast is " << model.width << "x" << model.height << ", the camera "
                                  << intrinsics.width << "x" << intrinsics.height);
  IcpResult result;
  result.cam_from_volume = predicted;
  const int needed =
      std::max(50, static_cast<int>(std::ceil(options.min_inlier_fraction * points.size())));
  // predicted_from_current: takes the current camera's points to where the predicted camera
  // sees the same surface (the model's raycast).
  Rigid3 correction;
  const double max_sq = options.max_distance_mm * options.max_distance_mm;
  double rms = 0;
  int inliers = 0;
  // The twist is taken about a pivot (first the points' centroid), with the turn scaled by the
  // points' spread about it, so that turns and shifts weigh alike.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& point : points) centroid += point.cast<double>();
  centroid /= std::max<size_t>(1, points.size());
  double spread_sq = 0;
  for (const Eigen::Vector3f& point : points)
    spread_sq += (point.cast<double>() - centroid).squaredNorm();
  spread_sq /= std::max<size_t>(1, points.size());
  Eigen::Vector3d pivot = centroid;
  double scale = std::max(1.0, std::sqrt(spread_sq));
  // Without anchors (or with anchors for them alone), the directions the surface leaves free keep
  // the prediction (IcpOptions::min_constraint_over_noise, anchors_free_directions_only).
  const bool keep_free = (anchors.empty() || options.anchors_free_directions_only) &&
                         options.min_constraint_over_noise > 0;
  std::vector<double> normal_jitter;
  // What a direction of the motion learns per point pair from the model's normal noise alone.
  double noise_information = 0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    Eigen::Matrix<double, 6, 6> normal_matrix = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> rhs = Eigen::Matrix<double, 6, 1>::Zero();
    Eigen::Vector3d centre = correction * pivot;
    // Where the model's normal lines meet (least squares): Σ(I − nnᵀ)·x = Σ(I − nnᵀ)·p.
    const bool find_pivot = keep_free && iteration == 0;
    Eigen::Matrix3d across = Eigen::Matrix3d::Zero();
    Eigen::Vector3d across_points = Eigen::Vector3d::Zero();
    if (find_pivot) normal_jitter.reserve(points.size());
    double sum_sq = 0;
    inliers = 0;
    for (const Eigen::Vector3f& point : points) {
      const Eigen::Vector3d p = correction * Eigen::Vector3d(point.cast<double>());
      if (p.z() <= 0) continue;
      const Eigen::Vector2d pixel = intrinsics.Project(p);
      // The nearest pixel (inside the image, truncation rounds).
      if (!intrinsics.Contains(pixel.x(), pixel.y())) continue;
      const int u = static_cast<int>(pixel.x() + 0.5), v = static_cast<int>(pixel.y() + 0.5);
      const size_t index = static_cast<size_t>(v) * model.width + u;
      const float depth = model.depth_mm[index];
      const Eigen::Vector3d normal = model.normals[index].cast<double>();
      if (depth <= 0 || normal.squaredNorm() < 0.5) continue;
      const Eigen::Vector3d target = intrinsics.BackProject(u, v, depth);
      if ((p - target).squaredNorm() > max_sq) continue;
      const double residual = normal.dot(p - target);
      // d(residual)/d(θ, t) for p ← exp(θ / scale)·(p − c) + c + t: ((p − c) / scale × n, n).
      Eigen::Matrix<double, 6, 1> row;
      row << ((p - centre) / scale).cross(normal), normal;
      // The upper triangle only; the lower one is filled in once per iteration.
      for (int c = 0; c < 6; ++c) normal_matrix.col(c).head(c + 1) += row[c] * row.head(c + 1);
      rhs -= row * residual;
      sum_sq += residual * residual;
      ++inliers;
      if (find_pivot) {
        // The model's normal noise: half the squared difference to the next pixel's normal on
        // the same surface.
        const size_t next = index + 1;
        if (u + 1 < model.width && model.depth_mm[next] > 0 &&
            std::abs(model.depth_mm[next] - depth) < 2 * options.max_distance_mm) {
          normal_jitter.push_back(0.5 *
                                  (model.normals[next].cast<double>() - normal).squaredNorm());
        }
        const Eigen::Matrix3d off_normal =
            Eigen::Matrix3d::Identity() - normal * normal.transpose();
        across += off_normal;
        across_points += off_normal * p;
      }
    }
    normal_matrix.triangularView<Eigen::StrictlyLower>() = normal_matrix.transpose();
    if (find_pivot && inliers >= 6) {
      // The surface's free turns (a sphere's, a bottle's about its axis) are turns about where
      // its normal lines meet: taken about that point, they are pure turns, so keeping them at the
      // prediction does not turn the object when its position is corrected. Where the lines do
      // not meet (a plane), the pivot stays near the centroid.
      const double pull = 1e-3 * across.trace();
      const Eigen::Vector3d meet =
          (across + pull * Eigen::Matrix3d::Identity()).ldlt().solve(across_points + pull * centre);
      if (meet.allFinite() && (meet - centre).norm() < 3 * scale) {
        // Rows about the new pivot are T·rows: ((p − c′) × n) / s′ = (s/s′)·((p − c) × n) / s
        // + ((c − c′) × n) / s′.
        const double new_scale =
            std::max(1.0, std::sqrt(spread_sq + (meet - centre).squaredNorm()));
        Eigen::Matrix<double, 6, 6> to_pivot = Eigen::Matrix<double, 6, 6>::Identity();
        to_pivot.topLeftCorner<3, 3>() *= scale / new_scale;
        const Eigen::Vector3d d = centre - meet;
        to_pivot.topRightCorner<3, 3>() << 0, -d.z(), d.y(), d.z(), 0, -d.x(), -d.y(), d.x(), 0;
        to_pivot.topRightCorner<3, 3>() /= new_scale;
        normal_matrix = to_pivot * normal_matrix * to_pivot.transpose();
        rhs = to_pivot * rhs;
        pivot = meet;  // The correction is the identity in the first iteration.
        centre = meet;
        scale = new_scale;
      }
      if (!normal_jitter.empty()) {
        auto middle = normal_jitter.begin() + normal_jitter.size() / 2;
        std::nth_element(normal_jitter.begin(), middle, normal_jitter.end());
        noise_information = *middle;
      }
    }
    rms = inliers > 0 ? std::sqrt(sum_sq / inliers) : 0;
    // The anchors together weigh `anchor_share` of the surface's pairs: they decide what the
    // surface leaves open (a sphere's turn) and hardly move what it fixes.
    double anchor_total = 0;
    for (const IcpAnchor& anchor : anchors) anchor_total += anchor.weight;
    const double anchor_scale =
        anchor_total > 0 ? options.anchor_share * std::max(inliers, 1) / anchor_total : 0.0;
    Eigen::Matrix<double, 6, 6> anchor_matrix = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> anchor_rhs = Eigen::Matrix<double, 6, 1>::Zero();
    for (const IcpAnchor& anchor : anchors) {
      const double weight = anchor.weight * anchor_scale;
      const Eigen::Vector3d p = correction * anchor.current;
      const Eigen::Vector3d residual = p - anchor.target;
      for (int k = 0; k < 3; ++k) {
        Eigen::Matrix<double, 6, 1> row;
        row << ((p - centre) / scale).cross(Eigen::Vector3d::Unit(k)), Eigen::Vector3d::Unit(k);
        anchor_matrix += weight * row * row.transpose();
        anchor_rhs -= weight * row * residual[k];
      }
    }
    if (!keep_free) {
      normal_matrix += anchor_matrix;
      rhs += anchor_rhs;
    }
    if (inliers < 6) break;
    // A little (Marquardt) damping keeps directions the data do not constrain at all where the
    // prediction put them.
    normal_matrix.diagonal() *= 1.0 + 1e-4;
    normal_matrix.diagonal().array() += 1e-9;
    Eigen::Matrix<double, 6, 1> step;
    if (keep_free && noise_information > 0) {
      // Only the directions the surface constrains move; the others keep the prediction, or
      // follow the anchors where they have any.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(normal_matrix);
      const double floor = options.min_constraint_over_noise * noise_information * inliers;
      step.setZero();
      std::vector<int> free;
      for (int i = 0; i < 6; ++i) {
        const double value = eigen.eigenvalues()[i];
        if (value <= floor || value <= 0) {
          free.push_back(i);
          continue;
        }
        const auto direction = eigen.eigenvectors().col(i);
        step += direction * (direction.dot(rhs) / value);
      }
      if (!free.empty() && !anchors.empty())
        step += AnchorStep(eigen.eigenvectors(), free, anchor_matrix, anchor_rhs, step);
    } else if (keep_free) {
      // No measure of the normals' noise to tell free directions by: the anchors join in.
      step = (normal_matrix + anchor_matrix).ldlt().solve(rhs + anchor_rhs);
    } else {
      step = normal_matrix.ldlt().solve(rhs);
    }
    if (!step.allFinite()) break;
    const Rigid3 turn = Rigid3::FromRotationVector(step.head<3>() / scale, Eigen::Vector3d::Zero());
    correction = Rigid3::Translation(centre + step.tail<3>()) * turn *
                 Rigid3::Translation(-centre) * correction;
    result.iterations = iteration + 1;
    if (step.tail<3>().norm() + step.head<3>().norm() < 0.01) break;
  }
  result.inliers = inliers;
  result.rms_mm = rms;
  // correction · current = predicted (as seen): cam_from_volume = correction⁻¹ · predicted.
  result.cam_from_volume = correction.Inverse() * predicted;
  if (inliers < needed) {
    result.reason = "ICP: " + std::to_string(inliers) + " of " + std::to_string(points.size()) +
                    " points pair with the model (need " + std::to_string(needed) + ")";
    return result;
  }
  result.ok = true;
  return result;
}

}  // namespace ihs::fusion
