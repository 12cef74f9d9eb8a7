#pragma once
// A small dense Levenberg–Marquardt minimiser for least-squares problems that hand it their
// normal equations (JᵀJ, Jᵀr) instead of their Jacobian: a problem whose residuals each touch a
// few of its parameters accumulates those products over the few, where a general solver forms
// and multiplies the whole dense Jacobian. The strategy is the textbook one as Ceres implements
// it (Jacobi scaling fixed at the start, the trust region's 1/λ grown by the step's quality),
// so that a problem moved over from Ceres' LEVENBERG_MARQUARDT steps alike.
#include <Eigen/Core>
#include <functional>

namespace ihs {

/// Options of MinimiseLevenbergMarquardt; the defaults are Ceres' where Ceres has the option.
struct LevenbergMarquardtOptions {
  /// Steps tried (taken or not), at most.
  int max_iterations = 50;
  /// Stop, without taking it, at a step that changes the cost by less than this share of it.
  double function_tolerance = 1e-6;
  /// Stop at a step shorter than this share of the parameters' norm.
  double parameter_tolerance = 1e-8;
  /// The trust region's radius at the start: the damping is diag(JᵀJ) / radius.
  double initial_radius = 1e4;
  /// A step is taken when the cost falls by at least this share of what the linear model
  /// predicted.
  double min_relative_decrease = 1e-3;
  void Check() const;
};

/// The cost ½‖r(x)‖² at `x`; where `jtj` and `jtr` are given, also JᵀJ (full, n × n) and Jᵀr.
using NormalEquationsFunction =
    std::function<double(const Eigen::VectorXd& x, Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr)>;

struct LevenbergMarquardtSummary {
  double initial_cost = 0;
  double final_cost = 0;
  int iterations = 0;        // Steps tried.
  int successful_steps = 0;  // Steps taken.
};

/// Minimises the cost from `x`, which it moves to the best point found.
LevenbergMarquardtSummary MinimiseLevenbergMarquardt(const NormalEquationsFunction& evaluate,
                                                     Eigen::VectorXd* x,
                                                     const LevenbergMarquardtOptions& options = {});

}  // namespace ihs
