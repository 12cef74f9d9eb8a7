#pragma once
// The scripted motion: a hand grasps the object with thumb, index and middle fingertips and
// turns it about its axis in grasps of `turn_per_grasp_deg`, re-grasping in between (fingers
// open, the hand turns back about the object while the object stays, fingers close again).
// While held, the object moves exactly with the hand (no slip unless asked), so its pose follows
// from the contacts.

#include <cstdint>
#include <string>

#include "tools/synth/motion.h"
#include "tools/synth/object_shape.h"
#include "tracker/hand_model.h"

namespace ihs::synth {

/// Parameters of the scripted motion.
struct ScriptedMotionOptions {
  /// Number of frames (the budget: one full turn in at most 300).
  int frames = 240;
  /// Turns about the object's axis over the whole motion.
  double turns = 1.0;
  /// Largest object rotation within one grasp, degrees; the number of grasps follows.
  double turn_per_grasp_deg = 90.0;
  /// Distance of the object's centre from the camera, mm.
  double distance_mm = 620.0;
  /// The object's axis leans this much from the image's vertical toward the camera, degrees.
  double tilt_deg = 20.0;
  /// Where the hand starts about the object's axis, degrees from the default start (the wrist
  /// on the hand's own side of the object, half a grasp before straight sideways), the same
  /// way round for either hand. With the sphere, +90 puts the hand in front of it (its back to
  /// the camera) and -90 behind; with other objects the grasp solved for them decides.
  double start_azimuth_deg = 0.0;
  /// Per grasp, the object also moves by up to this much (seeded), so the motion is not a pure
  /// rotation about a fixed axis: translation per axis, mm, and tilt, degrees.
  double sway_mm = 12.0;
  double sway_deg = 8.0;
  /// Fingertips press this far into the surface while holding, mm (a soft fingertip).
  double press_mm = 0.5;
  /// How far the fingertips back off from the surface when re-grasping, mm (at least).
  double release_mm = 8.0;
  /// Slip: while held, the object turns about its own axis relative to the fingers by a random
  /// walk of this many mm per frame at the contact radius (0 = no slip).
  double slip_mm = 0.0;
  /// Seed of the sway and the slip.
  std::uint32_t seed = 1;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Builds the scripted motion of `hand` turning `object`. Throws ihs::InternalError when no
/// grasp of the object can be found for this hand (an object far too large or small for it).
Motion MakeScriptedMotion(const tracker::HandModel& hand, const ObjectShape& object,
                          const ScriptedMotionOptions& options);

/// The height (mm, object frame) at which the scripted grasp holds `object`: where its radius
/// is closest to a comfortable pinch (30 mm), preferring the middle of the object.
double GraspHeight(const ObjectShape& object);

}  // namespace ihs::synth
