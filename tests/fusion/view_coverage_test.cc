// The share of directions around an object seen, against the sphere's geometry.

#include "fusion/view_coverage.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ihs::fusion {
namespace {

const Eigen::Vector3d kCentre(0, 0, 0);

// The camera 500 mm along its own axis from the object, the object turned by `object_rotation`.
Rigid3 CamFromObject(const Rigid3& object_rotation) {
  return Rigid3::Translation({0, 0, 500}) * object_rotation;
}

// A cap of half-angle `deg` is (1 - cos deg) / 2 of the sphere.
double Cap(double deg) { return (1 - std::cos(deg * M_PI / 180)) / 2; }

TEST(ViewCoverageTest, OneViewSeesTheCapWithinTheSteepestIncidence) {
  ViewCoverage coverage;
  EXPECT_EQ(coverage.Share(), 0.0);
  coverage.Observe(CamFromObject(Rigid3()), kCentre);
  EXPECT_NEAR(coverage.Share(), Cap(75), 0.01);
  ViewCoverageOptions grazing;
  grazing.max_incidence_deg = 90;
  ViewCoverage half(grazing);
  half.Observe(CamFromObject(Rigid3()), kCentre);
  EXPECT_NEAR(half.Share(), 0.5, 0.01);
}

TEST(ViewCoverageTest, ASpinAboutTheViewingAxisShowsNothingNewAndATurnShowsTheBand) {
  ViewCoverage spin, turn;
  for (int step = 0; step <= 36; ++step) {
    const double angle = step * 10 * M_PI / 180;
    spin.Observe(CamFromObject(Rigid3::FromAxisAngle({0, 0, 1}, angle)), kCentre);
    turn.Observe(CamFromObject(Rigid3::FromAxisAngle({0, 1, 0}, angle)), kCentre);
  }
  EXPECT_NEAR(spin.Share(), Cap(75), 0.01);
  // A full turn about an axis across the view: every direction but the caps within 15° of it.
  EXPECT_NEAR(turn.Share(), 1 - 2 * Cap(15), 0.01);
}

TEST(ViewCoverageTest, TheSameViewTwiceCountsOnceAndACameraAtTheCentreNothing) {
  ViewCoverage coverage;
  coverage.Observe(CamFromObject(Rigid3()), kCentre);
  const double once = coverage.Share();
  coverage.Observe(CamFromObject(Rigid3()), kCentre);
  EXPECT_EQ(coverage.Share(), once);
  ViewCoverage inside;
  inside.Observe(Rigid3::Translation({0, 0, 500}), Eigen::Vector3d(0, 0, -500));
  EXPECT_EQ(inside.Share(), 0.0);
}

TEST(ViewCoverageTest, BadOptionsAreRejected) {
  ViewCoverageOptions options;
  options.max_incidence_deg = 0;
  EXPECT_THROW(ViewCoverage{options}, std::invalid_argument);
  options = {};
  options.directions = 3;
  EXPECT_THROW(ViewCoverage{options}, std::invalid_argument);
}

}  // namespace
}  // namespace ihs::fusion
