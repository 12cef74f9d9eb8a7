#pragma once
// Least-squares rigid transform between corresponding point sets (Kabsch / Umeyama without
// scale), optionally weighted.

#include <Eigen/Core>
#include <vector>

#include "core/rigid3.h"

namespace ihs {

/// The rotation and translation b_from_a minimising Σ w_i·‖b_from_a·from[i] − to[i]‖² (all
/// w_i = 1 when `weights` is empty). Needs at least three non-collinear points of positive
/// weight for a unique answer; throws std::invalid_argument when the sets differ in size, are
/// empty, or the weights are negative or all zero.
Rigid3 FitRigidTransform(const std::vector<Eigen::Vector3d>& from,
                         const std::vector<Eigen::Vector3d>& to,
                         const std::vector<double>& weights = {});

}  // namespace ihs
