#pragma once
// A synthetic hand–object motion: per frame, every bone's transform and the object's pose,
// both in the camera frame, plus the parameters that made it (for the manifest).

#include <string>
#include <vector>

#include "core/rigid3.h"

namespace ihs::synth {

/// One frame of a motion.
struct MotionFrame {
  /// cam_from_bone of every hand bone (the hand model's bone order).
  std::vector<Rigid3> cam_from_bone;
  /// The object's pose, object frame (axis +z, base z = 0) → camera, mm.
  Rigid3 cam_from_object;
  /// Whether the hand holds the object in this frame (the object moves only while held).
  bool held = false;
};

/// A whole motion.
struct Motion {
  std::vector<MotionFrame> frames;
};

}  // namespace ihs::synth
