// The dense Levenberg–Marquardt minimiser: known minima of small least-squares problems reached
// from poor starts, its stopping rules, and bad options refused.

#include "core/levenberg_marquardt.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace ihs {
namespace {

// Rosenbrock's valley as least squares: r = (10·(y − x²), 1 − x), minimum 0 at (1, 1).
double Rosenbrock(const Eigen::VectorXd& p, Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr) {
  const Eigen::Vector2d r(10 * (p[1] - p[0] * p[0]), 1 - p[0]);
  if (jtj && jtr) {
    Eigen::Matrix2d j;
    j << -20 * p[0], 10, -1, 0;
    *jtj = j.transpose() * j;
    *jtr = j.transpose() * r;
  }
  return 0.5 * r.squaredNorm();
}

TEST(LevenbergMarquardtTest, FindsTheBottomOfRosenbrocksValleyFromTheClassicStart) {
  Eigen::VectorXd x(2);
  x << -1.2, 1.0;
  LevenbergMarquardtOptions options;
  options.max_iterations = 100;
  options.function_tolerance = 1e-12;
  const LevenbergMarquardtSummary summary = MinimiseLevenbergMarquardt(Rosenbrock, &x, options);
  EXPECT_NEAR(x[0], 1.0, 1e-5);
  EXPECT_NEAR(x[1], 1.0, 1e-5);
  EXPECT_NEAR(summary.initial_cost, 12.1, 1e-9);
  EXPECT_LT(summary.final_cost, 1e-10);
  EXPECT_GT(summary.successful_steps, 5);
  EXPECT_LE(summary.iterations, 100);
}

// y = a·exp(b·t) + c sampled at 30 points, fitted from a start far off.
TEST(LevenbergMarquardtTest, FitsAnExponentialCurveToItsSamples) {
  const double a = 2.5, b = -1.3, c = 0.7;
  std::vector<double> t, y;
  for (int i = 0; i < 30; ++i) t.push_back(0.1 * i), y.push_back(a * std::exp(b * t.back()) + c);
  auto curve = [&](const Eigen::VectorXd& p, Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr) {
    double cost = 0;
    if (jtj && jtr) jtj->setZero(3, 3), jtr->setZero(3);
    for (size_t i = 0; i < t.size(); ++i) {
      const double e = std::exp(p[1] * t[i]);
      const double r = p[0] * e + p[2] - y[i];
      cost += 0.5 * r * r;
      if (jtj && jtr) {
        const Eigen::Vector3d g(e, p[0] * t[i] * e, 1.0);
        *jtj += g * g.transpose();
        *jtr += g * r;
      }
    }
    return cost;
  };
  Eigen::VectorXd x(3);
  x << 1.0, 0.0, 0.0;
  LevenbergMarquardtOptions options;
  options.function_tolerance = 1e-14;
  MinimiseLevenbergMarquardt(curve, &x, options);
  EXPECT_NEAR(x[0], a, 1e-6);
  EXPECT_NEAR(x[1], b, 1e-6);
  EXPECT_NEAR(x[2], c, 1e-6);
}

TEST(LevenbergMarquardtTest, StopsAfterItsIterationsAndNeverRaisesTheCost) {
  Eigen::VectorXd x(2);
  x << -1.2, 1.0;
  LevenbergMarquardtOptions options;
  options.max_iterations = 3;
  const LevenbergMarquardtSummary summary = MinimiseLevenbergMarquardt(Rosenbrock, &x, options);
  EXPECT_EQ(summary.iterations, 3);
  EXPECT_LE(summary.final_cost, summary.initial_cost);
  EXPECT_DOUBLE_EQ(Rosenbrock(x, nullptr, nullptr), summary.final_cost);
  EXPECT_GT(std::abs(x[0] - 1.0), 1e-3);  // Not there yet after three steps.
}

TEST(LevenbergMarquardtTest, AStepThatWouldChangeTheCostByLessThanTheToleranceIsNotTaken) {
  Eigen::VectorXd x(2);
  x << 1.0 + 1e-4, 1.0;  // Near the minimum: any step changes the cost by a tiny amount...
  LevenbergMarquardtOptions options;
  options.function_tolerance = 2.0;  // ...less than twice the cost itself.
  const LevenbergMarquardtSummary summary = MinimiseLevenbergMarquardt(Rosenbrock, &x, options);
  EXPECT_EQ(summary.successful_steps, 0);
  EXPECT_EQ(x[0], 1.0 + 1e-4);
}

TEST(LevenbergMarquardtTest, RefusesBadOptions) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  LevenbergMarquardtOptions options;
  options.max_iterations = 0;
  EXPECT_THROW(MinimiseLevenbergMarquardt(Rosenbrock, &x, options), std::invalid_argument);
  options = {};
  options.initial_radius = 0;
  EXPECT_THROW(MinimiseLevenbergMarquardt(Rosenbrock, &x, options), std::invalid_argument);
}

}  // namespace
}  // namespace ihs
