#include "app/live_screen.h"

#include <opencv2/imgproc.hpp>

namespace ihs::app {
RgbImage ComposeLiveScreen(const LiveView& view, const CameraIntrinsics& intrinsics,
                           const std::string& status_line) {
  const int width = view.frame ? view.frame->width : intrinsics.width;
  const int height = view.frame ? view.frame->height : intrinsics.height;
  constexpr int kStatusHeight = 28;
  cv::Mat screen(height + kStatusHeight, 2 * width, CV_8UC3, cv::Scalar(30, 30, 36));
  cv::Mat left = screen(cv::Rect(0, 0, width, height));
  if (view.frame && view.frame->HasColor()) {
    cv::Mat(height, width, CV_8UC3, const_cast<std::uint8_t*>(view.frame->rgb.data())).copyTo(left);
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
    cv::line(left, project(joints[parent]), project(joints[j]), cv::Scalar(60, 220, 60), 2,
             cv::LINE_AA);
  }
  for (const auto& joint : joints) {
    if (joint.z() > 0) cv::circle(left, project(joint), 3, cv::Scalar(255, 255, 255), -1);
  }
  for (const auto& contact : view.contacts_mm) {
    if (contact.z() > 0) cv::circle(left, project(contact), 2, cv::Scalar(255, 40, 40), -1);
  }
  if (view.model.width == width && view.model.height == height) {
    // The model where the raycast hit it, over the window's background elsewhere.
    cv::Mat model(height, width, CV_8UC3, const_cast<std::uint8_t*>(view.model.rgb.data()));
    cv::Mat hit;
    cv::cvtColor(model, hit, cv::COLOR_RGB2GRAY);
    model.copyTo(screen(cv::Rect(width, 0, width, height)), hit > 0);
  }
  cv::putText(screen, status_line + "   keys: s save, r reset, q quit",
              cv::Point(8, height + kStatusHeight - 9), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  RgbImage image{screen.cols, screen.rows, {}};
  image.rgb.assign(screen.data, screen.data + screen.total() * 3);
  return image;
}

}  // namespace ihs::app
