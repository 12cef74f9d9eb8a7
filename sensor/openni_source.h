#pragma once
// Frames from OpenNI2: a live device (PrimeSense Carmine 1.09 first; any OpenNI2 depth + colour
// device) or an .oni recording played by OpenNI2's own player. OpenNI2's headers stay in the .cc.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sensor/frame_source.h"

namespace openni {
class VideoStream;
}

namespace ihs::sensor {

/// Options of the OpenNI2 source.
struct OpenNiOptions {
  /// Device URI, or an .oni file path; empty opens the first device found.
  std::string uri;
  /// Depth and colour resolution requested from a live device, pixels.
  int width = 640;
  int height = 480;
  /// Frame rate requested from a live device, Hz.
  int fps = 30;
  /// Hardware depth-to-colour registration (IMAGE_REGISTRATION_DEPTH_TO_COLOR).
  bool register_depth_to_color = true;
  /// Mirror the images (off: the camera's true view, as the paper's data).
  bool mirror = false;
  /// Largest depth/colour timestamp difference for a pair, µs; a depth frame without a colour
  /// frame that close is delivered without colour.
  std::int64_t max_color_offset_us = 34'000;

  /// Throws std::invalid_argument naming the bad field.
  void Check() const;
};

/// What OpenNI2 sees: one line per device (vendor, name, URI), or why it sees none. Never
/// throws.
std::string DescribeOpenNiDevices();

/// Reads registered depth (mm) + RGB colour frames through OpenNI2.
class OpenNiSource : public FrameSource {
 public:
  explicit OpenNiSource(OpenNiOptions options);
  ~OpenNiSource() override;

  /// Opens the device or file. Throws ihs::DeviceError for a live device (with the USB
  /// diagnosis: absent, not accessible with the udev rule to install, or busy) and
  /// ihs::InputError for a file OpenNI2 refuses.
  void Start() override;
  void Stop() override;
  SourceRead Next(std::chrono::milliseconds timeout) override;
  CameraIntrinsics Intrinsics() const override;
  std::string Description() const override;
  std::optional<std::int64_t> FrameCount() const override;
  bool IsLive() const override;
  std::int64_t MissedFrames() const override;

  /// Depth frames delivered without colour (no colour frame close enough in time).
  std::int64_t FramesWithoutColor() const;

  /// The started OpenNI2 streams (depth, then colour if any), for openni::Recorder; OpenNI.h is
  /// not needed to hold the pointers, so it stays out of this header.
  std::vector<openni::VideoStream*> OpenNiStreams();

  /// Whether `uri` names an .oni recording (by extension).
  static bool IsOniPath(const std::string& uri);

 private:
  struct Impl;
  const OpenNiOptions options_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ihs::sensor
