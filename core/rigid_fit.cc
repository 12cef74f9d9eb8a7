#include "core/rigid_fit.h"

#include <Eigen/SVD>

#include "core/check.h"

namespace ihs {

Rigid3 FitRigidTransform(const std::vector<Eigen::Vector3d>& from,
                         const std::vector<Eigen::Vector3d>& to,
                         const std::vector<double>& weights) {
  IHS_CHECK_ARG(from.size() == to.size() && !from.empty(),
                "FitRigidTransform needs two non-empty point sets of the same size");
  IHS_CHECK_ARG(
      weights.empty() || weights.size() == from.size(),
      "FitRigidTransform: " << weights.size() << " weights for " << from.size() << " points");
  auto weight = [&](size_t i) { return weights.empty() ? 1.0 : weights[i]; };
  double total = 0;
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) {
    IHS_CHECK_ARG(weight(i) >= 0, "FitRigidTransform: negative weight " << weight(i));
    total += weight(i);
    mean_from += weight(i) * from[i], mean_to += weight(i) * to[i];
  }
  IHS_CHECK_ARG(total > 0, "FitRigidTransform: all weights are zero");
  mean_from /= total, mean_to /= total;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i)
    covariance += weight(i) * (to[i] - mean_to) * (from[i] - mean_from).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d reflection = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) reflection(2, 2) = -1;
  const Eigen::Matrix3d rotation = svd.matrixU() * reflection * svd.matrixV().transpose();
  return Rigid3(rotation, mean_to - rotation * mean_from);
}

}  // namespace ihs
