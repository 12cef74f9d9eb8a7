#pragma once
// The object hidden behind the hand: frames that show only a small part of what the frames
// before showed, the rest of the model covered by something nearer, are registered and
// tracked, but not integrated into the model.
//
// A hand that turns a box can cover most of it for a second or more: those frames keep a few
// hundred of its points where the others have thousands. Registered from such a patch, a frame
// is easily turned off by tens of degrees (a few features, a face that fixes no turn), and,
// integrated, it writes that turn into the model; every frame after it then aligns to the
// corrupted model, consistently and wrongly (a generated box turn ended 67° off with its model
// 42 mm too large). Kept out of the model they cannot corrupt it: where the object shows itself
// again, it is aligned against a model that is still whole (docs/fusion.md, "The object hidden
// behind the hand").

#include <deque>

namespace ihs::fusion {

/// Options of the hold while the object is hidden (defaults in the field comments).
struct HiddenOptions {
  /// A frame hides the object where it shows fewer than this share of the most object points
  /// of the last `reference_frames` frames that did not (0, the default: never hidden; every
  /// frame is integrated). A box turning in view shows between about half and all of its
  /// largest view; behind the hand a tenth to a third. Off by default: at 0.4 with the point
  /// count alone (`covered_share` 0) it found two lost held-out box turns of ten but lost a flat
  /// object turned edge-on, which shows few points with nothing covering it; with the covering
  /// checked (0.5) it kept that one and the held-out boxes went back to lost (docs/fusion.md,
  /// "The object hidden behind the hand").
  double share = 0.0;
  int reference_frames = 30;
  /// ... and where at least this share of the pixels the model covers at the frame's registered
  /// pose (ObjectFusion raycasts it) show something nearer than the model (the hand) rather
  /// than the object (0: not checked): a flat object turned edge-on shows few points too, but
  /// nothing covers it.
  double covered_share = 0.5;
  /// How much nearer than the model a pixel's depth must be to cover it, mm.
  double cover_margin_mm = 10.0;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// Judges frame by frame whether the object is hidden. One Observe per frame, in order.
class HiddenSpan {
 public:
  explicit HiddenSpan(HiddenOptions options = {});

  /// Judges a frame by how many object points it shows; true where it hides the object. A
  /// frame that does not becomes part of the reference.
  bool Observe(int points);
  /// Frames hidden in a row up to the last one observed (0 where it showed the object).
  int hidden_frames() const { return hidden_frames_; }

 private:
  const HiddenOptions options_;
  // Object points of the latest frames not hidden.
  std::deque<int> reference_;
  int hidden_frames_ = 0;
};

}  // namespace ihs::fusion
