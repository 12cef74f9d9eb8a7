#include "app/live_screen.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <utility>
#include <vector>

#include "render/live_window.h"

namespace ihs::app {
namespace {

constexpr int kStatusHeight = 48;
const cv::Scalar kBackground(30, 30, 36);
const cv::Scalar kModelBackground(58, 60, 68);
const cv::Scalar kText(235, 235, 235);
const cv::Scalar kGood(110, 220, 110), kDoubt(250, 200, 70), kBad(250, 100, 90);

// A state word's colour: green when all is well, amber when in doubt or paused, red when lost.
cv::Scalar StateColour(const std::string& state) {
  if (state == "tracked" || state == "registered" || state == "turned by the hand") return kGood;
  if (state == "lost") return kBad;
  return kDoubt;
}

// Draws `segments` left to right on one line from (x, baseline).
void DrawSegments(cv::Mat& image, int x, int baseline,
                  const std::vector<std::pair<std::string, cv::Scalar>>& segments) {
  for (const auto& [text, colour] : segments) {
    cv::putText(image, text, cv::Point(x, baseline), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1,
                cv::LINE_AA);
    int unused = 0;
    x += cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, 0.5, 1, &unused).width;
  }
}

// The camera panel: the colour image with the fitted hand's skeleton and the contacts.
void DrawCameraPanel(cv::Mat panel, const LiveView& view, const CameraIntrinsics& intrinsics) {
  if (view.frame && view.frame->HasColor() && view.frame->width == panel.cols &&
      view.frame->height == panel.rows) {
    cv::Mat(panel.rows, panel.cols, CV_8UC3, const_cast<std::uint8_t*>(view.frame->rgb.data()))
        .copyTo(panel);
  }
  auto project = [&](const Eigen::Vector3d& p) {
    return cv::Point(static_cast<int>(intrinsics.fx * p.x() / p.z() + intrinsics.cx),
                     static_cast<int>(intrinsics.fy * p.y() / p.z() + intrinsics.cy));
  };
  const auto& joints = view.joints_mm;
  for (std::size_t j = 1; j < joints.size() && j < view.joint_parents.size(); ++j) {
    const int parent = view.joint_parents[j];
    if (parent < 0 || parent >= static_cast<int>(joints.size())) continue;
    if (joints[j].z() <= 0 || joints[parent].z() <= 0) continue;
    cv::line(panel, project(joints[parent]), project(joints[j]), cv::Scalar(60, 220, 60), 2,
             cv::LINE_AA);
  }
  for (const auto& joint : joints) {
    if (joint.z() > 0) cv::circle(panel, project(joint), 3, cv::Scalar(255, 255, 255), -1);
  }
  for (const auto& contact : view.contacts_mm) {
    if (contact.z() > 0) cv::circle(panel, project(contact), 3, cv::Scalar(255, 40, 40), -1);
  }
}

// The model panel's label: from where it is seen.
const char* ModelLabel(const ModelViewpoint& viewpoint) {
  const bool turned = std::abs(viewpoint.yaw_deg) > 0.5 || std::abs(viewpoint.pitch_deg) > 0.5;
  return turned ? "model, turned (c: back to the camera's view)"
                : "model, from the camera's direction (drag to turn it)";
}

// "seen 63 % | 28.5 fps | frames 120, fused 110, dropped 0".
std::string CountsText(const PipelineProgress& progress) {
  char text[160];
  std::snprintf(
      text, sizeof(text), "seen %.0f %% | %.1f fps | frames %lld, fused %lld, dropped %lld",
      100 * progress.coverage, progress.FramesPerSecond(),
      static_cast<long long>(progress.processed), static_cast<long long>(progress.registered),
      static_cast<long long>(progress.dropped));
  return text;
}

// The model panel: the lit model where the raycast hit it, over a lighter background.
void DrawModelPanel(cv::Mat panel, const LiveView& view) {
  panel.setTo(kModelBackground);
  bool any = false;
  if (view.model.width == panel.cols && view.model.height == panel.rows) {
    cv::Mat model(panel.rows, panel.cols, CV_8UC3,
                  const_cast<std::uint8_t*>(view.model.rgb.data()));
    cv::Mat hit;
    cv::cvtColor(model, hit, cv::COLOR_RGB2GRAY);
    hit = hit > 0;
    any = cv::countNonZero(hit) > 0;
    model.copyTo(panel, hit);
  }
  if (!any) {
    cv::putText(panel, "the model appears with the first registered frame",
                cv::Point(20, panel.rows / 2), cv::FONT_HERSHEY_SIMPLEX, 0.5, kText, 1,
                cv::LINE_AA);
  }
}


// The status line's pieces, each in its colour: the states coloured by how they stand.
std::vector<std::pair<std::string, cv::Scalar>> StatusSegments(const PipelineProgress& progress) {
  return {{"hand: ", kText},
          {progress.hand, StateColour(progress.hand)},
          {" | object: ", kText},
          {progress.object, StateColour(progress.object)},
          {" | " + CountsText(progress), kText}};
}

}  // namespace

