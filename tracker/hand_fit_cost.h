#pragma once
// Internal to the tracker (included by hand_fit.cc, hand_fit_cost.cc and their test only, as it
// brings in Ceres): the least-squares cost of one inner hand-fit problem, with analytic
// derivatives.

#include <ceres/ceres.h>

#include <Eigen/Core>
#include <vector>

#include "core/camera_intrinsics.h"
#include "tracker/hand_kinematics.h"
#include "tracker/hand_model.h"

namespace ihs::tracker {

/// A model vertex that should lie at `target` (camera frame, mm), weighted.
struct PointPair {
  int vertex = 0;
  Eigen::Vector3d target;
  double weight = 1.0;
};

/// A model vertex that should lie on the plane through `target` with unit `normal` (camera
/// frame), weighted: a point-to-plane pair. With `point_weight` > 0 the same vertex is also
/// pulled to `target` itself; both terms then share one three-row residual (see HandFitCost).
struct PlanePair {
  int vertex = 0;
  Eigen::Vector3d target;
  Eigen::Vector3d normal;
  double weight = 1.0;
  double point_weight = 0.0;
};

/// A model vertex whose image should lie at pixel `target` (the nearest pixel of the observed
/// silhouette), weighted per pixel (the weight carries the mm per pixel at the vertex's depth).
struct SilhouettePair {
  int vertex = 0;
  Eigen::Vector2d target;
  double weight = 1.0;
};

/// Two capsules (points on their axes fixed in their bones' frames) that must stay apart by the
/// sum of their radii.
struct CollisionPair {
  int bone_a = 0;
  Eigen::Vector3d point_a;
  double radius_a = 0;
  int bone_b = 0;
  Eigen::Vector3d point_b;
  double radius_b = 0;
};

/// The terms of one inner problem.
struct HandFitTerms {
  std::vector<PointPair> points;
  std::vector<PlanePair> planes;
  std::vector<SilhouettePair> silhouette;
  std::vector<CollisionPair> collisions;
};

/// Residuals: for each point pair w·(x_v − target) (3), for each plane pair w·n·(x_v − target)
/// (1) or, with a point weight p, A·(x_v − target) with A = p·I + (√(p² + w²) − p)·n·nᵀ (3: its
/// square is exactly w²(n·d)² + p²|d|², a plane pair plus a point pair of the same vertex),
/// for each silhouette pair w·(π(x_v) − target) (2, π the camera's projection), for each
/// collision √γc·max(0, r_a + r_b − |A − B|), for each joint angle the soft limit excess
/// (limit_weight per rad) and the pull toward `prior_rad` (prior_weight per rad). One parameter
/// block: the PoseParameters vector.
class HandFitCost : public ceres::CostFunction {
 public:
  HandFitCost(const HandModel& model, const Eigen::Matrix3d& reference_rotation,
              const CameraIntrinsics& intrinsics, HandFitTerms terms, double collision_weight,
              double limit_weight, double prior_weight, std::vector<double> prior_rad);

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;
  /// ½‖r(x)‖² at the PoseParameters vector `x`; where `jtj` and `jtr` are given, also JᵀJ and
  /// Jᵀr (for MinimiseLevenbergMarquardt), each residual's products taken over the parameters
  /// that move it only (the root's six and its bones' chains: a third of them or fewer).
  double NormalEquations(const double* x, Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr) const;

 private:
  // Evaluates the residuals at `x` in Evaluate's order and hands each to `sink(residual,
  // gradient, columns)`: with `derivatives`, gradient[c] for c in columns (ascending) holds the
  // row's non-zero derivatives (elsewhere it is undefined); without, columns is empty.
  template <class Sink>
  void Rows(const double* x, bool derivatives, Sink&& sink) const;

  const HandModel& model_;
  const Eigen::Matrix3d reference_;
  const CameraIntrinsics intrinsics_;
  const HandFitTerms terms_;
  const double collision_sqrt_;
  const double limit_weight_;
  const double prior_weight_;
  const std::vector<double> prior_;
  const std::vector<DegreeOfFreedom> dofs_;
  mutable PoseDerivatives derivatives_;
};

}  // namespace ihs::tracker
