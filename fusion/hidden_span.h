#pragma once
// The object hidden behind the hand: frames that show only a small part of what the frames
// before showed, and of what the model says is in view at their pose, are registered and
// tracked, but not integrated into the model.
//
// A hand that turns a box can cover most of it for a second or more: those frames keep a few
// hundred of its points where the others have thousands. Registered from such a patch, a frame
// is easily turned off by tens of degrees (a few features, a face that fixes no turn), and,
// integrated, it writes that turn into the model; every frame after it then aligns to the
// corrupted model, consistently and wrongly (a generated box turn ended 67° off with its model
// 42 mm too large). Kept out of the model they cannot corrupt it: where the object shows itself
// again, it is aligned against a model that is still whole (docs/fusion.md, "The object hidden
// behind the hand"). The segmentation losing most of the object (a red face taken for skin)
// looks the same and is held out alike.

#include <deque>

namespace ihs::fusion {

/// Options of the hold while the object is hidden (defaults in the field comments).
struct HiddenOptions {
  /// A frame hides the object where it shows fewer than this share of the most object points
  /// of the last `reference_frames` frames that did not (0: never hidden; every frame is
  /// integrated). A box turning in view shows between about half and all of its largest view;
  /// behind the hand, or with most of it lost to the segmentation, a tenth to a third.
  double share = 0.4;
  int reference_frames = 30;
  /// ... and where the frame shows the object at fewer than this share of the pixels where
  /// the model, raycast at the frame's registered pose, says it is in view (0: not checked).
  /// Behind the hand, or where the segmentation lost most of it (a red face taken for skin),
  /// the frame shows a patch of what the model says is there: 0.1-0.55 in the generated box
  /// turns; in view 0.6-0.9 (the mask leaves out the object's edges and what touches the
  /// hand). A flat object turned edge-on shows few points too, but all that the model says is
  /// in view (0.97-1.0): by the point count alone it was held out and lost (docs/fusion.md,
  /// "The object hidden behind the hand").
  double shown_share = 0.7;
  /// Pixels whose depth lies more than this behind the model's (mm) show what is behind it: the
  /// model is not there (its edges, a pose a little off), and they do not count.
  double background_margin_mm = 10.0;

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