std::string StatusLine(const PipelineProgress& progress) {
  std::string line;
  for (const auto& [text, colour] : StatusSegments(progress)) line += text;
  return line;
}

void LiveScreenSize(const CameraIntrinsics& intrinsics, int* width, int* height) {
  *width = 2 * intrinsics.width;
  *height = intrinsics.height + kStatusHeight;
}

RgbImage ComposeLiveScreen(const LiveView& view, const CameraIntrinsics& intrinsics,
                           const PipelineProgress& progress) {
  const int width = view.frame ? view.frame->width : intrinsics.width;
  const int height = view.frame ? view.frame->height : intrinsics.height;
  cv::Mat screen(height + kStatusHeight, 2 * width, CV_8UC3, kBackground);
  DrawCameraPanel(screen(cv::Rect(0, 0, width, height)), view, intrinsics);
  DrawModelPanel(screen(cv::Rect(width, 0, width, height)), view);
  DrawSegments(screen, 8, height + 19, StatusSegments(progress));
  DrawSegments(screen, 8, height + 40,
               {{"keys: s save the mesh now, r start anew, c the camera's view, q finish "
                 "(export and quit); drag the model to turn it",
                 cv::Scalar(170, 170, 180)}});
  RgbImage image{screen.cols, screen.rows, {}};
  image.rgb.assign(screen.data, screen.data + screen.total() * 3);
  DrawPanelLabel(&image, 0, width, "camera: colour, fitted hand, contacts (red)");
  DrawPanelLabel(&image, width, width, ModelLabel(view.viewpoint));
  return image;
}

LiveScreen::LiveScreen(Pipeline& pipeline, render::LiveWindow* window)
    : pipeline_(pipeline), window_(window), intrinsics_(pipeline.intrinsics()) {}

bool LiveScreen::Poll() {
  bool finish = false;
  if (window_) {
    const render::WindowInput input = window_->PollInput();
    for (char key : input.keys) {
      if (key == 's') pipeline_.RequestExport();
      if (key == 'r') pipeline_.RequestReset();
      if (key == 'c') viewpoint_ = {}, pipeline_.SetModelViewpoint(viewpoint_);
      if (key == 'q') finish = true;
    }
    if (input.drag_x != 0 || input.drag_y != 0) {
      viewpoint_ = viewpoint_.Dragged(input.drag_x, input.drag_y);
      pipeline_.SetModelViewpoint(viewpoint_);
    }
    finish = finish || window_->ShouldClose();
  }
  ShowNewest();
  return finish;
}

void LiveScreen::ShowNewest() {
  std::optional<LiveView> view = pipeline_.TakeLiveView();
  if (!view) return;
  last_ = std::move(view);
  if (!window_) return;
  const RgbImage screen = ComposeLiveScreen(*last_, intrinsics_, pipeline_.Progress());
  window_->Show(screen.rgb, screen.width, screen.height);
}

void LiveScreen::SaveScreenshot(const std::filesystem::path& path) {
  ShowNewest();  // The last frames' view, not yet shown.
  RgbImage image;
  if (window_) {
    image.rgb = window_->Screenshot(&image.width, &image.height);
  } else {
    image = ComposeLiveScreen(last_.value_or(LiveView{}), intrinsics_, pipeline_.Progress());
  }
  WritePng(path, image);
  spdlog::info("{} screenshot: {}", window_ ? "window" : "screen (drawn off-screen)",
               path.string());
}

}  // namespace ihs::app
