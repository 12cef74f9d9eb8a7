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
#include <memory>
#include <string>
#include <vector>

#include "core/camera_intrinsics.h"
#include "core/frame.h"
#include "render/offscreen_renderer.h"
#include "tools/synth/hand_object.h"
#include "tools/synth/motion.h"
#include "tools/synth/recorded_motion.h"
#include "tools/synth/scripted_motion.h"
#include "tools/synth/sensor_model.h"

namespace ihs::synth {

/// Everything that defines a sequence; written to the manifest.
struct SequenceOptions {
  /// ObjectShape::FromSpec name: sphere, water-bottle, bowling-pin, small-bottle, box,
  /// plain-box, cube, lathe:FILE.
  std::string object = "sphere";
  /// Give a lathe object or the cube a colour pattern; by default it is one uniform colour.
  bool textured = false;
  /// With `textured`, a lathe object's pattern is a label drawn from `seed`
  /// (ObjectShape::FromSpec's label_seed): no side alike, where the checkerboard repeats every
  /// 60° about the axis.
  bool label = false;
  /// The hand makes the motion with nothing in it: the object is not rendered, no fingertip
  /// touches anything and nothing is held (the ground truth keeps the absent object's poses).
  /// A scanner must end such a recording as it ends one without a hand.
  bool empty_hand = false;
  /// "scripted", or "recorded:DIR" with DIR a session folder of the real hand data (holding
  /// Model_Hand_R.SKEL and .MOTION).
  std::string motion = "scripted";
  /// "procedural" (the project's hand) or the real hand data folder (holding model/). A recorded
  /// motion needs the real hand; when left "procedural" it uses the data folder two levels above
  /// the session folder.
  std::string hand = "procedural";
  /// The hand's size relative to the template (scripted motion only: a recorded motion comes
  /// with its own hand).
  double hand_scale = 1.0;
  /// A left hand turns the object (scripted motion only: the recorded hand is a right one): the
  /// procedural hand is built mirrored, a scanned hand must be a left one.
  bool left_hand = false;
  /// Frames [first_frame, last_frame] of the motion (last_frame −1: to the end).
  int first_frame = 0;
  int last_frame = -1;
  /// Every `frame_step`-th frame of that range is rendered, with timestamps `fps` apart: the
  /// same motion made `frame_step` times as fast (the object turns that much more between
  /// frames), or a camera that drops frames.
  int frame_step = 1;
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

/// One rendered frame with its ground truth.
struct RenderedFrame {
  /// What the sensor delivers: depth (mm) and colour, index and timestamps set.
  Frame frame;
  /// Per-pixel labels of the noise-free rendering (render::Label).
  std::vector<std::uint8_t> labels;
  Rigid3 cam_from_object;
  /// The hand: every bone's transform, the 21 joints (camera frame, mm), the skinned mesh.
  std::vector<Rigid3> cam_from_bone;
  std::vector<Eigen::Vector3d> joints_mm;
  TriangleMesh posed_hand;
  /// Fingertips against the object (touch threshold: options.touch_mm).
  HandObjectContact contact;
  /// Whether the object moves with the hand in this frame.
  bool held = false;
};

/// Builds the hand, the object and the motion of a sequence and renders its frames one at a
/// time, in memory (GenerateSequence writes what it renders). Frame i's noise depends only on
/// the seed and i, so any frame can be rendered on its own.
class SequenceRenderer {
 public:
  /// Throws like GenerateSequence.
  explicit SequenceRenderer(const SequenceOptions& options);
  ~SequenceRenderer();
  SequenceRenderer(const SequenceRenderer&) = delete;
  SequenceRenderer& operator=(const SequenceRenderer&) = delete;

  /// Frames in the chosen range.
  int frame_count() const { return (last_ - options_.first_frame) / options_.frame_step + 1; }
  /// Renders frame i of the range (0-based; frame.index = i).
  RenderedFrame Render(int i);

  const SequenceOptions& options() const { return options_; }
  const tracker::HandModel& hand() const { return hand_; }
  /// Where the rendered hand came from: "procedural" or a hand data folder (a recorded motion
  /// brings the data's scanned hand).
  const std::string& hand_source() const { return hand_source_; }
  const ObjectShape& object() const { return object_; }
  /// The object's mesh as rendered (with its colours).
  const TriangleMesh& object_mesh() const { return object_mesh_; }
  const HandObjectGeometry& geometry() const { return *geometry_; }
  const RecordedMotionReport& recorded_report() const { return recorded_report_; }

 private:
  const SequenceOptions options_;
  ObjectShape object_;
  TriangleMesh object_mesh_;
  tracker::HandModel hand_;
  Motion motion_;
  RecordedMotionReport recorded_report_;
  std::string hand_source_;
  int last_ = 0;
  std::unique_ptr<HandObjectGeometry> geometry_;
  std::unique_ptr<render::OffscreenRenderer> renderer_;
};

/// Generates the sequence into `out` (created if needed). Throws std::invalid_argument for bad
/// options, ihs::InputError for unreadable input data, ihs::OutputError when writing fails.
SequenceSummary GenerateSequence(const SequenceOptions& options, const std::filesystem::path& out);

}  // namespace ihs::synth
