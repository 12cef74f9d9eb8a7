#include "fusion/view_coverage.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace ihs::fusion {

void ViewCoverageOptions::Check() const {
  if (directions < 12 || directions > 100000)
    throw std::invalid_argument("view_coverage.directions must be in [12, 100000], got " +
                                std::to_string(directions));
  if (!(max_incidence_deg > 0 && max_incidence_deg <= 90))
    throw std::invalid_argument("view_coverage.max_incidence_deg must be in (0, 90], got " +
                                std::to_string(max_incidence_deg));
}

ViewCoverage::ViewCoverage(ViewCoverageOptions options)
    : cos_max_incidence_((options.Check(),
                          std::cos(options.max_incidence_deg * std::numbers::pi / 180.0))) {
  // A Fibonacci lattice: equal areas in z, the golden angle around it.
  const int n = options.directions;
  const double golden_angle = std::numbers::pi * (3.0 - std::sqrt(5.0));
  directions_.reserve(n);
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden_angle * i;
    directions_.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
  }
  seen_.assign(n, 0);
}

void ViewCoverage::Observe(const Rigid3& cam_from_object, const Eigen::Vector3d& centre) {
  // The camera's centre in the object frame, and the direction to it from the object.
  const Eigen::Vector3d camera = cam_from_object.Inverse().translation();
  const Eigen::Vector3d towards = camera - centre;
  const double distance = towards.norm();
  if (!(distance > 0) || !std::isfinite(distance)) return;
  const Eigen::Vector3d v = towards / distance;
  for (std::size_t i = 0; i < directions_.size(); ++i) {
    if (!seen_[i] && directions_[i].dot(v) >= cos_max_incidence_) {
      seen_[i] = 1;
      ++seen_count_;
    }
  }
}

double ViewCoverage::Share() const {
  return directions_.empty() ? 0.0 : static_cast<double>(seen_count_) / directions_.size();
}

}  // namespace ihs::fusion
