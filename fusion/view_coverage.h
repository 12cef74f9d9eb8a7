#pragma once
// How much of the object the scan has seen, live: the share of the directions around the object
// from which the camera has looked at it. A surface patch whose outward normal is n is measured
// from a camera in direction v (object frame, from the object towards the camera) when the
// angle between n and v is below the sensor's steepest incidence; so the directions n that some
// registered frame has covered are the orientations of surface the model can hold. For a convex
// object in plain view this is the share of its surface seen (exactly so for a ball); the hand's
// fingers hide a little of what it counts, and a concave pocket may stay unseen from every
// direction. It needs no closed model and costs a few microseconds per frame.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "core/rigid3.h"

namespace ihs::fusion {

struct ViewCoverageOptions {
  /// Directions the sphere is sampled with (a Fibonacci lattice: 1000 gives cells of ~4°).
  int directions = 1000;
  /// The steepest incidence at which the surface is still measured, degrees: structured-light
  /// sensors lose the surface past 70-80° from its normal.
  double max_incidence_deg = 75.0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// The directions around an object seen so far. Not thread-safe; the fusion thread owns it.
class ViewCoverage {
 public:
  explicit ViewCoverage(ViewCoverageOptions options = {});

  /// Counts a registered frame: the camera at `cam_from_object` looking at the object around
  /// `centre` (object frame, mm). A camera at the centre adds nothing.
  void Observe(const Rigid3& cam_from_object, const Eigen::Vector3d& centre);
  /// The share of directions seen, in [0, 1].
  double Share() const;

 private:
  double cos_max_incidence_;
  std::vector<Eigen::Vector3d> directions_;
  std::vector<std::uint8_t> seen_;
  int seen_count_ = 0;
};

}  // namespace ihs::fusion
