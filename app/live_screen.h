#pragma once
// What the live window shows, as one image: the camera's colour image with the hand's skeleton
// and the contact points drawn over it, the lit model beside it (fitted to its panel, turned as
// the user drags it), both panels labelled, and a status bar: the hand's and the object's state,
// how much of the object has been seen, the frame rate, and the keys.

#include <filesystem>
#include <optional>
#include <string>

#include "app/pipeline.h"
#include "core/camera_intrinsics.h"

namespace ihs::render {
class LiveWindow;
}

namespace ihs::app {

/// The status bar's first line as text (the screen draws it with the states in colour): hand
/// and object state, share seen, frame rate and counts.
std::string StatusLine(const PipelineProgress& progress);

/// The size of ComposeLiveScreen's image for a camera with `intrinsics`: the window's size.
void LiveScreenSize(const CameraIntrinsics& intrinsics, int* width, int* height);

/// Composes the live window's image from `view` and `progress` (two frames wide, with a status
/// bar below).
RgbImage ComposeLiveScreen(const LiveView& view, const CameraIntrinsics& intrinsics,
                           const PipelineProgress& progress);

/// The screen's side of a scan, driven from the controlling thread: the window's keys and drags
/// become the pipeline's requests, each new LiveView is composed and shown, and the last one is
/// kept for a screenshot, which is taken with or without a window.
class LiveScreen {
 public:
  /// `pipeline` must be started and publish live views (PipelineOutput::live_view); `window`
  /// may be null (no window: only a screenshot is composed).
  LiveScreen(Pipeline& pipeline, render::LiveWindow* window);

  /// Handles what the user did since the last call (s: export, r: reset, c: the camera's
  /// view, a drag: turn the model) and shows the newest view. True when the user asked to
  /// finish (q, Escape, the window closed).
  bool Poll();
  /// Writes a PNG of the screen: the window's own pixels, or without a window the same screen
  /// composed off-screen. Throws ihs::OutputError when it cannot.
  void SaveScreenshot(const std::filesystem::path& path);

 private:
  // Takes the newest view, if any, and shows it in the window.
  void ShowNewest();

  Pipeline& pipeline_;
  render::LiveWindow* window_;
  const CameraIntrinsics intrinsics_;
  ModelViewpoint viewpoint_;
  std::optional<LiveView> last_;
};

}  // namespace ihs::app
