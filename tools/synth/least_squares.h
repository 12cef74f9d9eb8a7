#pragma once
// A small dense Levenberg–Marquardt solver with a forward-difference Jacobian, for the
// generator's few-parameter problems (grasp inverse kinematics, object placement). Ground truth
// deliberately does not depend on the tracker's solver.

#include <Eigen/Core>
#include <functional>

namespace ihs::synth {

/// Residuals r(x) of a least-squares problem; the size may not change between calls.
using ResidualFunction = std::function<Eigen::VectorXd(const Eigen::VectorXd& x)>;

/// Options of SolveLeastSquares.
struct LeastSquaresOptions {
  int max_iterations = 100;
  /// Forward-difference step per parameter.
  double step = 1e-6;
  /// Stop when the relative decrease of the cost falls below this.
  double tolerance = 1e-10;
};

/// Minimises ½‖r(x)‖² from `x`, returning the best x found.
Eigen::VectorXd SolveLeastSquares(const ResidualFunction& residuals, Eigen::VectorXd x,
                                  const LeastSquaresOptions& options = {});

}  // namespace ihs::synth
