#pragma once
// Least-squares rigid transform between corresponding point sets (Kabsch / Umeyama without
// scale).

#include <Eigen/Core>
#include <vector>

#include "core/rigid3.h"

namespace ihs::synth {

/// The rotation and translation b_from_a minimising Σ‖b_from_a·from[i] − to[i]‖². Needs at least
/// three non-collinear points for a unique answer; `from` and `to` must have the same size.
Rigid3 FitRigidTransform(const std::vector<Eigen::Vector3d>& from,
                         const std::vector<Eigen::Vector3d>& to);

}  // namespace ihs::synth
