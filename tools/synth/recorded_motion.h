#pragma once
// The recorded motion: the real hand motion of one of the paper's scanning sessions, with an
// object placed in the hand. The sessions recorded the hand only, so the object's pose is
// derived from the fingertips that touch it, by this rule:
//
//  1. Grasp: the first frame at which the object fits between the thumb and index fingertips:
//     their skin gap equals the object's diameter at some height, its axis lies across the gap,
//     turned about the gap line to the axis the two fingertips turn about over the next 60
//     frames (when they turn by 10° or more; otherwise the best of 24 directions), either way
//     up — with both fingertips within `contact_mm` of the surface and the hand's skin at most
//     `max_penetration_mm` inside the object.
//  2. Forward from there: the fingertips holding the object in the previous frame (within
//     `contact_mm`, at least two) carry it: it moves with their rigid motion (least squares over
//     their skin vertices). With one fingertip left on it (the others re-grasping) it keeps its
//     orientation and moves with that fingertip; with none it stays where it is.
//     Each frame's pose is then corrected (Levenberg–Marquardt, tied to the carried pose by
//     `prior_weight`) so that the fingertips within `contact_mm` lie on the surface and no skin
//     is inside the object.
//  3. Backward from the grasp frame to the first frame, the same with time reversed.
//
// The report says how well this holds: in how many held frames the holding fingertips are
// within 3 mm of the surface when carried by the contacts alone (before the correction), and
// how deep the hand penetrates the object after it.

#include <cstdint>

#include "tools/synth/motion.h"
#include "tools/synth/object_shape.h"
#include "tracker/hand_data.h"

namespace ihs::synth {

/// Parameters of the object placement in a recorded motion.
struct RecordedMotionOptions {
  /// A fingertip holds the object when its skin is within this distance of the surface, mm.
  double contact_mm = 3.0;
  /// Largest penetration accepted for the initial grasp, mm.
  double max_penetration_mm = 3.0;
  /// Weight of the carried pose in the per-frame correction (per mm; per rad × 50 mm): high
  /// enough that fingers opening to re-grasp let go of the object rather than slide it.
  double prior_weight = 3.0;
  /// Slip: while held, the object turns about its own axis relative to the fingers by a random
  /// walk of this many mm per frame at the contact radius (0 = none).
  double slip_mm = 0.0;
  std::uint32_t seed = 1;
  /// Last frame to place the object in (−1: the whole session); later frames are left out.
  int last_frame = -1;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// How well the placement rule explains the recorded fingertips.
struct RecordedMotionReport {
  int frames = 0;
  /// Frame at which the object was first placed.
  int grasp_frame = -1;
  /// Frames with at least two fingertips holding the object.
  int held_frames = 0;
  /// Share of held frames in which every holding fingertip, carried by the contacts' motion
  /// alone (before the correction), is within 3 mm of the surface.
  double carried_within_3mm_share = 0;
  /// Share of held frames in which every holding fingertip is within 3 mm after the correction.
  double placed_within_3mm_share = 0;
  /// Penetration of the hand's skin into the object after placement: 95th percentile over
  /// frames and largest, mm.
  double penetration_p95_mm = 0;
  double penetration_max_mm = 0;
};

/// Places `object` in the recorded motion of `recorded.model` and returns the motion (the
/// session's frames up to options.last_frame). Throws ihs::InputError when no frame admits a grasp
/// of the object.
Motion MakeRecordedMotion(const tracker::RecordedHand& recorded, const ObjectShape& object,
                          const RecordedMotionOptions& options, RecordedMotionReport* report);

}  // namespace ihs::synth
