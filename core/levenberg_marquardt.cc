#include "core/levenberg_marquardt.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace ihs {

void LevenbergMarquardtOptions::Check() const {
  IHS_CHECK_ARG(max_iterations >= 1, "Levenberg-Marquardt max_iterations must be >= 1");
  IHS_CHECK_ARG(function_tolerance >= 0 && parameter_tolerance >= 0,
                "Levenberg-Marquardt tolerances must be >= 0");
  IHS_CHECK_ARG(initial_radius > 0, "Levenberg-Marquardt initial_radius must be positive");
  IHS_CHECK_ARG(min_relative_decrease >= 0 && min_relative_decrease < 1,
                "Levenberg-Marquardt min_relative_decrease must be in [0, 1)");
}

LevenbergMarquardtSummary MinimiseLevenbergMarquardt(const NormalEquationsFunction& evaluate,
                                                     Eigen::VectorXd* x,
                                                     const LevenbergMarquardtOptions& options) {
  options.Check();
  const Eigen::Index n = x->size();
  Eigen::MatrixXd jtj(n, n);
  Eigen::VectorXd jtr(n);
  double cost = evaluate(*x, &jtj, &jtr);
  LevenbergMarquardtSummary summary;
  summary.initial_cost = summary.final_cost = cost;
  if (n == 0 || !std::isfinite(cost)) return summary;
  // Jacobi scaling, fixed at the start: column j of J divided by 1 + ‖J_j‖.
  const Eigen::VectorXd scale = (1.0 + jtj.diagonal().array().max(0.0).sqrt()).inverse().matrix();
  double radius = options.initial_radius, decrease = 2.0;
  bool fresh = true;  // Whether jtj and jtr are those of *x.
  for (; summary.iterations < options.max_iterations; ++summary.iterations) {
    if (!fresh) cost = evaluate(*x, &jtj, &jtr), fresh = true;
    // In scaled parameters: (S·JᵀJ·S + D/radius)·δ' = −S·Jᵀr, D = diag(S·JᵀJ·S) clamped.
    const Eigen::MatrixXd scaled = scale.asDiagonal() * jtj * scale.asDiagonal();
    const Eigen::VectorXd gradient = scale.cwiseProduct(jtr);
    if (gradient.lpNorm<Eigen::Infinity>() <= 1e-10) break;
    Eigen::MatrixXd damped = scaled;
    damped.diagonal() += (scaled.diagonal().array().max(1e-6).min(1e32) / radius).matrix();
    const Eigen::LDLT<Eigen::MatrixXd> factor(damped);
    const Eigen::VectorXd scaled_step = factor.solve(-gradient);
    // The linear model's decrease: −(gᵀδ + ½δᵀAδ), in scaled parameters.
    const double model_decrease =
        -(gradient.dot(scaled_step) + 0.5 * scaled_step.dot(scaled * scaled_step));
    if (factor.info() != Eigen::Success || !scaled_step.allFinite() || !(model_decrease > 0)) {
      radius /= decrease, decrease *= 2;
      continue;
    }
    const Eigen::VectorXd step = scale.cwiseProduct(scaled_step);
    if (step.norm() <= options.parameter_tolerance * (x->norm() + options.parameter_tolerance))
      break;
    const Eigen::VectorXd candidate = *x + step;
    const double candidate_cost = evaluate(candidate, nullptr, nullptr);
    if (std::abs(cost - candidate_cost) <= options.function_tolerance * cost) break;
    const double quality = (cost - candidate_cost) / model_decrease;
    if (std::isfinite(candidate_cost) && quality > options.min_relative_decrease) {
      *x = candidate;
      cost = summary.final_cost = candidate_cost;
      fresh = false;
      ++summary.successful_steps;
      radius /= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * quality - 1.0, 3));
      radius = std::min(radius, 1e16);
      decrease = 2.0;
    } else {
      radius /= decrease, decrease *= 2;
    }
  }
  return summary;
}

}  // namespace ihs
