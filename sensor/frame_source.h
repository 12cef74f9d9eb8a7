#pragma once
// The one interface through which the pipeline reads RGB-D frames: a live OpenNI2 device, an
// .oni recording, a TUM RGB-D directory, or the replay shim used by tests.

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/camera_intrinsics.h"
#include "core/frame.h"

namespace ihs::sensor {

/// What a call to FrameSource::Next produced.
enum class SourceStatus {
  kFrame,         ///< A frame was delivered.
  kTimeout,       ///< No frame within the timeout; the stream goes on.
  kEndOfStream,   ///< A recording has no more frames (an expected outcome, not an error).
  kDisconnected,  ///< A live device went away; frames already delivered stay valid.
};

/// Human-readable name of a status ("frame", "timeout", "end of stream", "disconnected").
const char* ToString(SourceStatus status);

/// The result of FrameSource::Next.
struct SourceRead {
  SourceStatus status = SourceStatus::kTimeout;
  /// The frame when status is kFrame, else null. Immutable and shareable across threads.
  std::shared_ptr<const Frame> frame;
  /// Why the stream ended or disconnected, when it did (empty otherwise).
  std::string message;
};

/// How a recording is paced.
enum class Pacing {
  kAsFastAsPossible,  ///< Deliver frames as fast as the reader asks (headless replay default).
  kRealTime,          ///< Deliver frames at the rate of their recorded timestamps.
};

/// A stream of registered depth + colour frames.
///
/// Start() opens the device or file (throwing ihs::DeviceError or ihs::InputError with a message
/// a user can act on); Next() then returns frames in order until kEndOfStream or kDisconnected;
/// Stop() releases the device and may be called any number of times. A source is used by one
/// thread at a time.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Opens the device or file and starts streaming.
  virtual void Start() = 0;
  /// Stops streaming and releases the device. Idempotent; the destructor calls it too.
  virtual void Stop() = 0;
  /// Waits at most `timeout` for the next frame.
  virtual SourceRead Next(std::chrono::milliseconds timeout) = 0;
  /// Intrinsics of the (depth-registered-to-colour) images. Valid after Start().
  virtual CameraIntrinsics Intrinsics() const = 0;
  /// Device name and serial, or the file or folder read.
  virtual std::string Description() const = 0;
  /// Number of frames, when known (recordings); nullopt for live devices.
  virtual std::optional<std::int64_t> FrameCount() const = 0;
  /// Whether frames arrive in real time (a live device, or a recording paced at its timestamps):
  /// a consumer that falls behind must then drop frames rather than block the capture thread.
  virtual bool IsLive() const = 0;
  /// Frames the source could not decode and skipped (each also logged with its reason).
  virtual std::int64_t SkippedFrames() const { return 0; }
  /// Frames the device (or a player pacing a recording like one) produced but that never
  /// reached this reader: gaps in the device's own frame numbers.
  virtual std::int64_t MissedFrames() const { return 0; }
  /// Whether the frames come from a damaged recording that was only partly recovered.
  virtual bool Recovered() const { return false; }
};

}  // namespace ihs::sensor
