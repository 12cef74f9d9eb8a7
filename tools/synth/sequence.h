#pragma once
// A whole synthetic sequence: a hand turning an object (scripted or recorded motion), rendered
// off-screen, passed through the sensor model and written as the user would get it from a
// Carmine (an .oni file and the same frames as a TUM directory), with ground truth beside it:
//
//   OUT/sequence.oni            16zT depth + RGB colour, 30 fps
//   OUT/tum/                    the same frames as a TUM RGB-D directory
//   OUT/gt/trajectory.txt       cam_from_object per frame (TUM: t tx ty tz qx qy qz qw, mm)
//   OUT/gt/object.ply           the object mesh, object frame, mm
//   OUT/gt/hand_joints.csv      21 hand joints per frame (camera frame, mm)
//   OUT/gt/contacts.csv         per frame and fingertip: distance to the surface, touching
//   OUT/gt/labels/NNNNNN.png    per-pixel labels of the noise-free rendering (0/1/2)
//   OUT/gt/intrinsics.json      the camera
//   OUT/gt/manifest.json        every parameter and a summary of the contacts
//   OUT/contact_sheet.png       a few frames: colour, depth colour-mapped, labels

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>

#include "core/camera_intrinsics.h"
#include "tools/synth/recorded_motion.h"
#include "tools/synth/scripted_motion.h"
#include "tools/synth/sensor_model.h"

namespace ihs::synth {

/// Everything that defines a sequence; written to the manifest.
struct SequenceOptions {
  /// ObjectShape::FromSpec name: sphere, water-bottle, bowling-pin, small-bottle, box, lathe:FILE.
  std::string object = "sphere";
  /// "scripted", or "recorded:DIR" with DIR a session folder of the real hand data (holding
  /// Model_Hand_R.SKEL and .MOTION).
  std::string motion = "scripted";
  /// "procedural" (the project's hand) or the real hand data folder (holding model/). A recorded
  /// motion needs the real hand; when left "procedural" it uses the data folder two levels above
  /// the session folder.
  std::string hand = "procedural";
  /// Frames [first_frame, last_frame] of the motion (last_frame −1: to the end).
  int first_frame = 0;
  int last_frame = -1;
  /// Seed of every random choice (motion sway, slip, sensor noise).
  std::uint32_t seed = 1;
  /// Frame rate of the timestamps, Hz.
  int fps = 30;
  /// A fingertip touches the object when within this distance of its surface, mm.
  double touch_mm = 2.0;
  /// Colours of the hand and (for untextured objects) the object, RGB8.
  std::array<std::uint8_t, 3> hand_rgb = {222, 170, 140};
  std::array<std::uint8_t, 3> object_rgb = {70, 110, 200};
  CameraIntrinsics intrinsics;
  SensorModelOptions sensor;
  ScriptedMotionOptions scripted;
  RecordedMotionOptions recorded;
  /// Write the .oni file and the TUM directory (the ground truth is always written).
  bool write_oni = true;
  bool write_tum = true;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// What was generated.
struct SequenceSummary {
  int frames = 0;
  /// Frames in which the hand holds the object (it moves with the hand).
  int held_frames = 0;
  /// Deepest penetration of the hand's skin into the object over all frames, mm.
  double max_penetration_mm = 0;
  /// Recorded motion only: the placement report (see RecordedMotionReport).
  RecordedMotionReport recorded;
  double seconds = 0;
};

/// Generates the sequence into `out` (created if needed). Throws std::invalid_argument for bad
/// options, ihs::InputError for unreadable input data, ihs::OutputError when writing fails.
SequenceSummary GenerateSequence(const SequenceOptions& options, const std::filesystem::path& out);

}  // namespace ihs::synth
