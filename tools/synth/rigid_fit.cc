#include "tools/synth/rigid_fit.h"

#include <Eigen/SVD>

#include "core/check.h"

namespace ihs::synth {

Rigid3 FitRigidTransform(const std::vector<Eigen::Vector3d>& from,
                         const std::vector<Eigen::Vector3d>& to) {
  IHS_CHECK_ARG(from.size() == to.size() && !from.empty(),
                "FitRigidTransform needs two non-empty point sets of the same size");
  Eigen::Vector3d mean_from = Eigen::Vector3d::Zero(), mean_to = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < from.size(); ++i) mean_from += from[i], mean_to += to[i];
  mean_from /= static_cast<double>(from.size());
  mean_to /= static_cast<double>(to.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < from.size(); ++i)
    covariance += (to[i] - mean_to) * (from[i] - mean_from).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d reflection = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) reflection(2, 2) = -1;
  const Eigen::Matrix3d rotation = svd.matrixU() * reflection * svd.matrixV().transpose();
  return Rigid3(rotation, mean_to - rotation * mean_from);
}

}  // namespace ihs::synth
