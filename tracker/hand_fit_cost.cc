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

template <class Sink>
void HandFitCost::Rows(const double* x, bool derivatives, Sink&& sink) const {
  const int n = derivatives_.size();
  derivatives_.Evaluate(reference_, x);
  std::vector<double> point_jacobian(3 * n), jacobian_b(3 * n), gradient(n), rows3(3 * n);
  std::vector<int> columns;
  double* const jp = derivatives ? point_jacobian.data() : nullptr;
  auto skinned = [&](int vertex) {
    if (derivatives) derivatives_.Columns(model_.weights[vertex], &columns);
    return derivatives_.SkinnedPoint(model_.weights[vertex], model_.rest_mesh.vertices[vertex], jp);
  };
  // Row r of the point's Jacobian times `w`, over the point's columns.
  auto scaled_row = [&](int r, double w) {
    if (!derivatives) return;
    for (int c : columns) gradient[c] = w * point_jacobian[r * n + c];
  };
  for (const PointPair& pair : terms_.points) {
    const Eigen::Vector3d p = skinned(pair.vertex);
    for (int r = 0; r < 3; ++r) {
      scaled_row(r, pair.weight);
      sink(pair.weight * (p[r] - pair.target[r]), gradient.data(), columns);
    }
  }
  for (const PlanePair& pair : terms_.planes) {
    const Eigen::Vector3d p = skinned(pair.vertex);
    const Eigen::Vector3d& normal = pair.normal;
    if (pair.point_weight <= 0) {
      if (derivatives) {
        for (int c : columns) {
          double d = 0;
          for (int r = 0; r < 3; ++r) d += normal[r] * point_jacobian[r * n + c];
          gradient[c] = pair.weight * d;
        }
      }
      sink(pair.weight * normal.dot(p - pair.target), gradient.data(), columns);
      continue;
    }
    // A = p·I + b·n·nᵀ, b = √(p² + w²) − p: normal component weighted √(p² + w²), tangential p.
    const double a = pair.point_weight;
    const double b = std::sqrt(a * a + pair.weight * pair.weight) - a;
    const Eigen::Vector3d residual =
        a * (p - pair.target) + b * normal.dot(p - pair.target) * normal;
    if (derivatives) {
      for (int c : columns) {
        const Eigen::Vector3d column(point_jacobian[c], point_jacobian[n + c],
                                     point_jacobian[2 * n + c]);
        const double along_normal = b * normal.dot(column);
        for (int r = 0; r < 3; ++r) rows3[r * n + c] = a * column[r] + along_normal * normal[r];
      }
    }
    for (int r = 0; r < 3; ++r) sink(residual[r], rows3.data() + r * n, columns);
  }
  for (const SilhouettePair& pair : terms_.silhouette) {
    const Eigen::Vector3d p = skinned(pair.vertex);
    const double z = std::max(p.z(), 1.0), focal[2] = {intrinsics_.fx, intrinsics_.fy};
    const Eigen::Vector2d pixel = intrinsics_.Project(Eigen::Vector3d(p.x(), p.y(), z));
    for (int r = 0; r < 2; ++r) {
      // d(f·p_r/z + c) = f/z·dp_r − f·p_r/z²·dz.
      if (derivatives) {
        for (int c : columns) {
          gradient[c] = pair.weight * focal[r] / z *
                        (point_jacobian[r * n + c] - p[r] / z * point_jacobian[2 * n + c]);
        }
      }
      sink(pair.weight * (pixel[r] - pair.target[r]), gradient.data(), columns);
    }
  }
  static const std::vector<int> kNone;
  for (const CollisionPair& pair : terms_.collisions) {
    const Eigen::Vector3d a = derivatives_.BonePoint(pair.bone_a, pair.point_a, jp);
    const Eigen::Vector3d b = derivatives_.BonePoint(pair.bone_b, pair.point_b,
                                                     derivatives ? jacobian_b.data() : nullptr);
    const double distance = (a - b).norm();
    const double depth = pair.radius_a + pair.radius_b - distance;
    if (!(depth > 0)) {
      sink(0.0, gradient.data(), kNone);
      continue;
    }
    const bool moves = derivatives && distance > 1e-9;
    if (moves) {
      derivatives_.Columns(pair.bone_a, pair.bone_b, &columns);
      const Eigen::Vector3d normal = (a - b) / distance;
      for (int c : columns) {
        double d = 0;
        for (int r = 0; r < 3; ++r)
          d += normal[r] * (point_jacobian[r * n + c] - jacobian_b[r * n + c]);
        gradient[c] = -collision_sqrt_ * d;
      }
    }
    sink(collision_sqrt_ * depth, gradient.data(), moves ? columns : kNone);
  }
  for (size_t k = 0; k < dofs_.size(); ++k) {
    const auto [lo_deg, hi_deg] = model_.limits[dofs_[k].bone].limits_deg[dofs_[k].axis];
    const double angle = x[6 + k], lo = lo_deg * M_PI / 180, hi = hi_deg * M_PI / 180;
    const double excess = angle > hi ? angle - hi : (angle < lo ? angle - lo : 0.0);
    const int c = 6 + static_cast<int>(k);
    columns.assign({c});
    gradient[c] = excess != 0 ? limit_weight_ : 0.0;
    sink(limit_weight_ * excess, gradient.data(), derivatives ? columns : kNone);
    gradient[c] = prior_weight_;
    sink(prior_weight_ * (angle - prior_[k]), gradient.data(), derivatives ? columns : kNone);
  }
}

bool HandFitCost::Evaluate(double const* const* parameters, double* residuals,
                           double** jacobians) const {
  const int n = derivatives_.size();
  double* jacobian = jacobians ? jacobians[0] : nullptr;
  if (jacobian) std::fill(jacobian, jacobian + static_cast<size_t>(num_residuals()) * n, 0.0);
  int row = 0;
  Rows(parameters[0], jacobian != nullptr,
       [&](double residual, const double* gradient, const std::vector<int>& columns) {
         residuals[row] = residual;
         for (int c : columns) jacobian[static_cast<size_t>(row) * n + c] = gradient[c];
         ++row;
       });
  return true;
}

double HandFitCost::NormalEquations(const double* x, Eigen::MatrixXd* jtj,
                                    Eigen::VectorXd* jtr) const {
  const int n = derivatives_.size();
  const bool derivatives = jtj != nullptr && jtr != nullptr;
  if (derivatives) jtj->setZero(n, n), jtr->setZero(n);
  double cost = 0;
  Rows(x, derivatives,
       [&](double residual, const double* gradient, const std::vector<int>& columns) {
         cost += 0.5 * residual * residual;
         // The upper triangle, over the row's non-zero columns.
         for (size_t i = 0; i < columns.size(); ++i) {
           const int ci = columns[i];
           const double gi = gradient[ci];
           (*jtr)[ci] += gi * residual;
           double* column = jtj->data() + static_cast<size_t>(ci) * n;
           for (size_t j = 0; j <= i; ++j) column[columns[j]] += gi * gradient[columns[j]];
         }
       });
  if (derivatives) jtj->triangularView<Eigen::StrictlyLower>() = jtj->transpose().eval();
  return cost;
}

}  // namespace ihs::tracker
