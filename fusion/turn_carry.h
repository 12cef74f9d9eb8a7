#pragma once
// The turn the hand carries (ours, beyond the paper). A ball, or a bottle about its axis, shows
// ICP nothing of how it turns, and the fingertip contacts that would are found in some held
// frames only: on the scripted full turns the object lost all the turn of the held frames
// without contacts (60-190° of 360°), and the contacts the tracker found while the hand swung
// back to re-grasp — fingers lifted 8-11 mm off, within the detector's grown threshold — turned
// it back by 100-230° (docs/fusion.md, "Where the lathe turns are lost"). Neither the fitted
// fingertips nor the depth around them tells a held object from a released one.
//
// What does: an object turned all the way round is turned one way, and the hand swings back
// without it. Once the hand has been seen to turn the object consistently one way (its turn
// over the recent frames whose contacts moved the object), that way is the object's: in a frame
// where the hand turns on that way, the object turns with it in the directions its surface
// leaves free (where nothing else registers the frame); where the hand turns back, it does not,
// whatever contacts were found. Motions that go back and forth (the paper's recorded sessions)
// never show a consistent one-way turn, and then nothing changes. The turn of the frames before
// it was recognised that nothing registered is caught up once it is (TakeCatchUp).

#include <Eigen/Core>
#include <deque>
#include <optional>
#include <utility>

#include "core/rigid3.h"

namespace ihs::fusion {

/// Options of the hand-carried turn (ObjectFusion, FusionInput::hand_motion).
struct TurnCarryOptions {
  /// Carry the object's free turn with the hand once a one-way turn is recognised.
  bool enabled = true;
  /// A one-way turn is recognised when, over the last `window_frames` frames whose contacts
  /// moved the object, the hand turned by at least `recognise_deg` about one axis, and that is
  /// at least `min_consistency` of all the turning it did in those frames (back and forth
  /// cancels; so does the fit's wobble of 1-2° a frame about other axes). The scripted full
  /// turns turn 2-4° a frame while held: 40° is half a stroke of their grasps. With 15 frames,
  /// 30° and 0.8, a release whose lifted fingers were still taken for contacts was recognised
  /// as the turn in one of twenty generated turns (docs/fusion.md).
  int window_frames = 20;
  double recognise_deg = 40.0;
  double min_consistency = 0.7;
  /// A frame's turn counts at most this much towards recognising it, degrees: a hand turns a
  /// held object a few degrees a frame (the scripted grasps 2-4° at 30 frames/s), but swings
  /// back faster, up to 12° a frame — and a swing back whose lifted fingers were taken for
  /// contacts for six frames was recognised as the turn on a generated egg-shaped object.
  double recognise_max_frame_deg = 5.0;
  /// The hand turns on in a frame where its turn about the recognised axis is forward in that
  /// frame and on average over the last this many frames (one frame's fitting noise is not a
  /// stroke).
  int smoothing_frames = 3;
  /// A hand that turns neither on nor back (its turn in the frame and its average disagree: a
  /// stroke that starts or ends, a hand held still) leaves the frame to the contacts
  /// (kUndecided), nothing carried; only a hand turning back in the frame and on average keeps
  /// them out. Off: such a frame is taken for a turn back. The fitted hand lags a stroke's start
  /// (its turn 0-0.2° a frame while the truth's palm turns 0.1-1.3° and the object 0.2-3.2°):
  /// taken for turns back, up to fourteen frames of a stroke were lost (docs/fusion.md).
  bool undecided_to_contacts = true;
  /// When the one-way turn is recognised, the object catches up the turn of the last this many
  /// frames that nothing registered (no contacts, no features): the hand's turn on in each, as
  /// it would have been carried had the turn been known (0: none). The first stroke of a turn
  /// is recognised only 20-40 frames in, and its frames without contacts were lost.
  int catch_up_frames = 60;
  /// A hand that turns farther than this in one frame was refitted rather than followed (a
  /// fit that flipped, a search): its motion says nothing of the object's, degrees.
  double max_frame_turn_deg = 15.0;
  /// Such a frame turning back once the turn is recognised is judged back all the same: its
  /// contacts are kept out. Fitted hands swinging back to re-grasp turn 16-29° a frame, and
  /// their contacts, used where the frame was not judged, turned 22 generated lathe and ball
  /// turns back by 132° in all (docs/fusion.md).
  bool fast_back_kept_out = true;
  /// The hand carries only the turn of an object whose surface leaves it free: where at least
  /// `min_free_share` of the last `surface_frames` frames whose free directions ICP judged
  /// had one (IcpResult::free_directions). Balls, bottles and the pin: all of them; boxes and
  /// cubes: none but where a face is seen alone (at most 47 % of 30 frames in eleven turns).
  int surface_frames = 30;
  double min_free_share = 0.8;
  /// In a frame where the hand turns on, the registered turn about the recognised axis (from
  /// the contacts, the features and ICP) and the hand's turn are two measurements of the same
  /// free turn; the object is turned by their mean weighted this much toward the hand's (0: the
  /// registration's alone, 1: the hand's). On the generated lathe and ball turns, in such
  /// frames, the registration read 11 % less than the truth's turn and the hand 21 % more (it
  /// is judged on where it turns forward), each off by alike amounts per frame (0.5-1.9°):
  /// neither is the better, so they count alike (docs/fusion.md, "The hand's turn weighed").
  double hand_weight = 0.5;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// How the hand turns in a frame, relative to the recognised one-way turn.
enum class HandTurn {
  kUnknown,    ///< No one-way turn recognised yet, or no hand motion in this frame.
  kOn,         ///< The hand turns on the recognised way: it carries the object.
  kBack,       ///< It turns back: the object stays, whatever contacts were found.
  kUndecided,  ///< Neither (TurnCarryOptions::undecided_to_contacts): the contacts decide.
};

/// A short name for stats ("unknown", "on", "back", "undecided").
const char* ToString(HandTurn turn);

/// Recognises the one-way turn and judges each frame's hand motion against it. Not
/// thread-safe; ObjectFusion owns one.
class TurnCarry {
 public:
  explicit TurnCarry(TurnCarryOptions options = {});

