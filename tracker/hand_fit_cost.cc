#include "tracker/hand_fit_cost.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace ihs::tracker {

HandFitCost::HandFitCost(const HandModel& model, const Eigen::Matrix3d& reference_rotation,
                         const CameraIntrinsics& intrinsics, HandFitTerms terms,
                         double collision_weight, double limit_weight, double prior_weight,
                         std::vector<double> prior_rad)
    : model_(model),
      reference_(reference_rotation),
      intrinsics_(intrinsics),
      terms_(std::move(terms)),
      collision_sqrt_(std::sqrt(collision_weight)),
      limit_weight_(limit_weight),
      prior_weight_(prior_weight),
      prior_(std::move(prior_rad)),
      dofs_(JointDegreesOfFreedom(model)),
      derivatives_(model) {
  IHS_CHECK(prior_.size() == dofs_.size(),
            "prior has " << prior_.size() << " angles, the model " << dofs_.size());
  const int n = derivatives_.size();
  size_t plane_rows = 0;
  for (const PlanePair& pair : terms_.planes) plane_rows += pair.point_weight > 0 ? 3 : 1;
  set_num_residuals(static_cast<int>(3 * terms_.points.size() + plane_rows +
                                     2 * terms_.silhouette.size() + terms_.collisions.size() +
                                     2 * dofs_.size()));
  mutable_parameter_block_sizes()->push_back(n);
}

bool HandFitCost::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  const double* x = parameters[0];
  const int n = derivatives_.size();
  derivatives_.Evaluate(reference_, x);
  double* jacobian = jacobians ? jacobians[0] : nullptr;
  if (jacobian) std::fill(jacobian, jacobian + static_cast<size_t>(num_residuals()) * n, 0.0);
  int row = 0;
  std::vector<double> point_jacobian(3 * n);
  auto skinned = [&](int vertex) {
    return derivatives_.SkinnedPoint(model_.weights[vertex], model_.rest_mesh.vertices[vertex],
                                     jacobian ? point_jacobian.data() : nullptr);
  };
  for (const PointPair& pair : terms_.points) {
    const Eigen::Vector3d p = skinned(pair.vertex);
    for (int r = 0; r < 3; ++r) {
      residuals[row + r] = pair.weight * (p[r] - pair.target[r]);
      if (jacobian) {
        for (int c = 0; c < n; ++c)
          jacobian[(row + r) * n + c] = pair.weight * point_jacobian[r * n + c];
      }
    }
    row += 3;
  }
  for (const PlanePair& pair : terms_.planes) {
    const Eigen::Vector3d p = skinned(pair.vertex);
    const Eigen::Vector3d& normal = pair.normal;
    if (pair.point_weight <= 0) {
      residuals[row] = pair.weight * normal.dot(p - pair.target);
      if (jacobian) {
        for (int c = 0; c < n; ++c) {
          double d = 0;
          for (int r = 0; r < 3; ++r) d += normal[r] * point_jacobian[r * n + c];
          jacobian[row * n + c] = pair.weight * d;
        }
      }
      ++row;
      continue;
    }
    // A = p·I + b·n·nᵀ, b = √(p² + w²) − p: normal component weighted √(p² + w²), tangential p.
    const double a = pair.point_weight;
    const double b = std::sqrt(a * a + pair.weight * pair.weight) - a;
    const Eigen::Vector3d residual =
        a * (p - pair.target) + b * normal.dot(p - pair.target) * normal;
    for (int r = 0; r < 3; ++r) residuals[row + r] = residual[r];
    if (jacobian) {
      for (int c = 0; c < n; ++c) {
        const Eigen::Vector3d column(point_jacobian[c], point_jacobian[n + c],
                                     point_jacobian[2 * n + c]);
        const Eigen::Vector3d d = a * column + b * normal.dot(column) * normal;
        for (int r = 0; r < 3; ++r) jacobian[(row + r) * n + c] = d[r];
      }
    }
    row += 3;
  }
  for (const SilhouettePair& pair : terms_.silhouette) {
    const Eigen::Vector3d p = skinned(pair.vertex);
    const double z = std::max(p.z(), 1.0), focal[2] = {intrinsics_.fx, intrinsics_.fy};
    const Eigen::Vector2d pixel = intrinsics_.Project(Eigen::Vector3d(p.x(), p.y(), z));
    for (int r = 0; r < 2; ++r) {
      residuals[row + r] = pair.weight * (pixel[r] - pair.target[r]);
      if (jacobian) {
        // d(f·p_r/z + c) = f/z·dp_r − f·p_r/z²·dz.
        for (int c = 0; c < n; ++c) {
          jacobian[(row + r) * n + c] =
              pair.weight * focal[r] / z *
              (point_jacobian[r * n + c] - p[r] / z * point_jacobian[2 * n + c]);
        }
      }
    }
    row += 2;
  }
  std::vector<double> jacobian_b(3 * n);
  for (const CollisionPair& pair : terms_.collisions) {
    const Eigen::Vector3d a = derivatives_.BonePoint(pair.bone_a, pair.point_a,
                                                     jacobian ? point_jacobian.data() : nullptr);
    const Eigen::Vector3d b =
        derivatives_.BonePoint(pair.bone_b, pair.point_b, jacobian ? jacobian_b.data() : nullptr);
    const double distance = (a - b).norm();
    const double depth = pair.radius_a + pair.radius_b - distance;
    residuals[row] = depth > 0 ? collision_sqrt_ * depth : 0.0;
    if (jacobian && depth > 0 && distance > 1e-9) {
      const Eigen::Vector3d normal = (a - b) / distance;
      for (int c = 0; c < n; ++c) {
        double d = 0;
        for (int r = 0; r < 3; ++r)
          d += normal[r] * (point_jacobian[r * n + c] - jacobian_b[r * n + c]);
        jacobian[row * n + c] = -collision_sqrt_ * d;
      }
    }
    ++row;
  }
  for (size_t k = 0; k < dofs_.size(); ++k) {
    const auto [lo_deg, hi_deg] = model_.limits[dofs_[k].bone].limits_deg[dofs_[k].axis];
    const double angle = x[6 + k], lo = lo_deg * M_PI / 180, hi = hi_deg * M_PI / 180;
    const double excess = angle > hi ? angle - hi : (angle < lo ? angle - lo : 0.0);
    residuals[row] = limit_weight_ * excess;
    if (jacobian && excess != 0) jacobian[row * n + 6 + k] = limit_weight_;
    ++row;
    residuals[row] = prior_weight_ * (angle - prior_[k]);
    if (jacobian) jacobian[row * n + 6 + k] = prior_weight_;
    ++row;
  }
  return true;
}

}  // namespace ihs::tracker
