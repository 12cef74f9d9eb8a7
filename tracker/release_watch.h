#pragma once
// A grasp let go. A hand that releases the object (to re-grasp it, to swing back for the next
// stroke) backs its touching fingertips off the surface together: on the generator's scripted
// turns by 8-10 mm within four or five frames, and the fitted fingertips follow (their contact
// distances rise by 6-10 mm within three frames). While the grasp holds they wander too, but
// one at a time: a hidden thumb drifts off by 1-2 mm a frame as the others stay. Here a grasp's
// fingertips that all rise by at least `rise_mm` within `frames` frames have let go: they do
// not count as contacts, at any threshold, until each comes back to within `return_mm` of
// where it was before (a re-grasp), and the held grasp (GraspHold) is given up. Frames where the
// contacts are those of a hand letting go are what a detection bound generous enough for the
// hidden fingertips of a held grasp finds wrongly.

#include <cstddef>
#include <deque>
#include <vector>

namespace ihs::tracker {

/// Options of telling a grasp let go (see the file comment).
struct ReleaseOptions {
  bool enabled = false;
  /// The frames over which the grasp's fingertips must rise together, and by how much, mm.
  int frames = 3;
  double rise_mm = 5.0;
  /// A let-go fingertip counts again once within this of its distance before the release, mm,
  /// or after `max_frames` frames (two seconds at 30 Hz).
  double return_mm = 2.5;
  int max_frames = 60;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Watches the fingertips' contact distances for a grasp let go. One per tracked hand.
class ReleaseWatch {
 public:
  /// `tips`: the number of end-effectors (ContactDetector::fingertip_vertices().size()).
  ReleaseWatch(ReleaseOptions options, size_t tips);

  /// This frame's contact distances (Contacts::tip_distance_mm) with the end-effector indices
  /// of the previous frame's contacts (the grasp). Returns whether the grasp was let go in
  /// this frame.
  bool Observe(const std::vector<double>& tip_distance_mm, const std::vector<size_t>& grasp);
  /// Per end-effector, the largest threshold at which it may count as a contact
  /// (ContactDetector::Select): -1 for a let-go fingertip, unbounded for the others.
  std::vector<double> Limits() const;
  /// Forgets everything (the hand was lost or found anew).
  void Reset();

 private:
  struct Tip {
    std::deque<double> recent;  // The last `frames` contact distances before this frame.
    bool let_go = false;
    double before_mm = 0;  // Where it was before it was let go.
    double peak_mm = 0;    // The farthest it went since.
    int frames_let_go = 0;
  };
  // How far tip `t` rose at `distance_mm` above the nearest of its recent distances (0 without).
  double Rise(const Tip& tip, double distance_mm) const;

  const ReleaseOptions options_;
  std::vector<Tip> tips_;
};

}  // namespace ihs::tracker
