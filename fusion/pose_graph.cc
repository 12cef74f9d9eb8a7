#include "fusion/pose_graph.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "core/check.h"

namespace ihs::fusion {
namespace {

// A node's parameters: object_from_cam as an angle-axis turn and a translation.
using NodeParameters = std::array<double, 6>;

NodeParameters ToParameters(const Rigid3& cam_from_object) {
  const Rigid3 object_from_cam = cam_from_object.Inverse();
  const Eigen::Vector3d axis_angle = object_from_cam.RotationVector();
  const Eigen::Vector3d t = object_from_cam.translation();
  return {axis_angle.x(), axis_angle.y(), axis_angle.z(), t.x(), t.y(), t.z()};
}

Rigid3 FromParameters(const NodeParameters& p) {
  return Rigid3::FromRotationVector({p[0], p[1], p[2]}, {p[3], p[4], p[5]}).Inverse();
}

// The object-frame points an edge's disagreement is measured at, and their weights: the
// origin and three points `lever` along the axes; for a spin-free edge with an axis, also two
// points on the axis, the first four then weighing `spin_weight` of them.
constexpr int kEdgePoints = 6;
struct EdgePoints {
  std::array<Eigen::Vector3d, kEdgePoints> at;
  std::array<double, kEdgePoints> weight;
};

EdgePoints PointsOf(const PoseGraphEdge& edge, const PoseGraphOptions& options,
                    const std::optional<SpinAxis>& axis) {
  EdgePoints points;
  const bool spin = edge.spin_free && axis.has_value();
  for (int n = 0; n < 4; ++n) {
    points.at[n] = Eigen::Vector3d::Zero();
    if (n > 0) points.at[n][n - 1] = options.lever_mm;
    points.weight[n] = edge.weight * (spin ? options.spin_weight : 1.0);
  }
  for (int n = 4; n < kEdgePoints; ++n) {
    points.at[n] = spin ? Eigen::Vector3d(axis->point +
                                          (n - 4) * options.lever_mm * axis->direction.normalized())
                        : Eigen::Vector3d::Zero();
    points.weight[n] = spin ? edge.weight : 0.0;
  }
  return points;
}

// The edge's disagreement: object_from_cam_to · to_from_from · cam_from_from_object should be
// the identity; the residual is how far it moves the edge's points, weighed.
class EdgeCost {
 public:
  EdgeCost(const Rigid3& to_from_from, EdgePoints points) : points_(std::move(points)) {
    const Eigen::Vector3d axis_angle = to_from_from.RotationVector();
    for (int i = 0; i < 3; ++i) {
      turn_[i] = axis_angle[i];
      shift_[i] = to_from_from.translation()[i];
    }
  }

  template <typename T>
  bool operator()(const T* from, const T* to, T* residuals) const {
    const T back[3] = {-from[0], -from[1], -from[2]};
    const T measured[3] = {T(turn_[0]), T(turn_[1]), T(turn_[2])};
    for (int n = 0; n < kEdgePoints; ++n) {
      const T p[3] = {T(points_.at[n].x()), T(points_.at[n].y()), T(points_.at[n].z())};
      // p (object) → camera `from` → camera `to` → object.
      const T local[3] = {p[0] - from[3], p[1] - from[4], p[2] - from[5]};
      T in_from[3], in_to[3], back_in_object[3];
      ceres::AngleAxisRotatePoint(back, local, in_from);
      ceres::AngleAxisRotatePoint(measured, in_from, in_to);
      for (int i = 0; i < 3; ++i) in_to[i] += T(shift_[i]);
      ceres::AngleAxisRotatePoint(to, in_to, back_in_object);
      for (int i = 0; i < 3; ++i)
        residuals[3 * n + i] = T(points_.weight[n]) * (back_in_object[i] + to[3 + i] - p[i]);
    }
    return true;
  }

 private:
  EdgePoints points_;
  double turn_[3];
  double shift_[3];
};

}  // namespace

void PoseGraphOptions::Check() const {
  IHS_CHECK_ARG(lever_mm > 0, "pose graph lever_mm must be positive");
  IHS_CHECK_ARG(spin_weight > 0 && spin_weight <= 1, "pose graph spin_weight must be in (0, 1]");
  IHS_CHECK_ARG(max_iterations >= 1, "pose graph max_iterations must be >= 1");
}

std::vector<Rigid3> SolvePoseGraph(const std::vector<Rigid3>& cam_from_object,
                                   const std::vector<PoseGraphEdge>& edges,
                                   const PoseGraphOptions& options,
                                   const std::optional<SpinAxis>& spin_axis) {
  options.Check();
  const int nodes = static_cast<int>(cam_from_object.size());
  std::vector<NodeParameters> parameters;
  for (const Rigid3& pose : cam_from_object) parameters.push_back(ToParameters(pose));
  ceres::Problem problem;
  for (const PoseGraphEdge& edge : edges) {
    IHS_CHECK_ARG(
        edge.from >= 0 && edge.from < nodes && edge.to >= 0 && edge.to < nodes &&
            edge.from != edge.to,
        "pose graph edge " << edge.from << " -> " << edge.to << " of " << nodes << " nodes");
    auto* cost = new ceres::AutoDiffCostFunction<EdgeCost, 3 * kEdgePoints, 6, 6>(
        new EdgeCost(edge.to_from_from, PointsOf(edge, options, spin_axis)));
    problem.AddResidualBlock(cost, nullptr, parameters[edge.from].data(),
                             parameters[edge.to].data());
  }
  if (problem.NumResidualBlocks() == 0 || !problem.HasParameterBlock(parameters[0].data())) {
    return cam_from_object;
  }
  problem.SetParameterBlockConstant(parameters[0].data());
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.num_threads = 1;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  std::vector<Rigid3> solved;
  for (const NodeParameters& p : parameters) solved.push_back(FromParameters(p));
  return solved;
}

std::optional<SpinAxis> ScrewAxis(const Rigid3& correction, double min_deg) {
  const Eigen::Vector3d turn = correction.RotationVector();
  if (turn.norm() < min_deg * M_PI / 180.0) return std::nullopt;
  SpinAxis axis;
  axis.direction = turn.normalized();
  // The points the correction leaves on their line: (I - R) a = t less its part along the
  // axis; the least-squares solution nearest the origin.
  const Eigen::Vector3d t = correction.translation();
  const Eigen::Vector3d across = t - t.dot(axis.direction) * axis.direction;
  const Eigen::Matrix3d m = Eigen::Matrix3d::Identity() - correction.rotation();
  axis.point = m.completeOrthogonalDecomposition().solve(across);
  return axis;
}

double PoseDistanceMm(const Rigid3& a, const Rigid3& b, double lever_mm) {
  // Both poses seen from the object: how far apart they put the same points.
  const Rigid3 difference = b.Inverse() * a;
  double largest = 0;
  for (int n = 0; n < 4; ++n) {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    if (n > 0) p[n - 1] = lever_mm;
    largest = std::max(largest, (difference * p - p).norm());
  }
  return largest;
}

}  // namespace ihs::fusion
