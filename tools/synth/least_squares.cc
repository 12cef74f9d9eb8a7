#include "tools/synth/least_squares.h"

#include <Eigen/Cholesky>

namespace ihs::synth {

Eigen::VectorXd SolveLeastSquares(const ResidualFunction& residuals, Eigen::VectorXd x,
                                  const LeastSquaresOptions& options) {
  Eigen::VectorXd r = residuals(x);
  double cost = r.squaredNorm();
  double lambda = 1e-3;
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    Eigen::MatrixXd jacobian(r.size(), x.size());
    for (int k = 0; k < x.size(); ++k) {
      Eigen::VectorXd shifted = x;
      shifted[k] += options.step;
      jacobian.col(k) = (residuals(shifted) - r) / options.step;
    }
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    const Eigen::VectorXd gradient = jacobian.transpose() * r;
    bool improved = false;
    while (lambda < 1e10) {
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += lambda * (normal.diagonal().array() + 1e-9).matrix();
      const Eigen::VectorXd candidate = x - damped.ldlt().solve(gradient);
      const Eigen::VectorXd candidate_r = residuals(candidate);
      const double candidate_cost = candidate_r.squaredNorm();
      if (candidate_cost < cost) {
        const double decrease = (cost - candidate_cost) / std::max(cost, 1e-300);
        x = candidate, r = candidate_r, cost = candidate_cost;
        lambda = std::max(lambda / 3, 1e-9);
        improved = decrease > options.tolerance;
        break;
      }
      lambda *= 4;
    }
    if (!improved) break;
  }
  return x;
}

}  // namespace ihs::synth