  /// This frame's hand motion (camera frame; none when the tracker did not follow the hand
  /// from the previous frame) with the object's previous pose: how the hand turns.
  HandTurn Judge(const std::optional<Rigid3>& hand_motion, const Rigid3& cam_from_object);
  /// After the frame: whether its contacts moved the object (the frames the one-way turn is
  /// recognised from), and whether anything registered it (contacts or features).
  void Learn(bool contacts_used, bool registered);
  /// Where the last Learn recognised the turn, what the frames before it missed (radians about
  /// axis(); see `catch_up_frames`); 0 otherwise, and once taken.
  double TakeCatchUp();
  /// After ICP: how many directions the surface left free (-1: not judged, ignored).
  void ObserveSurface(int free_directions);
  /// Whether the surface has been leaving a direction free (see `min_free_share`).
  bool SurfaceLeavesTurnFree() const;
  /// The object's previous pose carried by this frame's turn (after Judge returned kOn) about
  /// `pivot` (camera frame), and the angle, radians.
  Rigid3 Carry(const Rigid3& cam_from_object, const Eigen::Vector3d& pivot) const;
  /// `cam_from_object` turned by `radians` about the recognised axis through `pivot` (camera
  /// frame).
  Rigid3 Turn(const Rigid3& cam_from_object, const Eigen::Vector3d& pivot, double radians) const;
  /// `registered` (this frame's pose, after Judge returned kOn) with its turn from `previous`
  /// about the recognised axis moved `hand_weight` of the way to the hand's, about `pivot`
  /// (camera frame); sets `*moved_rad` to the angle it was turned by.
  Rigid3 Blend(const Rigid3& previous, const Rigid3& registered, const Eigen::Vector3d& pivot,
               double* moved_rad) const;
  double carried_rad() const { return carried_rad_; }

  bool recognised() const { return recognised_; }
  /// The recognised turn's axis in the object frame (unit; zero until recognised): the
  /// direction of the hand's turns that recognised it and of every turn on since.
  const Eigen::Vector3d& axis() const { return axis_; }

 private:
  void Recognise();
  // The turn on of the frames in history_ that nothing registered, about axis_ (radians).
  double MissedTurn() const;

  TurnCarryOptions options_;
  bool recognised_ = false;
  Eigen::Vector3d axis_ = Eigen::Vector3d::Zero();
  // The hand's turns that recognised the axis and every turn on since (object frame).
  Eigen::Vector3d turned_on_ = Eigen::Vector3d::Zero();
  // This frame's hand turn in the object frame (rotation vector, radians), when there is one.
  std::optional<Eigen::Vector3d> turn_;
  // The hand's turns of the last frames whose contacts moved the object (object frame).
  std::deque<Eigen::Vector3d> contact_turns_;
  // Before recognition, the hand's turn of the last frames and whether something registered
  // them (object frame).
  std::deque<std::pair<Eigen::Vector3d, bool>> history_;
  double catch_up_rad_ = 0;
  // The hand's turn about the axis in the last frames (radians; cleared where it is unknown).
  std::deque<double> along_axis_;
  // Whether ICP found a free direction, in the last frames where it judged.
  std::deque<bool> surface_free_;
  double carried_rad_ = 0;
};

}  // namespace ihs::fusion
